"""The engine, seen from a host (FreeCAD, Blender): a worker process started once, kept warm, restarted if it dies.

Standard library only: nothing of the engine's environment (numpy 2, OCP, build123d, ``patterns``) is
ever imported into the host's process.  The worker is ``patterns serve``, in the environment the engine
was installed in, recorded by ``patterns freecad install`` (or ``patterns blender install``) in an
``engine.json`` beside the host's package (or given as a command line by ``PATTERNS_ENGINE``); requests
and replies are JSON lines on its standard input and output (docs/worker.md).  Its standard error goes
to a log file, whose last lines an error quotes.  It ends when the host exits (its input closes).

This file is copied into each host's package when it is installed (``client.py``); each host's
``engine.py`` says where its ``engine.json`` is and what to run when the engine is missing.
"""

import hashlib
import json
import os
import queue
import re
import shlex
import subprocess
import sys
import tempfile
import threading

PROTOCOL = 1
"""The protocol this host side speaks."""
HELLO = 120.0
"""Seconds a starting worker has to answer ``hello`` (its imports take about 3 s); a request has no limit:
a flattening takes what it takes."""

class EngineError(Exception):
    """The engine could not answer: missing, would not start, died twice, or another protocol."""


class Refused(EngineError):
    """The engine answered with an error: a bad option or shape (``kind``: the engine's exception class)."""

    def __init__(self, kind, message, details=""):
        super().__init__(message)
        self.kind, self.details = kind, details


def configured(config, hint):
    """The worker's command line: ``$PATTERNS_ENGINE`` (split as a shell would), else the one the host's
    ``engine.json`` (``config``) records, else EngineError saying what to run (``hint``)."""
    text = os.environ.get("PATTERNS_ENGINE", "").strip()
    if text:
        if os.name != "nt":
            return shlex.split(text)
        return [t[1:-1] if len(t) > 1 and t[0] == t[-1] == '"' else t for t in shlex.split(text, posix=False)]
    try:
        with open(config, encoding="utf-8") as f:
            command = json.load(f)["command"]
    except FileNotFoundError:
        raise EngineError(f"the patterns engine is not set up ({config} is missing): {hint}") from None
    except (ValueError, KeyError, TypeError) as exc:
        raise EngineError(f"{config} is damaged ({exc}): {hint}") from None
    if not command or not os.path.exists(command[0]):
        raise EngineError(f"the patterns engine recorded in {config} ({command[0] if command else 'nothing'}) is "
                          f"gone: {hint}")
    return [str(c) for c in command]


def _installed_version(config):
    """The engine's version when the host's side was installed (``engine.json``), or None."""
    try:
        with open(config, encoding="utf-8") as f:
            return json.load(f).get("version")
    except (OSError, ValueError, AttributeError):
        return None


def _environment():
    """The host's environment less what points a Python at the host's own packages."""
    env = dict(os.environ)
    for name in ("PYTHONPATH", "PYTHONHOME", "PYTHONSTARTUP", "PYTHONEXECUTABLE", "PYTHONUSERBASE",
                 "PYTHONNOUSERSITE", "PYTHONSAFEPATH"):
        env.pop(name, None)
    if "APPIMAGE" in env or "APPDIR" in env:  # an AppImage's libraries are FreeCAD's, not the engine's
        env.pop("LD_LIBRARY_PATH", None)
    env.setdefault("PYTHONIOENCODING", "utf-8")
    return env


_FLAGS = re.compile(r"(?m)^[01]{7}$")
"""A BREP shape's flags line (free, modified, checked, orientable, closed, infinite, convex): left out of keys."""


def _stamp(path):
    """A file's size and modification time: an edited table file is a new request."""
    status = os.stat(path)
    return [status.st_size, status.st_mtime_ns]


def key_of(kind, shape, options, name):
    """The key of a request's result (the engine's ``patterns.service.work.key_of``): unchanged key, unchanged
    pieces."""
    files = {v: _stamp(v) for v in options.values() if isinstance(v, str) and os.path.isfile(v)}  # a bend table
    text = json.dumps([kind, name, options, files], sort_keys=True, separators=(",", ":"))
    geometry = _FLAGS.sub("", shape)  # a shape's state flags change when it is only displayed (tessellated)
    return hashlib.sha256(text.encode() + b"\0" + geometry.encode()).hexdigest()


class Engine:
    """One worker process and its pipes; :meth:`request` starts it the first time and again if it died.

    ``config``: the host's ``engine.json``; ``host``: its name (``hello`` says it); ``hint``: what to run where
    the engine cannot be found or started; ``install``: the command that installs the host's side."""

    def __init__(self, command=None, *, config, host, hint, install):
        self.command = command
        self.config, self.host, self.hint, self.install = config, host, hint, install
        self.process = None
        self.hello = None
        self.starts = 0
        self.log = None
        self._next = 0
        self._lines = None
        self._lock = threading.Lock()

    @property
    def options(self):
        """``{kind: [property, ...]}``: the option schema the engine sent (starting it if needed)."""
        self.start()
        return self.hello["options"]

    def alive(self):
        return self.process is not None and self.process.poll() is None

    def start(self):
        """Start the worker unless it runs; check it speaks this protocol.  EngineError if it cannot."""
        if self.alive():
            return
        command = (self.command or configured(self.config, self.hint)) + ["serve"]
        self._forget_log()
        fd, self.log = tempfile.mkstemp(prefix="patterns-engine-", suffix=".log")
        try:
            self.process = subprocess.Popen(command, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=fd,
                                            env=_environment(), close_fds=True,
                                            creationflags=getattr(subprocess, "CREATE_NO_WINDOW", 0))
        except OSError as exc:
            raise EngineError(f"the patterns engine could not be started ({shlex.join(command)}: {exc}): "
                              f"{self.hint}") from None
        finally:
            os.close(fd)
        self.starts += 1
        self._lines = queue.Queue()
        threading.Thread(target=_read_lines, args=(self.process.stdout, self._lines), daemon=True).start()
        try:
            self.hello = self._exchange({"op": "hello", "protocol": PROTOCOL, "host": self.host}, timeout=HELLO)
        except Refused as exc:  # another protocol: said in one line
            self.stop()
            raise EngineError(str(exc)) from None
        except _Died as exc:
            self.process = None
            raise EngineError(f"the patterns engine ({shlex.join(command)}) did not start"
                              + (f" ({str(exc).splitlines()[-1]})" if str(exc) else "") + f": {self.hint}") from None
        installed = _installed_version(self.config)
        if installed and installed != self.hello["version"]:
            sys.stderr.write(f"patterns: the {self.host} side came with engine {installed}, the engine is "
                             f"{self.hello['version']}: run `{self.install}` again from the engine's environment\n")

    def _exchange(self, message, timeout=None):
        """Send one request, wait for its reply (``timeout`` s at most, else the worker is ended); a reply that
        is not JSON or not this request's ends the worker too (:class:`_Died`: it is started again)."""
        self._next += 1
        message = dict(message, id=self._next)
        try:
            self.process.stdin.write(json.dumps(message, separators=(",", ":")).encode() + b"\n")
            self.process.stdin.flush()
            line = self._lines.get(timeout=timeout)
        except (BrokenPipeError, OSError):
            line = b""
        except queue.Empty:
            self.process.kill()
            raise _Died(f"no answer in {timeout:.0f} s\n{self._tail()}") from None
        try:
            reply = json.loads(line) if line else None
        except ValueError:
            reply = None
        if not isinstance(reply, dict) or reply.get("id") != message["id"]:
            if self.process.poll() is None:
                self.process.kill()
            raise _Died(self._tail() if not line else f"a reply that is not the answer: {line[:200]!r}\n{self._tail()}")
        if not reply.get("ok"):
            error = reply.get("error") or {}
            raise Refused(error.get("type", "Error"), error.get("message", "the engine failed"),
                          error.get("traceback", ""))
        return reply["result"]

    def _tail(self, lines=8):
        try:
            with open(self.log, encoding="utf-8", errors="replace") as f:
                return "".join(f.readlines()[-lines:]).strip()
        except OSError:
            return ""

    def request(self, op, **fields):
        """The result of one request; a worker that died is started again and asked once more."""
        with self._lock:
            for attempt in (0, 1):
                self.start()
                try:
                    return self._exchange(dict(fields, op=op))
                except _Died as exc:
                    self.process = None
                    if attempt:
                        raise EngineError(f"the patterns engine stopped twice while answering {op!r}"
                                          + (f"; its last words:\n{exc}" if str(exc) else "")) from None

    def stop(self):
        """End the worker (it also ends by itself when the host's end of its input closes) and remove its log."""
        process, self.process = self.process, None
        if process is not None and process.poll() is None:
            try:
                process.stdin.write(b'{"op":"shutdown","id":0}\n')
                process.stdin.close()
                process.wait(timeout=5)
            except (OSError, subprocess.TimeoutExpired):
                process.kill()
        self._forget_log()

    def _forget_log(self):
        if self.log:
            try:
                os.unlink(self.log)
            except OSError:
                pass
            self.log = None


def _read_lines(stream, lines):
    """The worker's replies, a line each, into ``lines`` (``b""`` at the end)."""
    for line in iter(stream.readline, b""):
        lines.put(line)
    lines.put(b"")


class _Died(Exception):
    """The worker's pipe closed: it died (the message: the last lines of its log)."""
