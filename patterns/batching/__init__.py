"""Many parts at once: every file ends as a row, whatever happens to the others.

Work travels as data, on the local process pool and on a Dask cluster alike:
the client reads each input (its name, suffix and bytes); a worker writes the
bytes to a private temporary folder, runs the whole pipeline on them
(:func:`patterns.jobs.flatten_part`, or with ``unfold``
:func:`patterns.jobs.unfold_part`) and returns every output as bytes; the
client writes them into the output folder as they arrive, all of one part or
none (:class:`patterns.files.Outputs`).  Relative paths, a cluster with no
shared disk and any worker's working folder all work; nothing is written on a
worker.

Every file ends as one :class:`Row`: ``ok``; ``check failed`` (written, but the
pattern is not usable or fails a limit asked for); ``failed`` (its one-line
reason, nothing written); ``timeout`` (stopped after ``timeout`` seconds);
``lost`` (its worker died, and died again on the one retry: the OOM killer, a
crash in native code); ``not run`` (the batch was stopped first).  A stopped
batch (Ctrl-C, SIGTERM) stops its workers and still returns its rows.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Callable
from pathlib import Path

from ..bundle import Bundle
from ..errors import InputError, PatternsError, Terminated
from ..files import Outputs
from ..text import printable
from .cluster import DaskRunner
from .local import LocalRunner
from .plan import (
    _SUFFIXES,
    STATUSES,
    BatchOptions,
    BatchResult,
    Row,
    check_output_folder,
    output_stems,
    plan_batch,
    skipped_in,
    wanted,
)
from .worker import process_part

__all__ = ["STATUSES", "BatchOptions", "BatchResult", "Row", "batch", "check_output_folder", "output_stems",
           "plan_batch", "process_part", "skipped_in"]

_TWO_WAYS = {"max_strain": "dart_strain", "gap": "nest_gap", "units": "input_units"}
"""Keywords that 0.2.0's ``batch`` gave to two records (``max_strain`` the darts' and the check's limit, ``gap`` the
pieces' and the nester's, ``units`` a mesh's and the drawing's): they still do, with a warning, until 0.3.0 (then
the check's, the pieces' and the drawing's only)."""


def batch(files, out, *, bundle: Bundle | None = None, options: BatchOptions | None = None,
          on_row: Callable | None = None, on_start: Callable | None = None, records: dict | None = None,
          **keywords) -> BatchResult:
    """Flatten many parts in parallel into one folder: every file ends as a :class:`Row`.

    Parameters
    ----------
    files : str, Path or sequence of them
        A folder (every CAD and mesh file directly in it) or the files.
    out : str or Path
        The output folder (made if missing; its folder must exist):
        ``NAME.dxf`` and ``NAME.json`` per part (``NAME_preview.png``,
        ``NAME_heatmap.png`` if asked), ``NAME`` the input's stem -- or its whole
        name where two stems collide (``a.step.dxf``, ``a.stl.dxf``), compared
        ignoring case; whole names that still collide are numbered
        (``part.step-2.dxf``): see :func:`output_stems`.
    bundle : patterns.bundle.Bundle, optional
        The part's options, a ``flatten`` bundle (``unfold`` with
        ``unfold=True``), as the command line makes it; default from
        ``keywords``.
    options : BatchOptions, optional
        How the batch runs; keywords (``jobs``, ``scheduler``, ``timeout``,
        ``memory``, ``report``, ``preview``, ``heat_map``) go over it.
    on_row : callable, optional
        ``on_row(row, done, total)`` as each file ends (progress).
    on_start : callable, optional
        ``on_start(name)`` as each file is handed to a worker.
    records : dict, optional
        Deprecated (goes in 0.3.0): ``{"load": LoadOptions, ...}``; give ``bundle``.
    **keywords
        Any option of the bundle, by its name (:meth:`patterns.bundle.Bundle.names`: the fields of
        :class:`~patterns.LoadOptions`, :class:`~patterns.FlattenOptions`, :class:`~patterns.CheckOptions`,
        :class:`~patterns.PieceOptions`, :class:`~patterns.WriteOptions`, :class:`~patterns.NestOptions`,
        each part nested on its own roll or sheets; ``dart_strain`` is the darts' limit, ``max_strain``
        the check's, ``nest_gap`` the nester's gap), and :class:`BatchOptions` fields.

    Returns
    -------
    BatchResult

    Raises
    ------
    InputError
        Before any work: a bad option, no such folder or file, no part files,
        an output folder that cannot be made or written.

    Notes
    -----
    Safe at a script's top level, with no ``if __name__ == "__main__":`` guard:
    the local workers are fresh interpreters that run only this package
    (:mod:`patterns.batching.local`) and never import the caller's ``__main__``.
    """
    from ..reading import CAD_SUFFIXES, check_source

    opts, bundle = _options(options, bundle, records, keywords)
    skipped = ()
    if isinstance(files, (str, os.PathLike)) and Path(files).is_dir():
        skipped = skipped_in(files, unfold=opts.unfold)
        files, stems = plan_batch(files, out, unfold=opts.unfold)
    else:
        files = [Path(f) for f in ([files] if isinstance(files, (str, os.PathLike)) else files)]
        if not files:
            raise InputError("no files to flatten")
        check_output_folder(out)
        stems = output_stems(files)
    out = Path(out)
    refused = {}  # every file is its own row: one that cannot be read (permissions, size) fails alone
    for index, path in enumerate(files):
        try:
            check_source(path, CAD_SUFFIXES if opts.unfold else None)
        except InputError as exc:
            refused[index] = Row(printable(path.name), "failed", str(exc))
    todo = [i for i in range(len(files)) if i not in refused]
    kinds = wanted(opts)
    runner = DaskRunner(opts) if opts.scheduler else LocalRunner(opts, max(1, len(todo)))
    if opts.scheduler:
        runner.connect()  # the address, the workers and their patterns checked before any work
    rows = {}
    stopped = ""
    for index, row in refused.items():
        rows[index] = row
        if on_row is not None:
            on_row(row, len(rows), len(files))
    try:
        for k, row in runner.run([files[i] for i in todo], bundle, kinds, on_start) if todo else ():
            index = todo[k]
            row = _commit(out, stems[files[index]], row)
            rows[index] = row
            if on_row is not None:
                on_row(row, len(rows), len(files))
    except KeyboardInterrupt:
        stopped = "interrupted"
    except Terminated:
        stopped = "terminated"
    finally:
        runner.close()
    for index, path in enumerate(files):
        if index not in rows:
            rows[index] = Row(printable(path.name), "not run", f"the batch was {stopped or 'stopped'} first")
    skipped_rows = tuple(Row(name, "skipped", why) for name, why in skipped)
    return BatchResult(tuple(rows[i] for i in range(len(files))) + skipped_rows, runner.where, stopped)


def _options(options, bundle, records, keywords) -> tuple:
    """``(BatchOptions, Bundle)`` from what :func:`batch` was given, every value checked."""
    mine = {k: v for k, v in keywords.items() if k in BatchOptions.__dataclass_fields__}
    rest = {k: v for k, v in keywords.items() if k not in mine}
    opts = BatchOptions.of(options, mine)
    kind = "unfold" if opts.unfold else "flatten"
    if records is not None:
        warnings.warn("batch(records=) goes in 0.3.0: give bundle=patterns.bundle.Bundle(...)", DeprecationWarning,
                      stacklevel=3)
        bundle = Bundle(kind, **records)
    if bundle is None:
        names = {n.name for n in Bundle.names(kind)}
        for old, new in _TWO_WAYS.items():
            if old in rest and new not in rest and new in names:
                warnings.warn(f"batch({old}=) sets {old} and {new} (as 0.2.0 did) until 0.3.0, then {old} only: "
                              f"give {new}= as well", DeprecationWarning, stacklevel=3)
                rest[new] = rest[old]
        bundle = Bundle.of(kind, rest, name=f"batch{' (unfold)' if opts.unfold else ''}")
    elif rest:
        raise InputError(f"give the part's options as a bundle or as keywords, not both ({min(rest)!r})")
    if not isinstance(bundle, Bundle) or bundle.kind != kind:
        raise InputError(f"bundle must be a patterns {kind} Bundle, got {bundle!r}")
    if bundle.write.sheet_files:
        raise InputError("sheet_files writes a file per sheet of one part's nest: give it to flatten or unfold, "
                         "not to a batch")
    if opts.unfold and opts.heat_map:
        raise InputError("a blank is exact: it has no strain heat map (leave out heat_map with unfold)")
    return opts, bundle


def _commit(out: Path, stem: str, row: dict) -> Row:
    """Write one part's outputs into ``out`` (all or none): the row as it ends."""
    files = row.pop("files", {}) or {}
    written = ()
    if files:
        try:
            out.mkdir(parents=False, exist_ok=True)
            with Outputs() as outputs:
                names = []
                for kind, data in files.items():
                    target = out / _SUFFIXES[kind].format(stem)
                    outputs.stage(target, what=kind.replace("_", " ")).write_bytes(data)
                    names.append(target.name)
                outputs.commit()
            written = tuple(names)
        except (PatternsError, OSError) as exc:
            row.update(status="failed", reason=f"cannot write its results: {exc}")
    return Row(file=printable(row["file"]), status=row["status"], reason=printable(row.get("reason", "")),
               panels=row.get("panels"), seams=row.get("seams"), strain_rms=row.get("strain_rms"),
               strain_max=row.get("strain_max"), seconds=float(row.get("seconds", 0.0)), written=written,
               thickness=row.get("thickness"), size=row.get("size"), bends=row.get("bends"))
