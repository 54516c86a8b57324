"""The engine, seen from FreeCAD: the worker of :mod:`.client` (copied in by ``patterns freecad install``),
started from what that command recorded in ``engine.json`` beside this package.

Standard library only: nothing of the engine's environment is ever imported into FreeCAD's process.
"""

import atexit
import os

from .client import HELLO, PROTOCOL, EngineError, Refused, key_of
from .client import Engine as _Engine
from .client import configured as _configured

__all__ = ["CONFIG", "HELLO", "ICONS", "INSTALL_HINT", "PROTOCOL", "Engine", "EngineError", "Refused", "configured",
           "engine", "key_of"]

HERE = os.path.dirname(os.path.abspath(__file__))
ICONS = os.path.join(HERE, "resources", "icons")
"""The workbench's icons."""
CONFIG = os.path.join(os.path.dirname(os.path.dirname(HERE)), "engine.json")
"""What ``patterns freecad install`` recorded: ``{"command": [...], "version": ..., "protocol": ...}``."""

INSTALL_HINT = ("install the engine in an environment of its own and put the workbench into FreeCAD from it; in a "
                "clone of patterns:\n"
                "    python3 -m venv .venv && .venv/bin/pip install .\n"
                "    .venv/bin/patterns freecad install\n"
                "(docs/freecad.md; or set PATTERNS_ENGINE to the engine's command line, e.g. "
                "\"/path/to/python -m patterns\"); FreeCAD need not be restarted")
"""The commands a user runs where the engine cannot be found or started."""


def configured():
    """The worker's command line (``$PATTERNS_ENGINE``, else ``engine.json``'s), or EngineError saying what to run."""
    return _configured(CONFIG, INSTALL_HINT)


class Engine(_Engine):
    """FreeCAD's worker (see :class:`.client.Engine`)."""

    def __init__(self, command=None):
        super().__init__(command, config=CONFIG, host="freecad", hint=INSTALL_HINT, install="patterns freecad install")


_ENGINE = None


def engine():
    """The host's one engine."""
    global _ENGINE
    if _ENGINE is None:
        _ENGINE = Engine()
        atexit.register(_ENGINE.stop)
    return _ENGINE
