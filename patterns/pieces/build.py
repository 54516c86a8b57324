"""Patterns and blanks into pieces: :func:`pieces_of`, the one door into the piece model.

A pattern gives one piece per panel (:func:`~patterns.pieces.panel.panel_piece`);
a blank gives one piece: its exact outline and holes (and the rims of its
countersunk holes, to mark), its bend lines with
their direction, angle, inside radius and K-factor, and its findings.  A list
of patterns, blanks and pieces gives all their pieces, named
``"<part>/<piece>"`` when more than one part is in it.  Each piece made here
keeps its labels, placed once (:func:`~patterns.pieces.labels.place_labels`), and
a ``label-left-out`` note for every label that does not fit on it at the least
text height (:func:`~patterns.pieces.labels.label_findings`): the writers leave
that label out.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import replace

import numpy as np
import shapely

from ..blank import Blank
from ..errors import InputError
from ..findings import Finding
from ..mesh import extent
from ..pattern import Pattern
from ..text import printable
from ..units import Unit
from .allowance import allowance_lookup
from .labels import label_findings, with_labels
from .options import PieceOptions, check_marks
from .panel import panel_piece, text_height_for
from .piece import BendLine, Piece, Source

__all__ = ["blank_piece", "pieces_of"]


def blank_piece(blank: Blank, options: PieceOptions | None = None) -> Piece:
    """The piece of an unfolded blank: its exact contour, bend lines, title and findings."""
    options = options or PieceOptions()
    w, h = blank.size
    how = f"K {blank.k_factor:g}" if blank.k_factor is not None else "BEND TABLE"
    polygon = blank.polygon
    label_at = shapely.get_coordinates(shapely.point_on_surface(polygon))[0]
    faces = sorted({blank.fixed_face, *(f for b in blank.bends for f in b.faces)})
    return Piece(
        name=printable(blank.name), outline=blank.outline, holes=blank.holes,
        sew=tuple([blank.outline.points(0.01)] + [h.points(0.01) for h in blank.holes]), allowance=False,
        notches=(), drills=np.zeros((0, 2)), grain=None,
        bends=tuple(BendLine(b.line, b.angle, b.direction, b.inside_radius, b.k_factor, b.allowance,
                             sequence=b.sequence, of=len(blank.bends), flange=b.flange) for b in blank.bends),
        seams=(), title=(f"T {blank.thickness:g} MM  {how}  {w:.1f} x {h:.1f} MM",),
        text_height=text_height_for(max(w, h), options.text_height), label_at=label_at,
        source=Source("blank", blank.name, 0, tuple(faces)), strain=None, findings=blank.findings, rims=blank.rims)


def _pattern_pieces(pattern: Pattern, options: PieceOptions, findings) -> list:
    check_marks(pattern.name, [fs.seam.length for fs in pattern.seams],
                [extent(flat.uv) for flat in pattern.panels], options)
    allowance_of = allowance_lookup(options.seam_allowance, {s.seam.id for s in pattern.seams}, pattern.name)
    return [panel_piece(pattern, i, allowance_of, options, findings) for i in range(len(pattern.panels))]


def pieces_of(source, options: PieceOptions | None = None, *, findings: Iterable[Finding] = (),
              unit: Unit | str = Unit.MM, **keywords) -> tuple:
    """The pieces to cut of a pattern, a blank, a piece, or a list of them.

    Parameters
    ----------
    source : patterns.Pattern, patterns.Blank, Piece, or a sequence of them
    options : PieceOptions, optional
        The options as a record; keywords (any :class:`PieceOptions` field: ``seam_allowance``,
        ``notch_spacing``, ``bend_spacing``, ``arcs``, ...) go over it.
    findings : iterable of patterns.Finding
        A pattern's check findings: each piece takes those about its panel.
    unit : patterns.Unit or str
        The unit its seam labels say (the drawing's; default mm): each piece made here keeps its labels,
        placed once for it (``Piece.labels``).

    Returns
    -------
    tuple of Piece
        Where each panel or blank lies (not laid out: see :func:`patterns.pieces.drawing_of`).

    Raises
    ------
    InputError
        Something that is no pattern, blank or piece; a bad option; a panel too small to draw, or a
        spacing that would draw more marks than :data:`~patterns.pieces.options.MAX_MARKS`.
    """
    items = list(source) if isinstance(source, (list, tuple)) else [source]
    name = getattr(items[0], "name", "pieces") if items else "pieces"
    opts = PieceOptions.of(options, keywords, name=str(name))
    findings = tuple(findings)
    if not items:
        raise InputError("no pattern, blank or piece given")
    groups = []
    for item in items:
        if isinstance(item, Pattern):
            groups.append((item.name, _pattern_pieces(item, opts, findings), True, True))
        elif isinstance(item, Blank):
            groups.append((item.name, [blank_piece(item, opts)], False, True))
        elif isinstance(item, Piece):
            groups.append((item.source.part, [item], False, False))  # taken as it is, its notes with it
        else:
            raise InputError(f"expected a patterns.Pattern, Blank or Piece (or a list of them), got "
                             f"{type(item).__name__}")
    several = len({group[0] for group in groups}) > 1  # a panel's name then says its part: "cup/face0"
    out = []
    for part, ps, prefix, made in groups:
        for p in ps:
            p = replace(p, name=f"{printable(part)}/{p.name}") if several and prefix else p
            if made:  # its labels placed once, here, and kept: the notes and every writer read them
                p = with_labels(p, unit)
                p = replace(p, findings=tuple(p.findings) + label_findings(p))
            out.append(p)
    return tuple(out)
