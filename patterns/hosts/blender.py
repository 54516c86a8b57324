"""``patterns blender install`` and ``uninstall``: the add-on into Blender's add-ons folder, and back out.

The add-on (``blender_addon/patterns_blender``: Blender and the standard library only) is copied to
``<add-ons folder>/patterns_blender`` with the hosts' worker client (``client.py``), the engine's option
schema (``schema.json``: the add-on's properties are made from it) and ``engine.json``, which records the
engine to start: this interpreter running ``-m patterns``.  Nothing is installed into Blender's Python.

The add-ons folder: ``--target``; else ``$BLENDER_USER_SCRIPTS/addons`` (as Blender takes it); else
``scripts/addons`` of every Blender 4.2 or later found in Blender's user folder: ``$XDG_CONFIG_HOME/blender``
or ``~/.config/blender`` on Linux, ``~/Library/Application Support/Blender`` on macOS,
``%APPDATA%\\Blender Foundation\\Blender`` on Windows.  ``--zip FILE`` writes the same as a zip for
Blender's Preferences > Add-ons > Install from Disk.
"""

from __future__ import annotations

import json
import os
import re
import sys
import zipfile
from pathlib import Path

from ..errors import InputError
from ..files import atomic_output
from .placing import CLIENT, MARK, place, record_text, remove

__all__ = ["ADDON", "NAME", "addons_dirs", "install", "uninstall", "write_zip"]

ADDON = Path(__file__).resolve().parent / "blender_addon" / "patterns_blender"
"""The add-on's files."""
NAME = "patterns_blender"
"""Its folder's (and module's) name."""
OLDEST = (4, 2)
"""The oldest Blender the add-on is for."""


def _root(environ, platform: str, home: Path) -> Path:
    if platform.startswith("win"):
        return Path(environ.get("APPDATA") or home / "AppData" / "Roaming") / "Blender Foundation" / "Blender"
    if platform == "darwin":
        return home / "Library" / "Application Support" / "Blender"
    return Path(environ.get("XDG_CONFIG_HOME") or home / ".config") / "blender"


def addons_dirs(target: Path | None = None, *, environ=None, platform: str | None = None,
                home: Path | None = None) -> list:
    """The add-ons folders to install into (see the module); InputError where no Blender is found."""
    if target is not None:
        return [Path(target).expanduser()]
    environ = os.environ if environ is None else environ
    if environ.get("BLENDER_USER_SCRIPTS"):
        return [Path(environ["BLENDER_USER_SCRIPTS"]).expanduser() / "addons"]
    root = _root(environ, platform or sys.platform, home or Path.home())
    versions = sorted((tuple(int(x) for x in p.name.split(".")), p) for p in (root.iterdir() if root.is_dir() else ())
                      if re.fullmatch(r"\d+\.\d+", p.name))
    found = [p / "scripts" / "addons" for v, p in versions if v >= OLDEST]
    if not found:
        raise InputError(f"{root}: no Blender {OLDEST[0]}.{OLDEST[1]} or later found there (start Blender once, or "
                         f"give --target DIR: the add-ons folder)")
    return found


def _files() -> dict:
    from ..service import schema

    return {MARK: record_text(), "client.py": CLIENT, "schema.json": json.dumps(schema(), indent=1) + "\n"}


def install(target: Path | None = None) -> list:
    """Put the add-on into each add-ons folder (replacing an earlier one of ours); returns the folders."""
    files = _files()
    return [place(ADDON, folder / NAME, files=files,
                  not_ours="a folder that is not the patterns add-on is in the way: move it aside")
            for folder in addons_dirs(target)]


def uninstall(target: Path | None = None) -> list:
    """Take the add-on out of each add-ons folder; returns the folders removed."""
    gone = [remove(folder / NAME, what="the patterns add-on installed by `patterns blender install`")
            for folder in addons_dirs(target)]
    return [g for g in gone if g is not None]


def write_zip(path: Path) -> Path:
    """The add-on as a zip for Preferences > Add-ons > Install from Disk (``patterns_blender/`` inside)."""
    path = Path(path)
    if path.suffix.lower() != ".zip":
        raise InputError(f"{path}: the add-on is written as a .zip")
    with atomic_output(path, what="zip") as tmp, zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as z:
        for file in sorted(ADDON.rglob("*")):
            if file.is_file() and "__pycache__" not in file.parts:
                z.write(file, f"{NAME}/{file.relative_to(ADDON).as_posix()}")
        for relative, content in _files().items():
            if isinstance(content, Path):
                z.write(content, f"{NAME}/{relative}")
            else:
                z.writestr(f"{NAME}/{relative}", content)
    return path
