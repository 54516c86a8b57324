"""The worker: the engine in its own process, answering a host's requests as JSON lines (``patterns serve``).

One request a line on standard input, one reply a line on standard output, in order; see docs/worker.md
for the messages.  Standard output carries nothing else: whatever the libraries print goes to standard
error, which the host keeps as the worker's log.  The worker ends at ``shutdown`` or when its input closes
(the host exited or died), so it never outlives its host.
"""

from __future__ import annotations

import json
import os
import sys
import traceback
from typing import BinaryIO

from ..errors import InputError, PatternsError
from .work import Results, export, make, validate

__all__ = ["PROTOCOL", "Server", "protocol_output", "serve"]

PROTOCOL = 1
"""The protocol's version: a host and a worker of different protocols refuse each other, saying so."""

MAX_LINE = 1 << 30
"""The longest request line read, bytes (a shape's BREP text of 1 GB)."""


def _hello(request: dict) -> dict:
    from .. import __version__
    from .schema import schema

    protocol = request.get("protocol")
    if protocol != PROTOCOL:
        raise InputError(f"this patterns engine {__version__} speaks protocol {PROTOCOL}, the host {protocol!r}: "
                       f"install the same version on both sides (patterns freecad install)")
    return {"engine": "patterns", "version": __version__, "protocol": PROTOCOL, "pid": os.getpid(),
            "python": sys.executable, "options": schema()}


class Server:
    """Answers requests (:meth:`answer`); :func:`serve` runs it on a pair of streams."""

    def __init__(self):
        self.results = Results()
        self.requests = 0

    def answer(self, request: dict) -> dict:
        """The reply to one request: ``{"id", "ok": True, "result"}`` or ``{"id", "ok": False, "error"}``."""
        self.requests += 1
        ident = request.get("id")
        op = request.get("op")
        try:
            if op == "hello":
                result = _hello(request)
            elif op == "make":
                result = make(self.results, request)
            elif op == "validate":
                result = validate(request)
            elif op == "export":
                result = export(self.results, request)
            elif op == "stats":
                result = {"computed": self.results.computed, "requests": self.requests, "pid": os.getpid()}
            elif op == "shutdown":
                result = {}
            else:
                raise InputError(f"unknown operation {op!r}; the operations are hello, validate, make, export, stats, shutdown")
        except PatternsError as exc:
            return {"id": ident, "ok": False, "error": {"type": type(exc).__name__, "message": str(exc)}}
        except Exception as exc:  # noqa: BLE001 - a bug of the engine: said to the host, the worker lives on
            return {"id": ident, "ok": False, "error": {"type": "InternalError", "message": f"{type(exc).__name__}: "
                                                        f"{exc}", "traceback": traceback.format_exc()}}
        return {"id": ident, "ok": True, "result": result}


def _decode(line: bytes) -> dict:
    try:
        request = json.loads(line)
    except (ValueError, UnicodeDecodeError) as exc:
        return {"op": None, "bad": f"not a JSON line: {exc}"}
    return request if isinstance(request, dict) else {"op": None, "bad": "a request must be a JSON object"}


def protocol_output() -> BinaryIO:
    """The process's standard output, kept for the protocol; file descriptor 1 and ``sys.stdout`` then go to
    standard error, so that nothing a library prints can come between two replies.  Called first thing."""
    out = os.fdopen(os.dup(1), "wb")
    os.dup2(2, 1)
    sys.stdout = sys.stderr
    return out


def _too_long(stdin: BinaryIO) -> dict:
    """Skip the rest of a line longer than :data:`MAX_LINE`: one request, one reply."""
    while True:
        rest = stdin.readline(MAX_LINE)
        if not rest or rest.endswith(b"\n"):
            return {"op": None, "bad": f"a request longer than {MAX_LINE} bytes"}


def serve(stdin: BinaryIO | None = None, stdout: BinaryIO | None = None) -> int:
    """Answer requests from ``stdin`` on ``stdout`` (default the process's own, :func:`protocol_output`) until
    ``shutdown`` or the end of the input; returns the exit code (0)."""
    stdout = stdout or protocol_output()
    stdin = stdin or sys.stdin.buffer
    server = Server()
    while True:
        line = stdin.readline(MAX_LINE)
        if not line:
            return 0
        if not line.strip():
            continue
        request = _too_long(stdin) if len(line) == MAX_LINE and not line.endswith(b"\n") else _decode(line)
        if "bad" in request:
            reply = {"id": None, "ok": False, "error": {"type": "InputError", "message": request["bad"]}}
        else:
            reply = server.answer(request)
        stdout.write(json.dumps(reply, separators=(",", ":")).encode() + b"\n")
        stdout.flush()
        if request.get("op") == "shutdown":
            return 0
