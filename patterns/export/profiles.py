"""Writing what is cut: :func:`write` and the built-in profiles, one registry line each.

``patterns.write(thing, path)`` writes a pattern, a blank, a nest
(:class:`patterns.Layout`), pieces or a :class:`~patterns.pieces.Drawing`:
the pieces are made (:func:`patterns.pieces.drawing_of`), laid out in the
drawing's frame, and handed to the profile the file's suffix (or
``profile=``) names.  A new profile is one module with a
``write(drawing, path, options)`` function and one line below (see
docs/architecture.md, "Where a new thing goes").
"""

from __future__ import annotations

from dataclasses import fields, replace

from ..audit import CheckOptions, checked_drawing
from ..errors import ExportError, InputError
from ..files import output_target
from ..nesting import Layout
from ..pieces import Drawing, PieceOptions, drawing_of
from . import astm, bendsheet, machine, report, svg
from .options import WriteOptions
from .registry import Profile, profile_for, register

__all__ = ["write"]

register(Profile("machine", ".dxf", machine.write, "DXF for lasers, plasma, waterjet and knife plotters: every contour "
                 "one closed polyline, marks on layers of their own", default=True))
register(Profile("astm", ".dxf", astm.write, "DXF ASTM D6673 (AAMA) for garment CAD: R12, one block per piece"))
register(Profile("svg", ".svg", svg.write, "SVG at 1:1 in mm for laser and vinyl cutters: red cut, blue score, "
                 "black engrave", default=True))
register(Profile("json", ".json", report.write, "the JSON report: the check, and every piece as drawn",
                 default=True))
register(Profile("bends", ".csv", bendsheet.write, "the bend sheet (CSV) for the press brake: a row per bend of "
                 "every blank, in the order to bend them", default=True))


def _split(options, keywords) -> tuple:
    records = (WriteOptions, PieceOptions, CheckOptions)
    names = [{f.name for f in fields(r)} for r in records]
    unknown = sorted(set(keywords) - set().union(*names))
    if unknown:
        every = sorted(set().union(*names))
        raise InputError(f"unknown option {unknown[0]!r}; the options are {', '.join(every)}")
    return tuple({k: v for k, v in keywords.items() if k in n} for n in names)


def write(source, path, options: WriteOptions | None = None, *, pieces: PieceOptions | None = None,
          check: CheckOptions | None = None, **keywords) -> None:
    """Write a pattern, a blank, a nest, pieces or a drawing to a file, atomically.

    Parameters
    ----------
    source : patterns.Pattern, patterns.Blank, patterns.Layout, patterns.pieces.Drawing, Piece, or a list of
        patterns, blanks and pieces
    path : str or Path
        ``.dxf`` (the ``machine`` profile, or ``profile="astm"``), ``.svg``, ``.json`` (the report) or ``.csv``
        (a blank's bend sheet, the ``bends`` profile).
    options : WriteOptions, optional
        The writer's options; keywords (``profile``, ``units``, ``version``, ``layer_map``,
        ``bend_lines``) go over it.
    pieces : PieceOptions, optional
        What goes onto each piece; keywords (``seam_allowance``, ``notch_spacing``, ``notch_style``,
        ``seam_corners``, ``bend_spacing``, ``arcs``, ``arc_tolerance``, ``text_height``, ``gap``,
        ``strain_layer``) go over it.  A nest or a drawing is written as it is.
    check : CheckOptions, optional
        The limits the JSON report checks against (keywords ``max_strain``, ...); the JSON profile only.

    Raises
    ------
    InputError
        An unknown option or a bad value, a suffix no profile writes, or a profile for another suffix
        (nothing is written).
    ExportError
        The file cannot be written, or a blank cannot be cut as it is (flanges that collide).
    """
    mine, piece_keywords, check_keywords = _split(options, keywords)
    opts = WriteOptions.of(options, mine, name=str(path))
    profile = profile_for(path, opts.profile)
    opts = replace(opts, profile=profile.name)
    if (check is not None or check_keywords) and profile.name != "json":
        raise InputError(f"{path}: {min(check_keywords) if check_keywords else 'check'} is a limit of the "
                         f"JSON report, not of the {profile.name} profile")
    piece_opts = PieceOptions.of(pieces, piece_keywords, name=str(path))
    if profile.name == "astm" and piece_opts.arcs:
        raise InputError(f"{path}: arcs are written in the machine profile only")
    what = "report" if profile.name == "json" else f"{profile.suffix[1:].upper()} file"
    output_target(path, what=what)  # before the drawing: a path that cannot be written fails at once
    drawing = _drawing(source, piece_opts, opts.units if profile.name == "machine" else "mm")
    if profile.name == "json":
        if drawing.report is None and not isinstance(source, (Drawing, Layout)):
            drawing = checked_drawing(source, drawing, CheckOptions.of(check, check_keywords, name=str(path)))[1]
    else:
        errors = [f for p in drawing.pieces for f in p.findings if f.error]
        if errors:
            raise ExportError(f"{path}: not written: {errors[0].message}")
    profile.write(drawing, path, opts)


def _drawing(source, piece_opts: PieceOptions, unit: str) -> Drawing:
    if isinstance(source, Drawing):
        return source
    if isinstance(source, Layout):
        return source.drawing()
    return drawing_of(source, piece_opts, unit=unit)  # its labels placed once, in the file's unit
