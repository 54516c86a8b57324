"""The engine, seen from Blender: the worker of :mod:`.client` (copied in by ``patterns blender install``),
started from what that command recorded in ``engine.json`` beside this file.

Standard library only: nothing of the engine's environment is ever imported into Blender's process.
"""

import atexit
import json
import os

from .client import Engine as _Engine
from .client import EngineError, Refused
from .client import configured as _configured

__all__ = ["CONFIG", "SCHEMA", "Engine", "EngineError", "Refused", "configured", "engine", "schema"]

HERE = os.path.dirname(os.path.abspath(__file__))
CONFIG = os.path.join(HERE, "engine.json")
"""What ``patterns blender install`` recorded: ``{"command": [...], "version": ..., "protocol": ...}``."""
SCHEMA = os.path.join(HERE, "schema.json")
"""The engine's options (``patterns.service.schema()``), written by ``patterns blender install``."""

INSTALL_HINT = ("install the engine in an environment of its own and put the add-on into Blender from it; in a "
                "clone of patterns: python3 -m venv .venv && .venv/bin/pip install . && "
                ".venv/bin/patterns blender install (docs/blender.md; or set PATTERNS_ENGINE to the engine's "
                "command line)")
"""The commands a user runs where the engine cannot be found or started."""


def configured():
    """The worker's command line (``$PATTERNS_ENGINE``, else ``engine.json``'s), or EngineError saying what to run."""
    return _configured(CONFIG, INSTALL_HINT)


def schema():
    """``{kind: [property, ...]}`` as the install recorded it; empty where it did not."""
    try:
        with open(SCHEMA, encoding="utf-8") as f:
            return json.load(f)
    except (OSError, ValueError):
        return {}


class Engine(_Engine):
    """Blender's worker (see :class:`.client.Engine`)."""

    def __init__(self, command=None):
        super().__init__(command, config=CONFIG, host="blender", hint=INSTALL_HINT, install="patterns blender install")


_ENGINE = None


def engine():
    """Blender's one engine."""
    global _ENGINE
    if _ENGINE is None:
        _ENGINE = Engine()
        atexit.register(_ENGINE.stop)
    return _ENGINE
