"""``patterns freecad install`` and ``uninstall``: the workbench into FreeCAD's ``Mod`` folder, and back out.

The workbench (``freecad_addon/``: ``package.xml`` and the ``freecad.patterns_wb`` package, FreeCAD and
the standard library only) is copied to ``<FreeCAD's user data folder>/Mod/patterns``, with an
``engine.json`` that records which engine to start: this interpreter running ``-m patterns``.  Nothing is
installed into FreeCAD's Python; FreeCAD keeps its own numpy, and every other workbench its packages.

FreeCAD's user data folder: ``--user-dir``; else ``$FREECAD_USER_DATA`` or ``$FREECAD_USER_HOME`` (as
FreeCAD takes them); else the platform's: ``$XDG_DATA_HOME/FreeCAD`` or ``~/.local/share/FreeCAD`` on
Linux (FreeCAD 0.20, 0.21 and 1.0; ``~/.FreeCAD`` only with its ``KeepDeprecatedPaths`` setting: give
``--user-dir`` then), ``~/Library/Application Support/FreeCAD`` on macOS, ``%APPDATA%\\FreeCAD`` on
Windows.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

from .placing import CLIENT, MARK, place, record_text, remove

__all__ = ["ADDON", "CLIENT", "NAME", "install", "uninstall", "user_dir"]

ADDON = Path(__file__).resolve().parent / "freecad_addon"
"""The workbench's files, as they go into ``Mod/patterns``."""
NAME = "patterns"
"""The folder's name in ``Mod``."""


def user_dir(given: Path | None = None, *, environ=None, platform: str | None = None, home: Path | None = None) -> Path:
    """FreeCAD's user data folder: ``given``, else as the module says."""
    if given is not None:
        return Path(given).expanduser()
    environ = os.environ if environ is None else environ
    for name in ("FREECAD_USER_DATA", "FREECAD_USER_HOME"):
        if environ.get(name):
            return Path(environ[name]).expanduser()
    platform = platform or sys.platform
    home = home or Path.home()
    if platform.startswith("win"):
        return Path(environ.get("APPDATA") or home / "AppData" / "Roaming") / "FreeCAD"
    if platform == "darwin":
        return home / "Library" / "Application Support" / "FreeCAD"
    return Path(environ.get("XDG_DATA_HOME") or home / ".local" / "share") / "FreeCAD"


def install(user: Path | None = None) -> Path:
    """Put the workbench into ``<user>/Mod/patterns`` (replacing an earlier one of ours) and record this
    interpreter as its engine; returns the folder.  InputError if the place is taken by something else or
    cannot be written."""
    target = user_dir(user) / "Mod" / NAME
    return place(ADDON, target, files={MARK: record_text(), "freecad/patterns_wb/client.py": CLIENT},
                 not_ours="a folder that is not a patterns workbench is in the way (0.1.0's clone or link of the "
                          "repository? move it aside: docs/freecad.md)")


def uninstall(user: Path | None = None) -> Path | None:
    """Take the workbench out of ``<user>/Mod``; returns the folder removed, or None if there was none.
    InputError if the folder there is not ours."""
    return remove(user_dir(user) / "Mod" / NAME, what="a patterns workbench installed by `patterns freecad install`")
