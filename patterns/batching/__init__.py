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
from collections.abc import Callable
from pathlib import Path

from ..audit import CheckOptions
from ..errors import InputError, PatternsError, Terminated
from ..export import WriteOptions
from ..files import Outputs
from ..flattening import FlattenOptions
from ..nesting import NestOptions
from ..pieces import PieceOptions
from ..reading import LoadOptions
from ..sheetmetal import UnfoldOptions
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
    wanted,
)
from .worker import process_part

__all__ = ["STATUSES", "BatchOptions", "BatchResult", "Row", "batch", "check_output_folder", "output_stems",
           "plan_batch", "process_part"]

_FLATTEN = {"load": LoadOptions, "flatten": FlattenOptions, "check": CheckOptions, "pieces": PieceOptions,
            "write": WriteOptions, "nest": NestOptions}
"""The records of a part that is flattened."""
_UNFOLD = {"unfold": UnfoldOptions, "check": CheckOptions, "pieces": PieceOptions, "write": WriteOptions,
           "nest": NestOptions}
"""The records of a part that is unfolded."""


def batch(files, out, *, records: dict | None = None, options: BatchOptions | None = None,
          on_row: Callable | None = None, on_start: Callable | None = None, **keywords) -> BatchResult:
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
    records : dict, optional
        The part's option records (``"load"``, ``"flatten"``, ``"check"``,
        ``"dxf"``, ``"nest"``), as the command line makes them; default from
        ``keywords``.
    options : BatchOptions, optional
        How the batch runs; keywords (``jobs``, ``scheduler``, ``timeout``,
        ``memory``, ``report``, ``preview``, ``heat_map``) go over it.
    on_row : callable, optional
        ``on_row(row, done, total)`` as each file ends (progress).
    on_start : callable, optional
        ``on_start(name)`` as each file is handed to a worker.
    **keywords
        Any option of ``flatten``: :class:`~patterns.LoadOptions`,
        :class:`~patterns.FlattenOptions`, :class:`~patterns.CheckOptions`,
        :class:`~patterns.DxfOptions`, :class:`~patterns.NestOptions` (each
        part nested on its own roll or sheets) fields, and :class:`BatchOptions` fields.

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
    opts, records = _options(options, records, keywords)
    if isinstance(files, (str, os.PathLike)) and Path(files).is_dir():
        files, stems = plan_batch(files, out, unfold=opts.unfold)
    else:
        from ..reading import check_source

        files = [check_source(f) for f in ([files] if isinstance(files, (str, os.PathLike)) else files)]
        if not files:
            raise InputError("no files to flatten")
        check_output_folder(out)
        stems = output_stems(files)
    out = Path(out)
    kinds = wanted(opts)
    runner = DaskRunner(opts) if opts.scheduler else LocalRunner(opts, len(files))
    if opts.scheduler:
        runner.connect()  # the address, the workers and their patterns checked before any work
    rows = {}
    stopped = ""
    try:
        for index, row in runner.run(files, records, kinds, on_start):
            path = files[index]
            row = _commit(out, stems[path], row)
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
    return BatchResult(tuple(rows[i] for i in range(len(files))), runner.where, stopped)


def _options(options, records, keywords):
    mine = {k: v for k, v in keywords.items() if k in BatchOptions.__dataclass_fields__}
    rest = {k: v for k, v in keywords.items() if k not in mine}
    opts = BatchOptions.of(options, mine)
    if records is None:
        kinds = dict(_UNFOLD if opts.unfold else _FLATTEN)
        records = {}
        for key, record in kinds.items():
            fields = record.__dataclass_fields__
            records[key] = record.of(None, {k: v for k, v in rest.items() if k in fields})
        unknown = sorted(set(rest) - {f for r in kinds.values() for f in r.__dataclass_fields__})
        if unknown:
            raise InputError(f"unknown option {unknown[0]!r} for batch{' --unfold' if opts.unfold else ''}")
    elif rest:
        raise InputError(f"give the part's options as records or as keywords, not both ({min(rest)!r})")
    if opts.unfold and opts.heat_map:
        raise InputError("a blank is exact: it has no strain heat map (leave out heat_map with unfold)")
    return opts, records


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
               strain_max=row.get("strain_max"), seconds=float(row.get("seconds", 0.0)), written=written)
