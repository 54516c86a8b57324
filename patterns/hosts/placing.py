"""A host's side put into a host's folder, or taken out: all or nothing, never into someone else's folder.

Both installers (:mod:`.freecad`, :mod:`.blender`) copy a package folder, the hosts' worker client
(``client.py``) and a record of the engine (``engine.json``: the command to start, the version, the protocol)
into a staging folder beside the target, then swap it in: the old one aside, the new one in, the old one gone,
so that a failure leaves the old one or the new one, never neither.  A folder without ``engine.json`` is not
ours: it is never replaced or removed.
"""

from __future__ import annotations

import json
import shutil
import sys
import tempfile
from pathlib import Path

from ..errors import InputError

__all__ = ["CLIENT", "MARK", "engine_record", "place", "record_text", "remove"]

CLIENT = Path(__file__).resolve().parent / "client.py"
"""The worker's client (standard library only), copied into every host's package."""
MARK = "engine.json"
"""The file that says a folder is ours (an uninstall removes no other)."""


def engine_record() -> dict:
    """What a host's side records of the engine: this interpreter running ``-m patterns``, its version and
    protocol."""
    from .. import __version__
    from ..service import PROTOCOL

    return {"command": [sys.executable, "-m", "patterns"], "version": __version__, "protocol": PROTOCOL}


def place(source: Path, target: Path, *, files: dict, not_ours: str) -> Path:
    """Copy the folder ``source`` to ``target`` with ``files`` (``{relative path: text or a file's Path}``)
    added, replacing an earlier one of ours; InputError (``not_ours`` says what is in the way) if the place is
    taken by something else or cannot be written."""
    if target.is_symlink() or (target.exists() and not (target / MARK).is_file()):
        raise InputError(f"{target}: {not_ours}")
    parent = target.parent
    try:
        parent.mkdir(parents=True, exist_ok=True)
        staging = Path(tempfile.mkdtemp(prefix=".patterns-", dir=parent))
    except OSError as exc:
        raise InputError(f"{parent}: cannot write there ({exc.strerror})") from None
    try:
        folder = staging / target.name
        shutil.copytree(source, folder, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
        for relative, content in files.items():
            if isinstance(content, Path):
                shutil.copy2(content, folder / relative)
            else:
                (folder / relative).write_text(content, encoding="utf-8")
        if target.exists():  # the old one aside, the new one in, then the old one gone: never neither
            target.rename(staging / "old")
        folder.rename(target)
    except OSError as exc:
        raise InputError(f"{target}: cannot install there ({exc.strerror or exc})") from None
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    return target


def remove(target: Path, *, what: str) -> Path | None:
    """Remove ``target`` if it is ours (None if there is none); InputError, leaving it, if it is not."""
    if not target.exists() and not target.is_symlink():
        return None
    if target.is_symlink() or not (target / MARK).is_file():
        raise InputError(f"{target}: not {what} (no {MARK}); left as it is")
    try:
        shutil.rmtree(target)
    except OSError as exc:
        raise InputError(f"{target}: cannot remove it ({exc.strerror or exc})") from None
    return target


def record_text() -> str:
    """``engine.json``'s text."""
    return json.dumps(engine_record(), indent=2) + "\n"
