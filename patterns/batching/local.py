"""A batch on this machine: worker processes of our own, so that one can be stopped or lost alone.

Each worker is a fresh interpreter started with its own entry point
(:func:`~patterns.batching.worker.spawn_main`), fed one file at a time over a
socket, watched for its timeout and its death; a worker that dies is replaced
and its file tried once more, then reported lost; one over its memory budget
fails alone.

Not :mod:`multiprocessing`'s "spawn": its child imports the parent's
``__main__`` (``__mp_main__``) before it runs anything, so that a script calling
:func:`patterns.batch` at its top level, with no ``if __name__ == "__main__":``
guard, would run again in every worker.  A worker here runs only functions of
this package: it gets the parent's ``sys.path`` and nothing of its ``__main__``.
Its interpreter is this one, or inside FreeCAD (whose ``sys.executable`` is
FreeCAD) a Python of the same version on PATH.  Starting one changes nothing in
this process (no ``os.environ``, no module state), so batches may run in threads.
"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import socket
import subprocess
import sys
import tempfile
import time
from collections import deque
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO

from ..errors import PatternsError
from ..files import child_python
from ..text import printable
from .plan import BatchOptions, largest_first
from .worker import OUT_OF_MEMORY, Channel, out_of_memory

__all__ = ["START_TIMEOUT", "LocalRunner"]

START_TIMEOUT = 300.0
"""Seconds a worker may take to start (its interpreter and the heavy imports; a few on an idle machine) before
the batch gives up on it.  Not ``timeout``: a file's time starts when it is handed over."""

_ENTRY = "from patterns.batching.worker import spawn_main; spawn_main()"
"""What a worker runs (``python -P -c``), once the bootstrap below has put the parent's ``sys.path`` in place
(``-P``: no folder of the user's before it, not even to import ``json``)."""

_BOOTSTRAP = ("import json, sys; p = json.loads(sys.argv[1])['path']; sys.path[:] = p + [e for e in sys.path "
              f"if e not in p]; {_ENTRY}")
"""The parent's path first (the same packages), then the worker's own entries that it lacks."""


@dataclass
class _Worker:
    process: subprocess.Popen
    conn: Channel
    stderr: IO[bytes]  # a temporary file: what the worker said on stderr, read when it cannot start
    task: tuple | None = None  # (index, tries)
    started: float = 0.0
    ready: bool = False


@dataclass
class LocalRunner:
    """Worker processes fed one file at a time, each watched for its timeout and its death."""

    opts: BatchOptions
    n_files: int
    workers: list = field(default_factory=list)

    def __post_init__(self):
        self.n = max(1, min(self.opts.jobs or os.cpu_count() or 1, self.n_files))
        self.where = f"{self.n} process{'es' if self.n > 1 else ''}"
        memory = self.opts.memory * 2**20 if self.opts.memory else _total_memory() / self.n
        self.budget = int(memory) if memory else None
        self.python = _python()

    def _start(self) -> _Worker:
        """A new worker: this process's ``sys.path``, its end of a socket pair (an inherited descriptor; on
        Windows, which inherits none, the socket shared with its process id over its stdin), its stderr kept
        in a temporary file, its BLAS on one thread when there are several workers -- in its environment,
        not in ``os.environ``."""
        posix = os.name == "posix"
        parent, child = socket.socketpair()
        settings = {"path": _worker_path(), "fd": child.fileno() if posix else None, "budget": self.budget,
                    "one_thread": self.n > 1, "parent": os.getpid()}
        threads = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"} if self.n > 1 else {}
        stderr = tempfile.TemporaryFile(prefix="patterns-worker-")  # noqa: SIM115 - open for the worker's life
        try:
            process = subprocess.Popen([self.python, "-P", "-c", _BOOTSTRAP, json.dumps(settings)],
                                       stdin=subprocess.DEVNULL if posix else subprocess.PIPE,
                                       stdout=subprocess.DEVNULL, stderr=stderr,
                                       pass_fds=(child.fileno(),) if posix else (), env={**os.environ, **threads})
            if not posix:
                with process.stdin:
                    process.stdin.write(child.share(process.pid))
        except OSError as exc:
            parent.close()
            stderr.close()
            raise PatternsError(f"the worker processes cannot start ({self.python}: {exc.strerror or exc})") \
                from None
        finally:
            child.close()
        worker = _Worker(process, Channel(parent), stderr, started=time.monotonic())
        self.workers.append(worker)
        return worker

    def _stop(self, worker: _Worker) -> None:
        with contextlib.suppress(Exception):
            worker.process.kill()
        with contextlib.suppress(Exception):
            worker.process.wait(5)
        with contextlib.suppress(Exception):
            worker.conn.close()
        with contextlib.suppress(Exception):
            worker.stderr.close()
        if worker in self.workers:
            self.workers.remove(worker)

    def _exit_code(self, worker: _Worker) -> int | None:
        """The worker's exit code once its line is closed (waited for a little: None if it still runs)."""
        with contextlib.suppress(subprocess.TimeoutExpired):
            worker.process.wait(5)
        return worker.process.returncode

    def _started(self, worker: _Worker, ready: list) -> None:
        """Mark a starting worker ready when it says so; PatternsError with the reason when it cannot start
        (its words, or its death and its last line on stderr), advising more memory only when memory was it."""
        if worker.conn in ready:
            try:
                said = worker.conn.recv()
            except (EOFError, OSError):
                code = self._exit_code(worker)
                last = _last_line(worker.stderr)
                memory = bool(self.budget) and (code == OUT_OF_MEMORY or out_of_memory(last))
                said = ("cannot start", _death(code) + (f": {last}" if last else ""), memory)
            if said == "ready":
                worker.ready = True
                return
        elif time.monotonic() - worker.started > START_TIMEOUT:
            said = ("cannot start", f"not ready after {START_TIMEOUT:g} s", False)
        else:
            return
        advice = "; with --memory, give them more" if said[2] else ""
        raise PatternsError(f"the worker processes cannot start ({printable(said[1])}){advice}")

    def run(self, files, bundle, wanted, on_start):
        from multiprocessing.connection import wait

        pending = deque((i, 1) for i in largest_first(files))
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
                    worker.conn.send((path.name, data, bundle, wanted))
                except OSError:  # it died as the file was handed over: the answer's wait below sees it
                    pass
            busy = [w for w in self.workers if w.task is not None]
            if not busy and not starting:
                continue
            deadline = min((w.started for w in busy), default=time.monotonic()) + self.opts.timeout
            ready = wait([w.conn for w in busy + starting],
                         timeout=max(0.0, min(deadline - time.monotonic(), 1.0)))
            for worker in starting:
                self._started(worker, ready)
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
                    code = self._exit_code(worker)
                    self._stop(worker)
                    self._start()
                    if code == OUT_OF_MEMORY:  # no retry: the budget is the same on the next worker
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


def _python() -> str:
    """The Python to run a worker with (:func:`patterns.files.child_python`)."""
    found = child_python()
    if found is None:
        version = f"python{sys.version_info.major}.{sys.version_info.minor}"
        raise PatternsError(f"the worker processes cannot start (no {version} on PATH to run them; "
                            f"this process runs in {sys.executable})")
    return found


def _worker_path() -> list:
    """The ``sys.path`` a worker gets: this process's, with the folder this ``patterns`` was imported from first
    when the path does not hold it (so that the worker runs the same package)."""
    path = list(sys.path)
    root = str(Path(__file__).resolve().parents[2])
    if not any(os.path.realpath(p or ".") == root for p in path):
        path.insert(0, root)
    return path


def _last_line(stream) -> str:
    """The last non-empty line a worker wrote to its stderr file ("" if none)."""
    try:
        stream.seek(max(0, stream.seek(0, os.SEEK_END) - 4096))
        lines = [ln.strip() for ln in stream.read().decode(errors="replace").splitlines()]
    except (OSError, ValueError):
        return ""
    return next((ln for ln in reversed(lines) if ln), "")[:300]


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
