"""The ``patterns`` command's first lines: the stop handlers before any import that takes time.

Importing :mod:`patterns.cli` takes about a second on a loaded machine (argparse, numpy, OpenCascade's
modules); a Ctrl-C or SIGTERM in that second used to be Python's own ``KeyboardInterrupt`` traceback.
Here the handlers of :mod:`patterns.signals` are installed first (this module and that one import in
about 10 ms), so a stop during the import ends the run in one line, having written nothing.
"""

from __future__ import annotations

import sys

from . import signals

__all__ = ["main"]


def main() -> int:
    """Run the command line (:func:`patterns.cli.main`) with the stop handlers in place from the start."""
    restore = None
    try:
        restore = signals.install()  # cli.main installs them again, nested: one run; these come back after both
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
