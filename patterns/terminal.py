"""What the command line shows on the terminal: progress, names as data, a closed pipe, a HOME it cannot read.

* :class:`Progress` and :class:`BatchProgress`: a bar on a terminal, a line per file in a log, nothing
  with ``--quiet``.
* :class:`Terminal`: standard output or error with control characters and undecodable bytes of file names
  shown as escapes, and a closed pipe (``| head -1``) dropped instead of a traceback.
* :func:`foreign_home`: settings and caches kept out of a HOME this user cannot read (``sudo -u``).
"""

from __future__ import annotations

import os
import re
import sys
import time

from .text import escape

__all__ = ["BatchProgress", "Progress", "Terminal", "foreign_home", "isatty"]


LOG_EVERY = 10.0
"""Seconds between two progress lines in a log (stderr not a terminal): long work says it is moving."""


class Progress:
    """A one-line progress bar on stderr when it is a terminal; in a log (CI, nohup, a pipe), a line every
    :data:`LOG_EVERY` seconds of long work (none for work shorter than that)."""

    def __init__(self, label: str, *, stream=None, enabled: bool | None = None):
        self.stream = stream or sys.stderr
        self.enabled = isatty(self.stream) if enabled is None else enabled
        self.label = label
        self._last = -1.0
        self._start = self._logged = time.monotonic()

    def __call__(self, done: int, total: int) -> None:
        if total <= 0:
            return
        if not self.enabled:
            now = time.monotonic()
            if now - self._logged >= LOG_EVERY and done < total:
                self._logged = now
                self.stream.write(f"{self.label}: {100 * min(max(done / total, 0.0), 1.0):.0f}% "
                                  f"({now - self._start:.0f} s)\n")
                self.stream.flush()
            return
        frac = min(max(done / total, 0.0), 1.0)
        if frac - self._last < 0.01 and frac < 1.0:
            return
        self._last = frac
        width = 30
        bar = "#" * int(frac * width) + "-" * (width - int(frac * width))
        self.stream.write(f"\r{self.label} [{bar}] {100 * frac:3.0f}%")
        if frac >= 1.0:
            self.stream.write("\n")
        self.stream.flush()

    def close(self) -> None:
        if self.enabled and 0 <= self._last < 1.0:
            self.stream.write("\n")
            self.stream.flush()


def isatty(stream) -> bool:
    try:
        return stream.isatty()
    except (AttributeError, ValueError, OSError):
        return False


class BatchProgress:
    """A batch's progress: a bar with the file names, failures and time left on a terminal; else a line
    per finished file (for logs, CI, nohup); nothing with --quiet."""

    def __init__(self, total: int, *, quiet: bool = False, stream=None):
        self.total, self.quiet = total, quiet
        self.stream = stream or sys.stderr
        self.bar = isatty(self.stream) and not quiet
        self.start_time, self.done, self.bad, self.running = time.monotonic(), 0, 0, []

    def start(self, name: str) -> None:
        self.running.append(name)
        self._draw()

    def row(self, row, done: int, total: int) -> None:
        self.done = done
        self.bad += row.status not in ("ok", "check failed")
        if row.file in self.running:
            self.running.remove(row.file)
        if self.quiet:
            return
        if not self.bar:
            reason = f": {row.reason}" if row.reason else ""
            print(f"[{done}/{total}] {row.file}: {row.status}{reason} ({row.seconds:.1f} s)", file=self.stream,
                  flush=True)
        self._draw()

    def _draw(self) -> None:
        if not self.bar:
            return
        elapsed = time.monotonic() - self.start_time
        left = f", about {elapsed / self.done * (self.total - self.done):.0f} s left" if self.done else ""
        names = ", ".join(self.running[:2]) + (" ..." if len(self.running) > 2 else "")
        text = f"batch {self.done}/{self.total}, {self.bad} failed{left}  {names}"
        self.stream.write("\r" + text[:100].ljust(100))
        self.stream.flush()

    def close(self) -> None:
        if self.bar:
            self.stream.write("\n")
            self.stream.flush()


_CONTROL = re.compile(r"[\x00-\x08\x0b\x0c\x0e-\x1f\x7f-\x9f\ud800-\udfff]")


class Terminal:
    """Standard output or error as the command line writes it.

    Every control character but newline, tab and carriage return, and every
    byte of a file name that is not UTF-8, is written as a visible escape
    (``\\x1b``): a file named with an escape sequence cannot drive the terminal,
    and an undecodable name cannot stop the run.  Output to a closed pipe
    (``patterns flatten part.step | head -1``) is dropped: the files are still
    written and no traceback is shown.
    """

    def __init__(self, stream):
        self._stream, self._gone = stream, False

    def write(self, text: str) -> int:
        if not self._gone:
            try:
                return self._stream.write(_CONTROL.sub(escape, text))
            except BrokenPipeError:
                self._close()
        return len(text)

    def flush(self) -> None:
        if not self._gone:
            try:
                self._stream.flush()
            except BrokenPipeError:
                self._close()

    def _close(self) -> None:
        self._gone = True
        try:
            os.dup2(os.open(os.devnull, os.O_WRONLY), self._stream.fileno())
        except (OSError, ValueError, AttributeError):  # not a real file (a test's capture)
            pass

    def __getattr__(self, name):
        return getattr(self._stream, name)


def foreign_home() -> None:
    """``sudo -u user patterns ...`` without ``-H`` keeps root's HOME, which the user cannot read: ezdxf fails
    at import reading its settings and its font cache there, and matplotlib warns.  Then none looks there:
    the settings and caches (``XDG_CONFIG_HOME``, ``XDG_CACHE_HOME``, ``MPLCONFIGDIR``; the marker cache too)
    go to a folder of this run's, removed at exit."""
    import atexit
    import shutil
    import tempfile

    home = os.path.expanduser("~")
    if not os.path.isdir(home) or os.access(home, os.R_OK | os.X_OK):
        return
    own = tempfile.mkdtemp(prefix="patterns-home-")
    atexit.register(shutil.rmtree, own, ignore_errors=True)
    for name in ("XDG_CONFIG_HOME", "XDG_CACHE_HOME", "MPLCONFIGDIR"):
        if name not in os.environ or not os.access(os.environ[name], os.R_OK | os.W_OK | os.X_OK):
            os.environ[name] = own
