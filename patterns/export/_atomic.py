"""Atomic file output: write to a temporary file beside the target, then rename."""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path

from ..errors import ExportError

__all__ = ["atomic_output"]


@contextlib.contextmanager
def atomic_output(path, *, what: str = "file"):
    """Yield a temporary path to write; on success it replaces ``path``.

    If the body raises, the temporary file is removed and ``path`` is left as it
    was: a failed export never leaves a partial file behind.

    Raises
    ------
    ExportError
        The folder does not exist or is not writable (the message names ``path``).
    """
    target = Path(path)
    folder = target.parent if str(target.parent) else Path(".")
    if not folder.is_dir():
        raise ExportError(f"{target}: cannot write the {what}: folder {folder} does not exist")
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".part", dir=folder)
    except OSError as exc:
        raise ExportError(f"{target}: cannot write the {what} ({exc.strerror})") from None
    os.close(fd)
    try:
        yield Path(tmp)
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
