"""A batch's worker side: one part's bytes in, its row and its outputs' bytes out.

:func:`process_part` runs the whole pipeline (:func:`patterns.jobs.flatten_part`,
or :func:`patterns.jobs.unfold_part` for a bent sheet-metal part) on a part
given as bytes, in a private temporary folder, and never raises for the
part's fault.  :func:`worker_main` is a local worker process's loop, and
:func:`spawn_main` its entry point: a worker is a fresh interpreter that runs
only this module (never the user's ``__main__``), talking to its parent over a
:class:`Channel`.
"""

from __future__ import annotations

import contextlib
import json
import os
import pickle
import signal
import socket
import struct
import sys
import tempfile
import time
from pathlib import Path

from ..bundle import Bundle
from ..errors import PatternsError
from ..findings import Code
from ..jobs import PartResult, flatten_part, unfold_part
from .plan import _SUFFIXES

__all__ = ["OUT_OF_MEMORY", "Channel", "process_part", "spawn_main", "worker_main"]


def process_part(name: str, data: bytes, bundle: Bundle, wanted: tuple) -> dict:
    """Run the pipeline on one part given as bytes; return its row and outputs as bytes.  Never raises
    for the part's fault (a bad file, a limit, memory): that becomes the row's reason.

    Parameters
    ----------
    name : str
        The input's file name (its suffix says its type).
    data : bytes
        The file's content.
    bundle : patterns.bundle.Bundle
        The part's options: a ``flatten`` bundle, or an ``unfold`` one to unfold a bent sheet-metal part.
    wanted : tuple of str
        Output kinds: ``"pattern"`` (DXF), ``"report"``, ``"heat_map"``, ``"preview"``.

    Returns
    -------
    dict
        The :class:`Row` fields (``file``, ``status``, ...) and ``files``:
        ``{kind: bytes}`` of every output.
    """
    start = time.perf_counter()
    row = {"file": name, "status": "failed", "reason": "", "files": {}}
    try:
        with tempfile.TemporaryDirectory(prefix="patterns-part-") as tmp:
            source = Path(tmp) / name
            source.write_bytes(data)
            outputs = {kind: Path(tmp) / _SUFFIXES[kind].format("out") for kind in wanted}
            run = unfold_part if bundle.kind == "unfold" else flatten_part
            try:
                part = run(source, bundle, outputs=outputs, stage=lambda path, what: path)
            except PatternsError as exc:
                row["reason"] = str(exc).replace(tmp + os.sep, "")
                return row
            report = part.report
            row["files"] = {kind: path.read_bytes() for kind, path in part.written.items()}
            row.update(status="ok" if report.ok else "check failed",
                       reason="" if report.ok else report.findings[0].message, **_numbers(part))
    except MemoryError:
        row.update(status="failed", reason="out of memory (over the worker's memory budget)", files={})
    except Exception as exc:  # noqa: BLE001 - a defect of ours must not sink the batch: the row says what
        row.update(status="failed", reason=f"internal error: {type(exc).__name__}: {exc}", files={})
    finally:
        row["seconds"] = time.perf_counter() - start
    return row


def _numbers(part: PartResult) -> dict:
    """The row's panels, seams and strains: a pattern's, or a blank's (one piece, no seam, exact unless a face
    had to be meshed)."""
    report = part.report
    if part.model is None:
        meshed = any(f.code is Code.MESHED_FACE for f in report.findings)
        blank = report.blanks[0] if report.blanks else None
        return {"panels": 1, "seams": 0, "strain_rms": None if meshed else 0.0,
                "strain_max": None if meshed else 0.0,
                "thickness": None if blank is None else float(blank.thickness),
                "size": None if blank is None else tuple(round(float(x), 3) for x in blank.size),
                "bends": None if blank is None else len(blank.bends)}
    return {"panels": len(part.model.panels), "seams": len(part.model.seams),
            "strain_rms": max(p.strain_rms for p in report.panels), "strain_max": max(p.strain_max for p in report.panels)}


class Channel:
    """One end of a local worker's line to its parent: whole pickled messages over a stream socket (a length,
    then the pickle).  ``recv`` raises EOFError once the other end is gone; ``fileno`` lets
    :func:`multiprocessing.connection.wait` watch it."""

    _HEAD = struct.Struct("!Q")

    def __init__(self, sock: socket.socket):
        self.sock = sock

    def fileno(self) -> int:
        return self.sock.fileno()

    def send(self, message) -> None:
        data = pickle.dumps(message, protocol=pickle.HIGHEST_PROTOCOL)
        self.sock.sendall(self._HEAD.pack(len(data)))
        self.sock.sendall(data)

    def recv(self):
        (size,) = self._HEAD.unpack(self._read(self._HEAD.size))
        return pickle.loads(self._read(size))

    def _read(self, size: int) -> bytearray:
        data = bytearray(size)
        view, got = memoryview(data), 0
        while got < size:
            n = self.sock.recv_into(view[got:])
            if not n:
                raise EOFError("the other end of the channel is closed")
            got += n
        return data

    def close(self) -> None:
        self.sock.close()


def spawn_main() -> None:  # pragma: no cover - in a child process
    """A local worker process's entry point (``python -c``, see :mod:`patterns.batching.local`): its settings in
    ``sys.argv[1]`` as JSON -- the parent's ``sys.path`` (already in place when this module is imported), the
    channel's file descriptor (None on Windows: the shared socket on stdin), the memory budget, one BLAS thread
    or not, the parent's process id."""
    settings = json.loads(sys.argv[1])
    if settings["fd"] is None:  # Windows: the socket, shared with this process, comes on stdin
        channel = Channel(socket.fromshare(sys.stdin.buffer.read()))
    else:
        channel = Channel(socket.socket(fileno=settings["fd"]))
    worker_main(channel, settings["budget"], settings["one_thread"], parent=settings["parent"])


def worker_main(conn, budget: int | None, one_thread: bool, *, parent: int | None = None) -> None:  # pragma: no cover
    """A local worker: dies with its parent, ignores Ctrl-C (the parent stops it), stays in its memory budget,
    and never prints: what goes wrong goes back to the parent, or the worker just ends.  A worker that cannot
    start says why, and whether memory (its budget) was the cause."""
    try:
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        _die_with_parent()
        if parent is not None and os.getppid() != parent:  # the parent died before the line above
            os._exit(1)
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

            from .. import jobs  # noqa: F401
        except BaseException as exc:  # noqa: BLE001 - said to the parent, which stops the batch
            said = f"{type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''}"
            conn.send(("cannot start", said, bool(budget) and out_of_memory(said)))
            return
        conn.send("ready")  # a file's time starts when it is handed over, not while the worker starts
        while True:
            task = conn.recv()
            if task is None:
                return
            conn.send(process_part(*task))
    except MemoryError:  # even the file's bytes do not fit the budget: the parent says so
        os._exit(OUT_OF_MEMORY)
    except BaseException:  # noqa: BLE001 - the parent sees the pipe close: the file is retried or lost
        os._exit(1)


OUT_OF_MEMORY = 3
"""A local worker's exit code when a file's bytes alone exceed its memory budget."""

_MEMORY_WORDS = ("memoryerror", "cannot allocate memory", "out of memory", "failed to map segment", "bad_alloc",
                 "memory regions")


def out_of_memory(said: str) -> bool:
    """Whether what a failing worker said (an exception, its last words on stderr) names memory as the cause:
    Python's MemoryError, ENOMEM, a shared library that cannot be mapped, C++'s bad_alloc, OpenBLAS's buffers."""
    said = said.casefold()
    return any(word in said for word in _MEMORY_WORDS)


def _die_with_parent() -> None:
    """Linux: SIGKILL this process when its parent dies (a killed batch leaves no worker behind)."""
    if sys.platform.startswith("linux"):
        import ctypes

        with contextlib.suppress(OSError, AttributeError):
            ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
