"""The ``patterns`` command's first lines: the stop handlers before any import that takes time.

Importing :mod:`patterns.cli` takes about a second on a loaded machine (argparse, numpy, OpenCascade's
modules); a Ctrl-C or SIGTERM in that second used to be Python's own ``KeyboardInterrupt`` traceback.
Here the handlers of :mod:`patterns.signals` are installed first (this module and that one import in
about 10 ms), so a stop during the import ends the run in one line, having written nothing.
"""

from __future__ import annotations

import sys

from . import signals

__all__ = ["main", "one_run_allocator"]

_MMAP_THRESHOLD = 32 * 1024 * 1024  # bytes: glibc's own ceiling for the threshold it raises by itself
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3  # mallopt's parameters (glibc's malloc.h)


def one_run_allocator() -> bool:
    """Let this process keep the memory it frees, for a run that ends when its work does (glibc only).

    The engine's arrays on a large mesh are 8-32 MB each (a million faces), made and dropped a few hundred
    times.  glibc gives such blocks back to the system when they are freed, and every new one is then
    zero-filled page by page by the kernel: on the million-face cap that was a sixth of the time (7.4 s
    against 6.2 s, the same layout bit for bit).  Blocks up to 32 MB are taken from the heap, and the heap is
    never trimmed: the process keeps its peak until it exits.  The ``patterns`` command calls this for every
    command but ``serve`` (a long-lived process beside a CAD program, which should give memory back); a
    script that flattens large meshes may call it too, or set ``MALLOC_MMAP_THRESHOLD_=33554432
    MALLOC_TRIM_THRESHOLD_=2147483647`` in its environment.  Returns whether the C library took the settings
    (False where it is not glibc's: nothing changes).
    """
    if not sys.platform.startswith("linux"):  # glibc's knobs (Windows has no C library to open by None)
        return False
    import ctypes

    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):  # a C library without mallopt
        return False
    mallopt.argtypes, mallopt.restype = [ctypes.c_int, ctypes.c_int], ctypes.c_int
    return bool(mallopt(_M_MMAP_THRESHOLD, _MMAP_THRESHOLD)) and bool(mallopt(_M_TRIM_THRESHOLD, 2**31 - 1))


def main() -> int:
    """Run the command line (:func:`patterns.cli.main`) with the stop handlers in place from the start."""
    restore = None
    try:
        restore = signals.install()  # cli.main installs them again, nested: one run; these come back after both
        if sys.argv[1:2] != ["serve"]:
            one_run_allocator()
        try:
            from .cli import main as run
        except BaseException:
            stop = signals.received()
            if stop is None:
                raise
            print(f"patterns: {signals.stopped(stop)}; nothing written", file=sys.stderr)
            return signals.exit_code(stop)
        return run()
    finally:
        if restore is not None:
            restore()
