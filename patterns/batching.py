"""Many parts at once: every file ends as a row, whatever happens to the others.

Work travels as data, on the local process pool and on a Dask cluster alike:
the client reads each input (its name, suffix and bytes); a worker writes the
bytes to a private temporary folder, runs the whole pipeline on them
(:func:`patterns.jobs.flatten_part`) and returns every output as bytes; the
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

import contextlib
import os
import signal
import sys
import tempfile
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from .errors import InputError, PatternsError, Terminated
from .options import Options, option
from .text import printable

__all__ = ["BatchOptions", "BatchResult", "Row", "batch", "check_output_folder", "output_stems", "plan_batch",
           "process_part"]

STATUSES = ("ok", "check failed", "failed", "timeout", "lost", "not run")
"""What a row's status can be."""


@dataclass(frozen=True, repr=False)
class BatchOptions(Options):
    """How a batch runs (:func:`batch`, ``patterns batch``); the part's own options are those of ``flatten``."""

    jobs: int | None = option(None, "parallel processes on this machine (default: its CPU count); each runs one "
                                    "BLAS thread when there are several", integer=True, low=1, optional=True,
                              metavar="N")
    scheduler: str | None = option(None, "run on a Dask distributed cluster at this address (tcp://host:8786) "
                                         "instead of local processes; needs patterns[dask] here and patterns on "
                                         "every worker, no shared disk", optional=True, metavar="ADDRESS")
    wait: float = option(30.0, "Dask: seconds to wait for a first worker to join the scheduler", low=0,
                         low_open=True, high=86400, metavar="S")
    timeout: float = option(600.0, "seconds one file may take; a file still running then is stopped and reported "
                                   "(its worker replaced)", low=0, low_open=True, high=1e6, metavar="S")
    memory: float | None = option(None, "megabytes of memory (address space) one local worker process may use, "
                                        "at least 1024 (what starting one takes); a file that needs more fails "
                                        "alone (default: the machine's memory shared among the processes)",
                                  low=1024, optional=True, high=1e9, metavar="MB")
    report: bool = option(True, "write each part's JSON report (NAME.json); --no-report leaves it out")
    preview: bool = option(False, "also render each DXF at 1:1 (NAME_preview.png)")
    heat_map: bool = option(False, "also draw each part's strain heat map (NAME_heatmap.png)")
    quiet: bool = option(False, "no progress lines (the summary table still comes)")


@dataclass(frozen=True)
class Row:
    """One input file's fate.

    Attributes
    ----------
    file : str
        The input's name.
    status : str
        One of :data:`STATUSES`.
    reason : str
        Why it failed, timed out, was lost or fails its check ("" when ok).
    panels, seams : int or None
    strain_rms, strain_max : float or None
        The worst panel's, ratios.
    seconds : float
        Time on the worker (or until stopped).
    written : tuple of str
        The files written for it, in the output folder.
    """

    file: str
    status: str
    reason: str = ""
    panels: int | None = None
    seams: int | None = None
    strain_rms: float | None = None
    strain_max: float | None = None
    seconds: float = 0.0
    written: tuple = ()


@dataclass(frozen=True)
class BatchResult:
    """Every row, in the order of the input files, and how the batch ended.

    Attributes
    ----------
    rows : tuple of Row
    where : str
        What ran it (``"2 processes"``, ``"Dask scheduler tcp://..."``).
    stopped : str
        ``""``, or ``"interrupted"`` (Ctrl-C) or ``"terminated"`` (SIGTERM).
    """

    rows: tuple
    where: str
    stopped: str = ""

    def count(self, status: str) -> int:
        return sum(r.status == status for r in self.rows)

    @property
    def exit_code(self) -> int:
        """0 all ok; 1 some only fail a check; 2 some failed, timed out or were lost; 130/143 stopped."""
        if self.stopped:
            return 130 if self.stopped == "interrupted" else 143
        if any(r.status not in ("ok", "check failed") for r in self.rows):
            return 2
        return 1 if self.count("check failed") else 0


def output_stems(files) -> dict:
    """``{input path: output stem}``: the name without its suffix, unless two inputs would share it.

    ``a.step`` and ``a.stl`` both give ``a``: then each keeps its whole name
    (``a.step.dxf``, ``a.stl.dxf``), so that neither overwrites the other.  A
    stem that is not a plain name (``.``, ``..``, empty) keeps the whole name too.
    """
    stems = {}
    for path in files:
        stem = Path(path).stem
        stems[path] = stem if stem not in ("", ".", "..") else Path(path).name
    folded = {}
    for path, stem in stems.items():
        folded.setdefault(stem.casefold(), []).append(path)  # a.STEP and a.step collide on some disks too
    for group in folded.values():
        if len(group) > 1:
            for path in group:
                stems[path] = Path(path).name
    return stems


_SUFFIXES = {"pattern": "{}.dxf", "report": "{}.json", "preview": "{}_preview.png", "heat_map": "{}_heatmap.png"}


def _wanted(options: BatchOptions) -> tuple:
    return ("pattern",) + tuple(k for k in ("report", "heat_map", "preview") if getattr(options, k))


# --------------------------------------------------------------------------- #
# The worker's side: bytes in, bytes out
# --------------------------------------------------------------------------- #


def process_part(name: str, data: bytes, records: dict, wanted: tuple) -> dict:
    """Run the pipeline on one part given as bytes; return its row and outputs as bytes.  Never raises
    for the part's fault (a bad file, a limit, memory): that becomes the row's reason.

    Parameters
    ----------
    name : str
        The input's file name (its suffix says its type).
    data : bytes
        The file's content.
    records : dict
        The option records (``"load"``, ``"flatten"``, ``"check"``, ``"dxf"``, and ``"nest"``).
    wanted : tuple of str
        Output kinds: ``"pattern"`` (DXF), ``"report"``, ``"heat_map"``, ``"preview"``.

    Returns
    -------
    dict
        The :class:`Row` fields (``file``, ``status``, ...) and ``files``:
        ``{kind: bytes}`` of every output.
    """
    from .jobs import flatten_part

    start = time.perf_counter()
    row = {"file": name, "status": "failed", "reason": "", "files": {}}
    try:
        with tempfile.TemporaryDirectory(prefix="patterns-part-") as tmp:
            source = Path(tmp) / name
            source.write_bytes(data)
            outputs = {kind: Path(tmp) / _SUFFIXES[kind].format("out") for kind in wanted}
            try:
                part = flatten_part(source, records, outputs=outputs, stage=lambda path, what: path)
            except PatternsError as exc:
                row["reason"] = str(exc).replace(tmp + os.sep, "")
                return row
            report = part.report
            row["files"] = {kind: path.read_bytes() for kind, path in part.written.items()}
            row.update(status="ok" if report.ok else "check failed",
                       reason="" if report.ok else report.findings[0].message,
                       panels=len(part.model.panels), seams=len(part.model.seams),
                       strain_rms=max(p.strain_rms for p in report.panels),
                       strain_max=max(p.strain_max for p in report.panels))
    except MemoryError:
        row.update(status="failed", reason="out of memory (over the worker's memory budget)", files={})
    except Exception as exc:  # noqa: BLE001 - a defect of ours must not sink the batch: the row says what
        row.update(status="failed", reason=f"internal error: {type(exc).__name__}: {exc}", files={})
    finally:
        row["seconds"] = time.perf_counter() - start
    return row


def _worker_main(conn, budget: int | None, one_thread: bool) -> None:  # pragma: no cover - in a child process
    """A local worker: dies with its parent, ignores Ctrl-C (the parent stops it), stays in its memory budget,
    and never prints: what goes wrong goes back to the parent, or the worker just ends."""
    try:
        _die_with_parent()
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        if budget:
            import resource

            resource.setrlimit(resource.RLIMIT_AS, (budget, budget))
        if one_thread:
            from threadpoolctl import threadpool_limits

            threadpool_limits(1)
        try:  # the heavy imports now, not inside the first file's time
            import build123d  # noqa: F401
            import ezdxf  # noqa: F401
            import matplotlib.figure  # noqa: F401
            import trimesh  # noqa: F401

            from . import jobs  # noqa: F401
        except BaseException as exc:  # noqa: BLE001 - said to the parent, which stops the batch
            conn.send(("cannot start", f"{type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''}"))
            return
        conn.send("ready")  # a file's time starts when it is handed over, not while the worker starts
        while True:
            task = conn.recv()
            if task is None:
                return
            conn.send(process_part(*task))
    except MemoryError:  # even the file's bytes do not fit the budget: the parent says so
        os._exit(_OUT_OF_MEMORY)
    except BaseException:  # noqa: BLE001 - the parent sees the pipe close: the file is retried or lost
        os._exit(1)


_OUT_OF_MEMORY = 3
"""A local worker's exit code when a file's bytes alone exceed its memory budget."""


def _die_with_parent() -> None:
    """Linux: SIGKILL this process when its parent dies (a killed batch leaves no worker behind)."""
    if sys.platform.startswith("linux"):
        import ctypes

        with contextlib.suppress(OSError, AttributeError):
            ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG


# --------------------------------------------------------------------------- #
# The client's side
# --------------------------------------------------------------------------- #


def plan_batch(folder, out) -> tuple[list, dict]:
    """The input files and their output stems, checked before any work (InputError otherwise)."""
    from .reading import CAD_SUFFIXES, MESH_SUFFIXES

    folder, out = Path(folder), Path(out)
    if not folder.is_dir():
        raise InputError(f"{os.fsdecode(folder)}: no such folder")
    files = sorted(p for p in folder.iterdir() if p.suffix.lower() in CAD_SUFFIXES + MESH_SUFFIXES and p.is_file())
    if not files:
        raise InputError(f"{os.fsdecode(folder)}: no CAD or mesh files in this folder")
    check_output_folder(out)
    return files, output_stems(files)


def check_output_folder(out) -> None:
    """InputError unless ``out`` is a writable folder, or one that can be made (its folder exists, writable)."""
    out = Path(out)
    if out.exists():
        if not out.is_dir():
            raise InputError(f"{os.fsdecode(out)}: is a file; name a folder for the results")
        if not os.access(out, os.W_OK | os.X_OK):
            raise InputError(f"{os.fsdecode(out)}: the output folder is not writable (permission denied)")
    else:
        parent = out.parent if str(out.parent) else Path(".")
        if not parent.is_dir() or not os.access(parent, os.W_OK | os.X_OK):
            raise InputError(f"{os.fsdecode(out)}: cannot create the output folder (its folder "
                             f"{os.fsdecode(parent)} is missing or not writable)")


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
        name where two stems collide (``a.step.dxf``, ``a.stl.dxf``).
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
    """
    opts, records = _options(options, records, keywords)
    if isinstance(files, (str, os.PathLike)) and Path(files).is_dir():
        files, stems = plan_batch(files, out)
    else:
        from .reading import check_source

        files = [check_source(f) for f in ([files] if isinstance(files, (str, os.PathLike)) else files)]
        if not files:
            raise InputError("no files to flatten")
        check_output_folder(out)
        stems = output_stems(files)
    out = Path(out)
    wanted = _wanted(opts)
    runner = _DaskRunner(opts) if opts.scheduler else _LocalRunner(opts, len(files))
    if opts.scheduler:
        runner.connect()  # the address, the workers and their patterns checked before any work
    rows = {}
    stopped = ""
    try:
        for index, row in runner.run(files, records, wanted, on_start):
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
    from .audit import CheckOptions
    from .export.dxf import DxfOptions
    from .flattening import FlattenOptions
    from .nesting import NestOptions
    from .reading import LoadOptions

    kinds = {"load": LoadOptions, "flatten": FlattenOptions, "check": CheckOptions, "dxf": DxfOptions,
             "nest": NestOptions}
    mine = {k: v for k, v in keywords.items() if k in BatchOptions.__dataclass_fields__}
    rest = {k: v for k, v in keywords.items() if k not in mine}
    opts = BatchOptions.of(options, mine)
    if records is None:
        records = {}
        for key, record in kinds.items():
            fields = record.__dataclass_fields__
            records[key] = record.of(None, {k: v for k, v in rest.items() if k in fields})
        unknown = sorted(set(rest) - {f for r in kinds.values() for f in r.__dataclass_fields__})
        if unknown:
            raise InputError(f"unknown option {unknown[0]!r} for batch")
        allowance = records["dxf"].seam_allowance  # a piece's room when nested: its largest seam allowance
        margin = max(allowance.values(), default=0.0) if isinstance(allowance, dict) else allowance
        if "margin" not in rest and margin:
            records["nest"] = NestOptions.of(records["nest"], {"margin": margin})
    elif rest:
        raise InputError(f"give the part's options as records or as keywords, not both ({sorted(rest)[0]!r})")
    return opts, records


def _commit(out: Path, stem: str, row: dict) -> Row:
    """Write one part's outputs into ``out`` (all or none): the row as it ends."""
    from .files import Outputs

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


# --------------------------------------------------------------------------- #
# The local pool: processes of our own, so that one can be stopped or lost alone
# --------------------------------------------------------------------------- #


@contextlib.contextmanager
def _environment(**values):
    saved = {k: os.environ.get(k) for k in values}
    os.environ.update({k: str(v) for k, v in values.items()})
    try:
        yield
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def _largest_first(files) -> list[int]:
    """The files' indices, largest file first: the longest work first balances the workers best (rows
    still come back in whatever order they end; the batch reports them in the files' order)."""
    sizes = [f.stat().st_size if f.exists() else 0 for f in files]
    return sorted(range(len(files)), key=lambda i: -sizes[i])


@dataclass
class _Worker:
    process: object
    conn: object
    task: tuple | None = None  # (index, tries)
    started: float = 0.0
    ready: bool = False


@dataclass
class _LocalRunner:
    """Worker processes fed one file at a time, each watched for its timeout and its death."""

    opts: BatchOptions
    n_files: int
    workers: list = field(default_factory=list)

    def __post_init__(self):
        self.n = max(1, min(self.opts.jobs or os.cpu_count() or 1, self.n_files))
        self.where = f"{self.n} process{'es' if self.n > 1 else ''}"
        memory = self.opts.memory * 2**20 if self.opts.memory else _total_memory() / self.n
        self.budget = int(memory) if memory else None

    def _start(self) -> _Worker:
        import multiprocessing

        ctx = multiprocessing.get_context("spawn")
        parent, child = ctx.Pipe()
        threads = {"OPENBLAS_NUM_THREADS": 1, "OMP_NUM_THREADS": 1, "MKL_NUM_THREADS": 1} if self.n > 1 else {}
        process = ctx.Process(target=_worker_main, args=(child, self.budget, self.n > 1), daemon=True)
        with _environment(**threads):
            process.start()
        child.close()
        worker = _Worker(process, parent)
        self.workers.append(worker)
        return worker

    def _stop(self, worker: _Worker) -> None:
        with contextlib.suppress(Exception):
            worker.process.kill()
        with contextlib.suppress(Exception):
            worker.process.join(5)
        with contextlib.suppress(Exception):
            worker.conn.close()
        if worker in self.workers:
            self.workers.remove(worker)

    def run(self, files, records, wanted, on_start):
        from multiprocessing.connection import wait

        pending = deque((i, 1) for i in _largest_first(files))
        for _ in range(self.n):
            self._start()
        while pending or any(w.task for w in self.workers):
            starting = [w for w in self.workers if not w.ready]
            for worker in [w for w in self.workers if w.ready and w.task is None]:
                if not pending:
                    break
                index, tries = pending.popleft()
                path = files[index]
                try:
                    data = path.read_bytes()
                except OSError as exc:
                    yield index, {"file": path.name, "status": "failed",
                                  "reason": f"cannot read the file ({exc.strerror})"}
                    continue
                if on_start is not None:
                    on_start(printable(path.name))
                worker.task, worker.started = (index, tries), time.monotonic()
                try:
                    worker.conn.send((path.name, data, records, wanted))
                except OSError:  # it died as the file was handed over: the answer's wait below sees it
                    pass
            busy = [w for w in self.workers if w.task is not None]
            if not busy and not starting:
                continue
            deadline = min((w.started for w in busy), default=time.monotonic()) + self.opts.timeout
            ready = wait([w.conn for w in busy + starting],
                         timeout=max(0.0, min(deadline - time.monotonic(), 1.0)))
            for worker in starting:
                if worker.conn in ready:
                    try:
                        said = worker.conn.recv()
                    except (EOFError, OSError):
                        said = ("cannot start", _death(worker.process.exitcode))
                    if said != "ready":
                        raise PatternsError(f"the worker processes cannot start ({said[1]}); with --memory, give "
                                            f"them more")
                    worker.ready = True
            for worker in busy:
                index, tries = worker.task
                if worker.conn in ready:
                    try:
                        row = worker.conn.recv()
                    except (EOFError, OSError):
                        row = None
                    if row is not None:
                        worker.task = None
                        yield index, row
                        continue
                    worker.process.join(5)
                    code = worker.process.exitcode
                    self._stop(worker)
                    self._start()
                    if code == _OUT_OF_MEMORY:  # no retry: the budget is the same on the next worker
                        yield index, {"file": files[index].name, "status": "failed",
                                      "reason": "out of memory (over the worker's memory budget)",
                                      "seconds": time.monotonic() - worker.started}
                    elif tries < 2:
                        pending.appendleft((index, tries + 1))  # its worker died: once more, on a new one
                    else:
                        yield index, {"file": files[index].name, "status": "lost",
                                      "reason": f"its worker died twice ({_death(code)})",
                                      "seconds": time.monotonic() - worker.started}
                elif time.monotonic() - worker.started > self.opts.timeout:
                    self._stop(worker)
                    self._start()
                    yield index, {"file": files[index].name, "status": "timeout",
                                  "reason": f"still running after {self.opts.timeout:g} s: stopped",
                                  "seconds": time.monotonic() - worker.started}

    def close(self) -> None:
        for worker in list(self.workers):
            self._stop(worker)


def _death(code) -> str:
    if code is None:
        return "it stopped answering"
    if code < 0:
        try:
            name = signal.Signals(-code).name
        except ValueError:
            name = f"signal {-code}"
        return f"{name}{': out of memory or killed' if -code == signal.SIGKILL else ''}"
    return f"exit code {code}"


def _total_memory() -> float | None:
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        return None


# --------------------------------------------------------------------------- #
# Dask: the same work, on a cluster
# --------------------------------------------------------------------------- #


class _DaskRunner:
    """The same tasks (bytes in, bytes out) on a Dask distributed cluster, checked before the first task.

    Before any work: the address parsed (``tcp://host:port``, or ``host:port``), the port reached
    (3 s; a port that answers HTTP is the dashboard's, and is named so), the client connected, at
    least one worker waited for, and ``patterns`` -- its version -- found on every worker and on the
    scheduler (workers without it, or with another version, are named).  Then every file goes as
    bytes (scattered when large), results come back as bytes and are released as they arrive.  A
    file still running after ``timeout`` is reported and its future cancelled (Dask cannot stop a
    task that runs: its worker goes on until it ends); one whose worker died is retried once by
    the client, then reported lost.
    """

    CONNECT = 3.0
    """Seconds to reach the scheduler's port, and to connect."""

    def __init__(self, opts: BatchOptions):
        self.opts = opts
        self.where = f"Dask scheduler {opts.scheduler}"
        self.client = None

    def connect(self) -> None:
        try:
            from distributed import Client
        except ImportError:
            raise InputError("--scheduler needs Dask: pip install 'patterns[dask]'") from None
        address = _scheduler_address(self.opts.scheduler, self.CONNECT)
        try:
            self.client = Client(address, timeout=f"{self.CONNECT}s")
        except (OSError, TimeoutError, ValueError) as exc:
            raise InputError(f"{self.opts.scheduler}: cannot reach the Dask scheduler ({exc})") from None
        try:
            self.client.wait_for_workers(1, timeout=self.opts.wait)
        except (TimeoutError, OSError):
            self.close()
            raise InputError(f"{self.opts.scheduler}: no Dask worker joined the scheduler within "
                             f"{self.opts.wait:g} s (start one: dask worker {address})") from None
        self._check_versions()
        # The heavy imports now, on every worker, not inside the first file's time (a builtin, as above).
        self.client.run(eval, "[__import__(m) for m in ('build123d', 'ezdxf', 'matplotlib.figure', 'trimesh', "
                              "'patterns.jobs')] and None", on_error="return")

    def _check_versions(self) -> None:
        # A builtin, so that it unpickles anywhere: the version of the patterns that imports there --
        # and here, the same probe (the package is loaded already).
        probe = (eval, "__import__('patterns').__version__")
        mine = probe[0](probe[1])
        found = self.client.run(*probe, on_error="return")
        lacking = sorted(w for w, v in found.items() if isinstance(v, ImportError))
        other = sorted(f"{w} ({v})" for w, v in found.items() if not isinstance(v, BaseException) and v != mine)
        broken = sorted(w for w, v in found.items() if isinstance(v, BaseException) and w not in lacking)
        try:  # the scheduler unpickles the tasks: it needs patterns too
            on_scheduler = self.client.run_on_scheduler(*probe)
        except ImportError:
            on_scheduler = None
        except Exception:  # noqa: BLE001 - a scheduler that refuses to run code: its workers decide
            on_scheduler = mine
        problems = []
        if lacking or broken:
            problems.append(f"workers without patterns: {', '.join(lacking + broken)} (pip install patterns there)")
        if other:
            problems.append(f"workers with another patterns than this machine's {mine}: {', '.join(other)}")
        if on_scheduler is None:
            problems.append("the scheduler has no patterns (pip install patterns there too)")
        elif on_scheduler != mine:
            problems.append(f"the scheduler has patterns {on_scheduler}, this machine {mine}")
        if problems:
            self.close()
            raise InputError(f"{self.opts.scheduler}: " + "; ".join(problems))

    def run(self, files, records, wanted, on_start):
        from distributed import wait

        pending = {}  # future -> (index, tries)
        seen_running = {}  # future key -> when first seen executing

        def submit(index, tries):
            path = files[index]
            data = path.read_bytes()
            payload = self.client.scatter(data, hash=False) if len(data) > 1 << 20 else data
            future = self.client.submit(process_part, path.name, payload, records, wanted, pure=False)
            pending[future] = (index, tries)
            if on_start is not None and tries == 1:
                on_start(printable(path.name))

        for index in _largest_first(files):  # Dask runs tasks in the order they were submitted
            submit(index, 1)
        while pending:
            with contextlib.suppress(Exception):  # none finished in that second, or one was lost: see below
                wait(list(pending), timeout=1.0, return_when="FIRST_COMPLETED")
            done = [f for f in pending if f.done()]
            for future in done:
                index, tries = pending.pop(future)
                try:
                    row = future.result()
                except Exception as exc:  # noqa: BLE001 - KilledWorker, a lost connection, ...
                    if tries < 2:
                        submit(index, tries + 1)  # its worker died: once more
                        future.release()
                        continue
                    row = {"file": files[index].name, "status": "lost",
                           "reason": f"its worker died twice ({type(exc).__name__}: killed -- out of memory, or a "
                                     f"crash)"}
                future.release()
                yield index, row
            # executing now -- not merely sent to a worker, where it may wait behind another task
            running = {key for keys in self._executing(pending).values() for key in keys}
            now = time.monotonic()
            for future in list(pending):
                if future.key in running:
                    started = seen_running.setdefault(future.key, now)
                    if now - started > self.opts.timeout:
                        index, _ = pending.pop(future)
                        future.cancel()
                        yield index, {"file": files[index].name, "status": "timeout",
                                      "reason": f"still running after {self.opts.timeout:g} s: given up (Dask "
                                                f"cannot stop a running task; its worker ends it)",
                                      "seconds": now - started}

    def _executing(self, pending) -> dict:
        if not pending:
            return {}
        with contextlib.suppress(Exception):  # a worker that left meanwhile: none seen this second
            return self.client.call_stack(keys=[f.key for f in pending])
        return {}

    def close(self) -> None:
        if self.client is not None:
            with contextlib.suppress(Exception):
                self.client.close()
            self.client = None


def _scheduler_address(text: str, timeout: float) -> str:
    """``tcp://host:port``, checked: parsed, the port reached, and not the dashboard's (InputError otherwise)."""
    import socket

    raw = text.strip()
    scheme, sep, rest = raw.partition("://")
    if not sep:
        scheme, rest = "tcp", raw
    if scheme in ("http", "https"):
        raise InputError(f"{text}: a web address: the Dask dashboard's? give the scheduler's, tcp://HOST:8786")
    if scheme != "tcp":
        raise InputError(f"{text}: the scheduler's address is tcp://HOST:PORT, not {scheme}://")
    host, sep, port = rest.rstrip("/").rpartition(":")
    if not sep or not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise InputError(f"{text}: expected tcp://HOST:PORT (the scheduler's port, usually 8786)")
    host = host.strip("[]")
    try:
        sock = socket.create_connection((host, int(port)), timeout=timeout)
    except socket.gaierror:
        raise InputError(f"{text}: unknown host {host!r}") from None
    except TimeoutError:
        raise InputError(f"{text}: cannot reach the Dask scheduler (no answer in {timeout:g} s)") from None
    except OSError as exc:
        raise InputError(f"{text}: cannot reach the Dask scheduler ({exc.strerror or exc})") from None
    try:  # a scheduler says nothing to this; a web server (the dashboard, on 8787) answers HTTP
        sock.settimeout(1.0)
        sock.sendall(b"GET / HTTP/1.0\r\n\r\n")
        answer = sock.recv(5)
    except OSError:
        answer = b""
    finally:
        sock.close()
    if answer.startswith(b"HTTP"):
        raise InputError(f"{text}: that port answers HTTP: it is the Dask dashboard, not the scheduler (give the "
                         f"scheduler's port, usually 8786)")
    return f"tcp://{host}:{port}" if ":" not in host else f"tcp://[{host}]:{port}"
