"""A batch on this machine: worker processes of our own, so that one can be stopped or lost alone.

Each worker is a spawned process (a user's script is never re-run in it) fed
one file at a time through a pipe, watched for its timeout and its death; a
worker that dies is replaced and its file tried once more, then reported
lost; one over its memory budget fails alone.
"""

from __future__ import annotations

import contextlib
import multiprocessing.connection
import multiprocessing.process
import os
import signal
import time
from collections import deque
from dataclasses import dataclass, field

from ..errors import PatternsError
from ..text import printable
from .plan import BatchOptions, largest_first
from .worker import OUT_OF_MEMORY, worker_main

__all__ = ["LocalRunner"]


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


@dataclass
class _Worker:
    process: multiprocessing.process.BaseProcess
    conn: multiprocessing.connection.Connection
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

    def _start(self) -> _Worker:
        import multiprocessing

        ctx = multiprocessing.get_context("spawn")
        parent, child = ctx.Pipe()
        threads = {"OPENBLAS_NUM_THREADS": 1, "OMP_NUM_THREADS": 1, "MKL_NUM_THREADS": 1} if self.n > 1 else {}
        process = ctx.Process(target=worker_main, args=(child, self.budget, self.n > 1), daemon=True)
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
