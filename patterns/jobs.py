"""One part through the whole pipeline, as one run: checked before any work, written all at once.

A run of ``patterns flatten`` or ``patterns unfold`` (or one file of
``patterns batch``) goes in three steps, so that a refused run writes nothing
and no run destroys a file it was not asked to write:

1. **plan** -- before the input is read: every option checked by its
   declaration (a :class:`patterns.bundle.Bundle` of the option records), the input checked
   (a readable regular file of a known type), every output checked
   (:func:`plan_outputs`: its kind's suffix, a writable folder, not a folder
   or a device, not an input -- the part, a bend table, a flat pattern to
   compare with -- not another output);
2. **work** -- :func:`flatten_part` or :func:`unfold_part`: load, the checks
   that need the part (:func:`check_part`), flatten or unfold, make the
   pieces, nest them, check, and write every output to the place ``stage``
   gives (temporary files);
3. **commit** -- the caller renames them all onto their targets
   (:class:`patterns.files.Outputs`), or removes them all.

Patterns and blanks go the same way from the pieces on: one drawing
(:class:`patterns.pieces.Drawing`), one check report in its frame, one set of
writers.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path

from .audit import Report, check, checked_drawing
from .blank import Blank
from .bundle import Bundle
from .comparison import BlankComparison, FlatPattern, compare_blank
from .errors import InputError
from .export import WriteOptions, heat_map, preview_dxf, write, write_flat_obj
from .export.registry import profile_for
from .files import output_target
from .flattening import flatten
from .mesh import extent
from .model import Model
from .nesting import Layout, check_piece_count, layout
from .pattern import Pattern
from .pieces import Drawing, check_marks, drawing_of
from .reading import load
from .sheetmetal import unfold
from .units import Unit

__all__ = ["OUTPUT_KINDS", "PartResult", "check_part", "flatten_part", "plan_outputs", "unfold_part"]

OUTPUT_KINDS = {
    "pattern": ((".dxf", ".svg", ".obj"), "pattern"),
    "report": ((".json",), "report"),
    "heat_map": ((".png", ".svg"), "heat map"),
    "preview": ((".png", ".svg"), "preview"),
    "bend_sheet": ((".csv",), "bend sheet"),
}
"""What a run writes: ``{kind: (suffixes, what it is called in messages)}``, in the order written."""

_FLAGS = {"pattern": "-o", "report": "--report", "heat_map": "--heat-map", "preview": "--preview",
          "bend_sheet": "--bend-sheet"}

_DXF = ("machine", "astm")
"""Profiles that only choose the DXF's dialect: with another output suffix they are not asked for."""


def inputs_of(source, bundle: Bundle) -> list:
    """Every file a run reads: the part, and a bend table or a material table when one is given (no output may
    name them)."""
    out = [Path(source)]
    unfolding = bundle.unfold
    if unfolding is not None and unfolding.bend_table is not None:
        out.append(Path(unfolding.bend_table.path))
    if unfolding is not None and unfolding.material_table is not None and unfolding.material_table.path:
        out.append(Path(unfolding.material_table.path))
    return out


def plan_outputs(outputs: dict, *, inputs=(), suffixes: dict | None = None, profile: str | None = None) -> dict:
    """The run's outputs checked before any work: ``{kind: Path}`` (kinds given None left out).

    Parameters
    ----------
    outputs : dict
        ``{kind: path or None}``, kinds of :data:`OUTPUT_KINDS`.
    inputs : iterable of path
        The run's inputs (the part, a bend table, a file compared with), which no output may name.
    suffixes : dict, optional
        ``{kind: suffixes}`` narrower than :data:`OUTPUT_KINDS` (a blank has no flat mesh).
    profile : str, optional
        The profile asked for the pattern (``--profile``): it must write the pattern's suffix.

    Raises
    ------
    InputError
        A suffix the kind does not write, a preview without a DXF, an output
        that cannot be written (:func:`patterns.files.output_target`), one that
        names an input, or two outputs naming one file.
    """
    planned = {}
    for kind, path in outputs.items():
        if path is None:
            continue
        allowed, what = OUTPUT_KINDS[kind]
        allowed = (suffixes or {}).get(kind, allowed)
        path = Path(path)
        if path.suffix.lower() not in allowed:
            said = " or ".join(allowed) if len(allowed) < 3 else f"{', '.join(allowed[:-1])} or {allowed[-1]}"
            raise InputError(f"{path}: {_FLAGS[kind]} writes {said}, not {path.suffix.lower() or '(no suffix)'!r}")
        target = output_target(path, what=what, inputs=inputs, error=InputError)
        for other_kind, other in planned.items():
            if output_target(other, what=what, error=InputError) == target:
                raise InputError(f"{path}: given twice, as {_FLAGS[other_kind]} and {_FLAGS[kind]}; "
                                 f"name two files")
        planned[kind] = path
    pattern = planned.get("pattern")
    if pattern is not None and pattern.suffix.lower() != ".obj":
        profile_for(pattern, profile if pattern.suffix.lower() == ".dxf" or profile not in _DXF else None)
    if "preview" in planned and ("pattern" not in planned or planned["pattern"].suffix.lower() != ".dxf"):
        raise InputError(f"{planned['preview']}: --preview renders the DXF file; write the pattern as .dxf")
    return planned


def check_part(model: Model, bundle: Bundle, outputs: dict) -> None:
    """The checks that need the part but come before flattening it (InputError, in well under a second).

    A flat OBJ holds one panel; ``notch_spacing`` and ``bend_spacing`` must not
    ask for more marks than :data:`patterns.pieces.options.MAX_MARKS` on this part
    (its seams' 3D lengths, its panels' sizes); a nest takes at most
    :data:`patterns.nesting.MAX_PIECES` pieces.
    """
    pattern_path = outputs.get("pattern")
    if pattern_path is not None and pattern_path.suffix.lower() == ".obj" and len(model.panels) != 1:
        raise InputError(f"{model.name}: {len(model.panels)} panels; a flat .obj holds one, write a .dxf")
    if bundle.pieces is not None:
        check_marks(model.name, [s.length for s in model.seams],
                    [extent(p.vertices) for p in model.panels], bundle.pieces)
    nesting = bundle.nest
    if nesting is not None and nesting.active:  # a panel a piece (gores and darts may add more, checked again)
        quantities = nesting.quantities or {}
        check_piece_count(model.name, [quantities.get(p.name, nesting.copies) for p in model.panels], nesting)


@dataclass(frozen=True, eq=False)
class PartResult:
    """What :func:`flatten_part` or :func:`unfold_part` did.

    Attributes
    ----------
    subject : patterns.Pattern or patterns.Blank
        What was flattened or unfolded.
    model : patterns.Model or None
        The part as loaded (None for an unfold, which reads the solid itself).
    report : patterns.Report
        The check, in the drawing's frame.
    drawing : patterns.pieces.Drawing
        The pieces as written (nested when a roll or sheet was given).
    written : dict
        ``{kind: staged path}`` of every output written.
    seconds : dict
        Seconds of each step, each alone: ``{"load", "flatten", "nest", "check", "write"}`` (an unfold's
        ``"flatten"`` is its unfolding; a blank that cannot be cut has ``"load"`` and ``"flatten"`` only).
    nest : patterns.Layout or None
    preview_dpi : float or None
        The resolution of a PNG preview (lowered for a large drawing).
    comparison : patterns.BlankComparison or None
        An unfold compared with another CAD program's flat pattern.
    sheet_files : tuple of Path
        Each sheet's own file (``sheet_files``), as named (staged where ``stage`` said).
    """

    subject: Pattern | Blank
    model: Model | None
    report: Report
    drawing: Drawing
    written: dict = field(default_factory=dict)
    seconds: dict = field(default_factory=dict)
    nest: Layout | None = None
    preview_dpi: float | None = None
    comparison: BlankComparison | None = None
    sheet_files: tuple = ()



def _laid_out(subject, bundle: Bundle) -> tuple:
    """``(drawing, nest or None)``: the subject's pieces, nested when the bundle gives a roll or sheet."""
    unit = bundle.write.units  # the labels placed once, for the file's unit
    if bundle.nest.active:
        nest = layout(subject, bundle.nest, pieces=bundle.pieces, unit=unit)
        return nest.drawing(), nest
    return drawing_of(subject, bundle.pieces, unit=unit), None


def _write(subject, drawing: Drawing, checked: Drawing, options: WriteOptions, outputs: dict,
           stage: Callable) -> tuple:
    """Every output, each to where ``stage`` says: ``({kind: staged path}, preview dpi, sheet files)``."""
    written, dpi, sheets = {}, None, []
    for kind, path in outputs.items():
        tmp = stage(path, what=OUTPUT_KINDS[kind][1])
        if kind == "pattern" and path.suffix.lower() == ".obj":
            unit = Unit(options.units)  # one unit for the whole run: the DXF's and the OBJ's
            flat = subject.panels[0]
            write_flat_obj(tmp, flat.uv / unit.mm, flat.faces)
        elif kind == "pattern":
            dialect = options.profile if path.suffix.lower() == ".dxf" or options.profile not in _DXF else None
            write(drawing, tmp, replace(options, profile=dialect))
            if options.sheet_files:  # each sheet a file of its own, for the machine
                for k, sheet in enumerate(drawing.sheet_drawings(), start=1):
                    extra = path.with_name(f"{path.stem}-{k}{path.suffix}")
                    write(sheet, stage(extra, what=f"sheet {k}"), replace(options, profile=dialect))
                    sheets.append(extra)
        elif kind == "report":
            write(checked, tmp, replace(options, profile="json"))
        elif kind == "heat_map":
            heat_map(subject, tmp)
        elif kind == "bend_sheet":
            write(drawing, tmp, replace(options, profile="bends"))  # the bend lines where the DXF draws them
        else:
            dpi = preview_dxf(written["pattern"], tmp)
        written[kind] = tmp
    return written, dpi, tuple(sheets)


def flatten_part(source, bundle: Bundle, *, outputs: dict, stage: Callable, progress=None,
                 loaded: Callable | None = None) -> PartResult:
    """Load, check the options against the part, flatten, make and nest the pieces, check, write every output.

    Parameters
    ----------
    source : str or Path
        The part's file.
    bundle : patterns.bundle.Bundle
        The run's options, a ``flatten`` bundle (its ``nest`` nests the pieces on a roll or sheets when it
        gives one).
    outputs : dict
        ``{kind: Path}`` as :func:`plan_outputs` returns it.
    stage : callable
        ``stage(path, what=...) -> Path``: where to write the output named
        ``path`` (a temporary file the caller renames when all are written).
    progress : callable, optional
        ``progress(done, total)`` while flattening.
    loaded : callable, optional
        ``loaded(model, seconds)``, called once the part is read.

    Returns
    -------
    PartResult
    """
    seconds = {}
    start = time.perf_counter()
    model = load(source, bundle.load)
    check_part(model, bundle, outputs)
    seconds["load"] = time.perf_counter() - start
    if loaded is not None:
        loaded(model, seconds["load"])
    start = time.perf_counter()
    pattern = flatten(model, bundle.flatten, progress=progress)
    seconds["flatten"] = time.perf_counter() - start
    start = time.perf_counter()
    drawing, nest = _laid_out(pattern, bundle)
    seconds["nest"] = time.perf_counter() - start
    start = time.perf_counter()
    report, checked = checked_drawing(pattern, drawing, bundle.check)
    seconds["check"] = time.perf_counter() - start
    start = time.perf_counter()
    written, dpi, sheets = _write(pattern, drawing, checked, bundle.write, outputs, stage)
    seconds["write"] = time.perf_counter() - start
    return PartResult(pattern, model, report, drawing, written, seconds, nest, dpi, sheet_files=sheets)


def unfold_part(source, bundle: Bundle, *, outputs: dict, stage: Callable,
                reference: FlatPattern | None = None) -> PartResult:
    """Unfold a bent sheet-metal part, make and nest its blank's pieces, check, write every output.

    ``bundle``: the run's options, an ``unfold`` :class:`~patterns.bundle.Bundle`.  A blank that cannot be cut as it is (flanges that collide) writes nothing: its
    result's report says why.  ``reference``: another CAD program's flat pattern of the part
    (:func:`patterns.read_flat_pattern`), compared in the result and the report.
    """
    seconds = {}
    start = time.perf_counter()
    blank = unfold(source, bundle.unfold)
    seconds["load"] = 0.0
    comparison = compare_blank(blank, reference) if reference is not None else None
    if not blank.ok:
        seconds["flatten"] = time.perf_counter() - start
        return PartResult(blank, None, check(blank, bundle.check), drawing_of(blank, bundle.pieces),
                          seconds=seconds, comparison=comparison)
    seconds["flatten"] = time.perf_counter() - start
    start = time.perf_counter()
    drawing, nest = _laid_out(blank, bundle)
    seconds["nest"] = time.perf_counter() - start
    start = time.perf_counter()
    report, checked = checked_drawing(blank, drawing, bundle.check)
    if comparison is not None:
        checked = replace(checked, report={**checked.report, "comparison": comparison.to_dict(reference.path)})
    seconds["check"] = time.perf_counter() - start
    start = time.perf_counter()
    written, dpi, sheets = _write(blank, drawing, checked, bundle.write, outputs, stage)
    seconds["write"] = time.perf_counter() - start
    return PartResult(blank, None, report, drawing, written, seconds, nest, dpi, comparison, sheets)
