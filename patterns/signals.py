"""Ctrl-C and SIGTERM end a run wherever they land, and a run that was asked to stop writes nothing.

The command line (:func:`patterns.cli.main`) installs :func:`install` first thing, before any heavy
import.  The handler remembers the signal and raises where Python is (``KeyboardInterrupt``, or
:class:`~patterns.errors.Terminated` for SIGTERM), so that every ``finally`` runs; and because a library
may catch and drop what it raises there (trimesh's loaders catch ``BaseException``; an extension module
being imported turns it into ``ImportError``), the outputs' commit asks :func:`check` before it renames a
single file, and the command line's last word asks :func:`received`: a stop never depends on where Python
happened to be.  Where Python cannot raise it at all (inside a weak reference's callback or a ``__del__``,
such as importlib's module-lock clean-up during the heavy imports) it prints "Exception ignored in" and a
traceback; :func:`install` also sets an unraisable hook that keeps quiet about exactly those stops (they are
remembered, and :func:`check` raises them again) and passes everything else to the hook there was.
"""

from __future__ import annotations

import signal
import sys

from .errors import Terminated

__all__ = ["EXIT_INTERRUPTED", "EXIT_TERMINATED", "check", "committed", "exit_code", "install", "received", "stopped",
           "written"]

EXIT_INTERRUPTED, EXIT_TERMINATED = 130, 143
"""The exit codes of a run stopped by SIGINT and by SIGTERM (128 + the signal's number, as a shell gives)."""

_RECEIVED: list = []
"""The signals received since :func:`install`, in order."""

_COMMITTED: list = []
"""The outputs renamed onto their targets since :func:`install` (:func:`committed`)."""

_DEPTH: list = []
"""The unraisable hooks of the installs not yet restored, outermost first: a run's own install inside another
(the launcher's, then the command line's) is the same run, and keeps what was received before it."""

_UNDER: dict = {}
"""Each of those hooks (and of the run's restored ones) -> the hook it passes other errors to."""

_PREVIOUS: dict = {}
"""The handlers there were before the run's outermost install, put back when its last install is restored."""


def _handler(signum, frame):
    _RECEIVED.append(signum)
    if signum == signal.SIGINT:
        raise KeyboardInterrupt
    raise Terminated()


def install():
    """Handle SIGINT and SIGTERM as above (one ignored stays ignored); returns a function that puts back the
    handlers there were.  A new run forgets the stops of earlier ones; an install inside another (the launcher's,
    then :func:`patterns.cli.main`'s) is the same run and keeps a stop received between the two, such as one
    quieted during the heavy imports; the handlers and the unraisable hook there were come back when the last
    install is restored, in whatever order they are.  Outside the main thread (a test harness, a host's worker
    thread) nothing is installed and the function does nothing."""
    if not _DEPTH:
        _RECEIVED.clear()
        _COMMITTED.clear()
        _UNDER.clear()
    try:
        # a signal the process was started ignoring stays ignored (nohup, a shell's background job: as Python
        # itself leaves SIGINT then)
        previous = {s: signal.signal(s, _handler) for s in (signal.SIGINT, signal.SIGTERM)
                    if signal.getsignal(s) is not signal.SIG_IGN}
    except ValueError:  # not the main thread
        return lambda: None
    if not _DEPTH:
        _PREVIOUS.clear()
        _PREVIOUS.update(previous)
    hook = sys.unraisablehook

    def quiet(unraisable):
        # a stop raised where Python could not let it through: remembered already, raised again by check()
        if not (_RECEIVED and isinstance(unraisable.exc_value, (KeyboardInterrupt, Terminated))):
            hook(unraisable)

    def restore():
        if quiet in _DEPTH:
            _DEPTH.remove(quiet)
        current = sys.unraisablehook
        while current in _UNDER and current not in _DEPTH:  # ours, of an install restored: the one under it
            current = _UNDER[current]
        sys.unraisablehook = current  # a hook someone set after ours stays theirs
        if not _DEPTH:
            for s, handler in _PREVIOUS.items():
                signal.signal(s, handler)
            _RECEIVED.clear()  # the run is over: a library call after it is not stopped by it

    _UNDER[quiet] = hook
    sys.unraisablehook = quiet
    _DEPTH.append(quiet)
    return restore


def received() -> int | None:
    """The first signal received since :func:`install` (``signal.SIGINT`` or ``signal.SIGTERM``), or None."""
    return _RECEIVED[0] if _RECEIVED else None


def stopped(signum: int) -> str:
    """The word for a stop: ``"interrupted"`` (SIGINT) or ``"terminated"`` (SIGTERM)."""
    return "interrupted" if signum == signal.SIGINT else "terminated"


def exit_code(signum: int) -> int:
    """:data:`EXIT_INTERRUPTED` for SIGINT, :data:`EXIT_TERMINATED` for SIGTERM."""
    return EXIT_INTERRUPTED if signum == signal.SIGINT else EXIT_TERMINATED


def check() -> None:
    """Raise again a stop that was received but swallowed on its way (before anything is committed)."""
    first = received()
    if first == signal.SIGINT:
        raise KeyboardInterrupt
    if first is not None:
        raise Terminated()


def committed(path) -> None:
    """Note that ``path`` was written (renamed onto its target): a stop after it cannot say "nothing written"."""
    _COMMITTED.append(path)


def written() -> int:
    """How many outputs were written since :func:`install`."""
    return len(_COMMITTED)
