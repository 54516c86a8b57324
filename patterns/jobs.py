"""One part through the whole pipeline, as one run: checked before any work, written all at once.

A run of ``patterns flatten`` (or one file of ``patterns batch``) goes in three
steps, so that a refused run writes nothing and no run destroys a file it was
not asked to write:

1. **plan** -- before the input is read: every option checked by its
   declaration (the records of :mod:`patterns.options`), the input checked
   (a readable regular file of a known type), every output checked
   (:func:`plan_outputs`: its kind's suffix, a writable folder, not a folder
   or a device, not the input, not another output);
2. **work** -- :func:`flatten_part`: load, the checks that need the part
   (:func:`check_part`: a one-panel part for a flat OBJ, the notch and bend
   counts the spacing options would draw), flatten, nest, check, and every
   output written to the place ``stage`` gives (temporary files);
3. **commit** -- the caller renames them all onto their targets
   (:class:`patterns.files.Outputs`), or removes them all.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .errors import InputError
from .files import output_target
from .units import Unit

__all__ = ["OUTPUT_KINDS", "PartResult", "check_part", "flatten_part", "plan_outputs"]

OUTPUT_KINDS = {
    "pattern": ((".dxf", ".obj"), "pattern"),
    "report": ((".json",), "report"),
    "heat_map": ((".png", ".svg"), "heat map"),
    "preview": ((".png", ".svg"), "preview"),
}
"""What a run writes: ``{kind: (suffixes, what it is called in messages)}``, in the order written."""

_FLAGS = {"pattern": "-o", "report": "--report", "heat_map": "--heat-map", "preview": "--preview"}


def plan_outputs(outputs: dict, *, inputs=()) -> dict:
    """The run's outputs checked before any work: ``{kind: Path}`` (kinds given None left out).

    Parameters
    ----------
    outputs : dict
        ``{kind: path or None}``, kinds of :data:`OUTPUT_KINDS`.
    inputs : iterable of path
        The run's inputs, which no output may name.

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
        suffixes, what = OUTPUT_KINDS[kind]
        path = Path(path)
        if path.suffix.lower() not in suffixes:
            raise InputError(f"{path}: {_FLAGS[kind]} writes {' or '.join(suffixes)}, not "
                             f"{path.suffix.lower() or '(no suffix)'!r}")
        target = output_target(path, what=what, inputs=inputs, error=InputError)
        for other_kind, other in planned.items():
            if output_target(other, what=what, error=InputError) == target:
                raise InputError(f"{path}: given twice, as {_FLAGS[other_kind]} and {_FLAGS[kind]}; "
                                 f"name two files")
        planned[kind] = path
    if "preview" in planned and ("pattern" not in planned or planned["pattern"].suffix.lower() != ".dxf"):
        raise InputError(f"{planned['preview']}: --preview renders the DXF file; write the pattern as .dxf")
    return planned


def check_part(model, records: dict, outputs: dict) -> None:
    """The checks that need the part but come before flattening it (InputError, in well under a second).

    A flat OBJ holds one panel; ``notch_spacing`` and ``bend_spacing`` must not
    ask for more marks than :data:`patterns.export.dxf.MAX_MARKS` on this part
    (its seams' 3D lengths, its panels' sizes).
    """
    from .export.dxf import check_marks

    pattern_path = outputs.get("pattern")
    if pattern_path is not None and pattern_path.suffix.lower() == ".obj" and len(model.panels) != 1:
        raise InputError(f"{model.name}: {len(model.panels)} panels; a flat .obj holds one, write a .dxf")
    if "dxf" in records:
        check_marks(model.name, [s.length for s in model.seams],
                    [float(np.ptp(p.vertices, axis=0).max()) for p in model.panels], records["dxf"])


@dataclass(frozen=True, eq=False)
class PartResult:
    """What :func:`flatten_part` did.

    Attributes
    ----------
    model : patterns.Model
    pattern : patterns.Pattern
        As written (nested when a roll width was given).
    report : patterns.audit.Report
    written : dict
        ``{kind: staged path}`` of every output written.
    seconds : dict
        ``{"load": s, "flatten": s, "write": s}``.
    nest : patterns.nesting.Layout or None
    preview_dpi : float or None
        The resolution of a PNG preview (lowered for a large drawing).
    """

    model: object
    pattern: object
    report: object
    written: dict = field(default_factory=dict)
    seconds: dict = field(default_factory=dict)
    nest: object = None
    preview_dpi: float | None = None


def flatten_part(source, records: dict, *, outputs: dict, stage: Callable, progress=None,
                 loaded: Callable | None = None) -> PartResult:
    """Load, check the options against the part, flatten, nest, check, and write every output.

    Parameters
    ----------
    source : str or Path
        The part's file.
    records : dict
        The option records: ``"load"`` (LoadOptions), ``"flatten"``,
        ``"check"``, ``"dxf"`` when a pattern is written, and ``"nest"``
        (NestOptions: the pieces nested on a roll or sheets when it gives one).
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
    from .audit import check
    from .flattening import flatten
    from .reading import load

    seconds = {}
    start = time.perf_counter()
    model = load(source, records["load"])
    check_part(model, records, outputs)
    seconds["load"] = time.perf_counter() - start
    if loaded is not None:
        loaded(model, seconds["load"])
    start = time.perf_counter()
    pattern = flatten(model, records["flatten"], progress=progress)
    nest = None
    if records.get("nest") is not None and records["nest"].active:
        nest = pattern.layout(records["nest"])
        pattern = nest.pattern
    report = check(pattern, records["check"])
    seconds["flatten"] = time.perf_counter() - start
    start = time.perf_counter()
    written, dpi = {}, None
    for kind, path in outputs.items():
        tmp = stage(path, what=OUTPUT_KINDS[kind][1])
        if kind == "pattern" and path.suffix.lower() == ".dxf":
            pattern.to_dxf(tmp, records["dxf"])
        elif kind == "pattern":
            from .export import write_flat_obj

            unit = Unit(records["dxf"].units)  # one unit for the whole run: the DXF's and the OBJ's
            flat = pattern.panels[0]
            write_flat_obj(tmp, flat.uv / unit.mm, flat.faces)
        elif kind == "report":
            report.to_json(tmp)
        elif kind == "heat_map":
            pattern.heat_map(tmp)
        else:
            from .export.preview import preview_dxf

            dpi = preview_dxf(written["pattern"], tmp)
        written[kind] = tmp
    seconds["write"] = time.perf_counter() - start
    return PartResult(model, pattern, report, written, seconds, nest, dpi)

