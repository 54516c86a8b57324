"""The engine, seen from the host: a worker process started once, kept warm, restarted if it dies.

Standard library only: nothing of the engine's environment (numpy 2, OCP, build123d, ``patterns``) is
ever imported into the host's process.  The worker is ``patterns serve``, in the environment the engine
was installed in, recorded by ``patterns freecad install`` in ``engine.json`` beside this package (or
given as a command line by ``PATTERNS_ENGINE``); requests and replies are JSON lines on its standard
input and output (docs/worker.md).  Its standard error goes to a log file, whose last lines an error
quotes.  It ends when the host exits (its input closes).
"""

import atexit
import hashlib
import json
import os
import shlex
import subprocess
import sys
import tempfile
import threading

PROTOCOL = 1
"""The protocol this host side speaks."""

HERE = os.path.dirname(os.path.abspath(__file__))
ICONS = os.path.join(HERE, "resources", "icons")
"""The workbench's icons."""
CONFIG = os.path.join(os.path.dirname(os.path.dirname(HERE)), "engine.json")
"""What ``patterns freecad install`` recorded: ``{"command": [...], "version": ..., "protocol": ...}``."""

INSTALL_HINT = ("install the engine in an environment of its own and put the workbench into FreeCAD from it; in a "
                "clone of patterns:\n"
                "    python3 -m venv .venv && .venv/bin/pip install .\n"
                "    .venv/bin/patterns freecad install\n"
                "(docs/freecad.md); FreeCAD need not be restarted")
"""The commands a user runs where the engine cannot be found or started."""


class EngineError(Exception):
    """The engine could not answer: missing, would not start, died twice, or another protocol."""


class Refused(EngineError):
    """The engine answered with an error: a bad option or shape (``kind``: the engine's exception class)."""

    def __init__(self, kind, message, details=""):
        super().__init__(message)
        self.kind, self.details = kind, details


def configured():
    """The worker's command line: ``$PATTERNS_ENGINE`` (split as a shell would), else ``engine.json``'s, else
    EngineError saying what to run."""
    text = os.environ.get("PATTERNS_ENGINE", "").strip()
    if text:
        return shlex.split(text, posix=os.name != "nt")  # on Windows C:\path\python.exe keeps its backslashes
    try:
        with open(CONFIG, encoding="utf-8") as f:
            command = json.load(f)["command"]
    except FileNotFoundError:
        raise EngineError(f"the patterns engine is not set up ({CONFIG} is missing): {INSTALL_HINT}") from None
    except (ValueError, KeyError, TypeError) as exc:
        raise EngineError(f"{CONFIG} is damaged ({exc}): {INSTALL_HINT}") from None
    if not command or not os.path.exists(command[0]):
        raise EngineError(f"the patterns engine recorded in {CONFIG} ({command[0] if command else 'nothing'}) is "
                          f"gone: {INSTALL_HINT}")
    return [str(c) for c in command]


def _installed_version():
    """The engine's version when the workbench was installed (``engine.json``), or None."""
    try:
        with open(CONFIG, encoding="utf-8") as f:
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


def key_of(kind, shape, options):
    """The key of a request's result (the engine's ``patterns.service.work.key_of``): unchanged key, unchanged
    pieces."""
    text = json.dumps([kind, options], sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode() + b"\0" + shape.encode()).hexdigest()


class Engine:
    """One worker process and its pipes; :meth:`request` starts it the first time and again if it died."""

    def __init__(self, command=None):
        self.command = command
        self.process = None
        self.hello = None
        self.starts = 0
        self.log = None
        self._next = 0
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
        command = (self.command or configured()) + ["serve"]
        self._forget_log()
        fd, self.log = tempfile.mkstemp(prefix="patterns-engine-", suffix=".log")
        try:
            self.process = subprocess.Popen(command, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=fd,
                                            env=_environment(), close_fds=True)
        except OSError as exc:
            raise EngineError(f"the patterns engine could not be started ({shlex.join(command)}: {exc}): "
                              f"{INSTALL_HINT}") from None
        finally:
            os.close(fd)
        self.starts += 1
        try:
            self.hello = self._exchange({"op": "hello", "protocol": PROTOCOL, "host": "freecad"})
        except Refused as exc:  # another protocol: said in one line
            self.stop()
            raise EngineError(str(exc)) from None
        except _Died as exc:
            self.process = None
            raise EngineError(f"the patterns engine ({shlex.join(command)}) did not start"
                              + (f" ({str(exc).splitlines()[-1]})" if str(exc) else "") + f": {INSTALL_HINT}") from None
        installed = _installed_version()
        if installed and installed != self.hello["version"]:
            sys.stderr.write(f"patterns: the workbench came with engine {installed}, the engine is "
                             f"{self.hello['version']}: run `patterns freecad install` again from the engine's "
                             f"environment\n")

    def _exchange(self, message):
        self._next += 1
        message = dict(message, id=self._next)
        try:
            self.process.stdin.write(json.dumps(message, separators=(",", ":")).encode() + b"\n")
            self.process.stdin.flush()
            line = self.process.stdout.readline()
        except (BrokenPipeError, OSError):
            line = b""
        if not line:
            raise _Died(self._tail())
        reply = json.loads(line)
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


class _Died(Exception):
    """The worker's pipe closed: it died (the message: the last lines of its log)."""


_ENGINE = None


def engine():
    """The host's one engine."""
    global _ENGINE
    if _ENGINE is None:
        _ENGINE = Engine()
        atexit.register(_ENGINE.stop)
    return _ENGINE
