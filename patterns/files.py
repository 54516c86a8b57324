"""Files out: checked before any work, written atomically, several written as one.

* :func:`output_target`: where an output path really writes (through a symbolic
  link, to the file it names), or the one-line error saying why it cannot be
  written -- a folder, a device or pipe, a missing or read-only folder, a name
  too long, the path of an input of the same run.
* :func:`atomic_output`: one file, written to a temporary file beside the
  target and renamed over it only when complete; on any failure (a full disk,
  an interrupt) the temporary file is removed and the target left as it was.
* :class:`Outputs`: several files as one transaction: every one written to its
  temporary file first, all renamed only when all are complete; on a failure
  or an interrupt nothing is renamed and every temporary file is removed.

Temporary names are short (``.~patterns-XXXXXXXX`` and the target's suffix, at
most 27 characters), so that any name the file system allows for the target can
be written, and writers that go by the suffix (PNG or SVG) see the target's.
"""

from __future__ import annotations

import contextlib
import errno
import os
import shutil
import stat
import sys
import tempfile
from pathlib import Path

from . import signals
from .errors import ExportError, InputError, MissingFileError

__all__ = ["Outputs", "atomic_output", "check_input_file", "child_python", "csv_table", "output_target", "same_file"]

TEMP_PREFIX = ".~patterns-"
"""Temporary files start with this (and are removed when a write fails)."""


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _show(path) -> str:
    """A path as a message shows it (``os.fsdecode``: undecodable bytes kept as escapes by the printer)."""
    return os.fsdecode(path)


def same_file(a, b) -> bool:
    """True when paths ``a`` and ``b`` name one file (the same path resolved, or the same inode)."""
    a, b = Path(a), Path(b)
    try:
        if os.path.realpath(a) == os.path.realpath(b):
            return True
        return a.exists() and b.exists() and os.path.samefile(a, b)
    except OSError:
        return False


def output_target(path, *, what: str = "file", inputs=(), error=ExportError) -> Path:
    """The file an output path writes, checked; or the one-line error why it cannot be written.

    Parameters
    ----------
    path : str or Path
        The output as the user named it.
    what : str
        What it is, for the message (``"DXF file"``, ``"report"``).
    inputs : iterable of path
        The run's inputs: an output naming one of them is refused (it would be
        replaced).
    error : type
        The exception raised (:class:`~patterns.errors.ExportError` for the
        library's writers; the command line checks its plan with
        :class:`~patterns.errors.InputError`, a usage error).

    Returns
    -------
    Path
        The path to replace: ``path`` itself, or the file a symbolic link at
        ``path`` points to (written through the link, which stays a link).

    Raises
    ------
    error
        ``path`` is a folder, a device, a pipe or a socket; its folder is
        missing, not a folder or not writable; its name is longer than the file
        system allows; or it is one of ``inputs``.
    """
    shown = _show(path)
    target = Path(path)
    _check_name_length(target, shown, error)
    try:
        if target.is_symlink():
            _check_link_owners(target, shown, what, error)
            target = Path(os.path.realpath(target))  # write through the link: it stays a link to the new file
            _check_name_length(target, shown, error)
        info = os.stat(target)
    except FileNotFoundError:
        info = None
    except OSError as exc:
        raise error(f"{shown}: cannot write the {what} ({_reason(exc)})") from None
    if info is not None:
        if stat.S_ISDIR(info.st_mode):
            raise error(f"{shown}: is a folder; name a file for the {what}")
        if not stat.S_ISREG(info.st_mode):
            kind = ("a device" if stat.S_ISCHR(info.st_mode) or stat.S_ISBLK(info.st_mode) else
                    "a pipe" if stat.S_ISFIFO(info.st_mode) else "a socket" if stat.S_ISSOCK(info.st_mode)
                    else "not a regular file")
            raise error(f"{shown}: is {kind}; the {what} is written to a regular file only")
    folder = target.parent if str(target.parent) else Path(".")
    if not folder.is_dir():
        missing = "does not exist" if not folder.exists() else "is not a folder"
        raise error(f"{shown}: cannot write the {what}: folder {_show(folder)} {missing}")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise error(f"{shown}: cannot write the {what}: folder {_show(folder)} is not writable (permission denied)")
    for source in inputs:
        if same_file(target, source):
            raise error(f"{shown}: is an input of this run; writing the {what} there would replace it")
    return target


def _check_link_owners(link: Path, shown: str, what: str, error) -> None:
    """Every link on the way from ``link`` to its file, as the kernel's ``protected_symlinks`` judges links it
    follows: a link in a sticky, world-writable folder (``/tmp``) is followed only when this user or the
    folder's owner owns it.  The links are resolved here, not by the kernel, so the rule is kept here."""
    seen = 0
    while link.is_symlink() and seen < 40:
        info, folder = os.lstat(link), os.stat(link.parent if str(link.parent) else ".")
        shared = folder.st_mode & stat.S_ISVTX and folder.st_mode & stat.S_IWOTH
        if shared and info.st_uid not in (os.geteuid(), folder.st_uid):
            raise error(f"{shown}: is a link another user (uid {info.st_uid}) made in a shared folder (sticky, "
                        f"world-writable: {_show(link.parent)}); the {what} is not written through it")
        link = link.parent / os.readlink(link)
        seen += 1


def _check_name_length(target: Path, shown: str, error) -> None:
    """The name and the whole path within what the file system allows (a temporary name is shorter)."""
    folder = target.parent if str(target.parent) else Path(".")
    try:
        name_max = os.pathconf(folder, "PC_NAME_MAX") if folder.is_dir() else 255
        path_max = os.pathconf(folder, "PC_PATH_MAX") if folder.is_dir() else 4096
    except (OSError, ValueError):
        name_max, path_max = 255, 4096
    name = len(os.fsencode(target.name))
    if name > name_max:
        raise error(f"{shown}: the file name is {name} bytes long; the file system allows {name_max}")
    if len(os.fsencode(os.path.abspath(target))) >= path_max:
        raise error(f"{shown}: the path is longer than the file system allows ({path_max} bytes)")


@contextlib.contextmanager
def atomic_output(path, *, what: str = "file"):
    """Yield a temporary path to write; on success it replaces ``path``.

    If the body raises (or the process is interrupted), the temporary file is
    removed and ``path`` is left as it was: a failed export never leaves a
    partial file behind.  A symbolic link at ``path`` is written through (the
    link stays, pointing at the new file).

    Raises
    ------
    ExportError
        ``path`` cannot be written (see :func:`output_target`), or writing it
        failed (a full disk: "No space left on device"); the message names
        ``path``.
    """
    target = output_target(path, what=what)
    tmp = _temporary(target, path, what)
    try:
        yield tmp
        signals.check()  # a Ctrl-C a library swallowed on the way: nothing replaced
        _commit(tmp, target, path, what)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        if isinstance(exc, OSError) and not isinstance(exc, ExportError):
            raise ExportError(f"{_show(path)}: cannot write the {what} ({_reason(exc)})") from None
        raise


def _reason(exc: OSError) -> str:
    return exc.strerror or (errno.errorcode.get(exc.errno, "") if exc.errno else "") or str(exc)


def _temporary(target: Path, shown, what: str) -> Path:
    folder = target.parent if str(target.parent) else Path(".")
    try:
        fd, tmp = tempfile.mkstemp(prefix=TEMP_PREFIX, suffix=target.suffix[:8], dir=folder)
    except OSError as exc:
        raise ExportError(f"{_show(shown)}: cannot write the {what} ({_reason(exc)})") from None
    os.close(fd)
    return Path(tmp)


def _commit(tmp: Path, target: Path, shown, what: str) -> None:
    try:
        # mkstemp makes a private file: give it the mode a plain open() would.
        mode = target.stat().st_mode & 0o7777 if target.exists() else 0o666 & ~_umask()
        os.chmod(tmp, mode)
        os.replace(tmp, target)
        signals.committed(target)
    except OSError as exc:
        raise ExportError(f"{_show(shown)}: cannot write the {what} ({_reason(exc)})") from None


class Outputs:
    """Several output files written as one: all of them, or none.

    ``stage(path)`` checks ``path`` (:func:`output_target`) and returns the
    temporary file to write it to, in the same folder; ``commit()`` renames every
    staged file onto its target once all are written.  Leaving the ``with``
    block without ``commit()`` -- an error, ``KeyboardInterrupt``, the
    ``SystemExit`` of a SIGTERM handler -- removes every temporary file and
    changes nothing.

    Examples
    --------
    >>> with Outputs() as out:                                   # doctest: +SKIP
    ...     patterns.write(pattern, out.stage("part.dxf", what="DXF file"))
    ...     patterns.write(pattern, out.stage("part.json", what="report"))
    ...     out.commit()
    """

    def __init__(self, *, inputs=()):
        self._inputs = tuple(inputs)
        self._staged = []  # (temporary, target, path as given, what)

    def stage(self, path, *, what: str = "file") -> Path:
        """The temporary path to write ``path``'s content to (checked first; ExportError if it cannot be written)."""
        target = output_target(path, what=what, inputs=self._inputs)
        for _, other, given, _ in self._staged:
            if same_file(other, target):
                raise ExportError(f"{_show(path)}: named twice as an output of this run (also as {_show(given)})")
        tmp = _temporary(target, path, what)
        self._staged.append((tmp, target, path, what))
        return tmp

    def commit(self) -> None:
        """Rename every staged file onto its target."""
        staged, self._staged = self._staged, []
        k = 0
        try:
            signals.check()  # a Ctrl-C a library swallowed on the way (trimesh catches BaseException): none renamed
            for k, (tmp, target, given, what) in enumerate(staged):
                _commit(tmp, target, given, what)
        except BaseException:
            for tmp, *_ in staged[k:]:
                with contextlib.suppress(OSError):
                    os.unlink(tmp)
            raise

    def rollback(self) -> None:
        """Remove every staged temporary file (nothing is renamed)."""
        staged, self._staged = self._staged, []
        for tmp, *_ in staged:
            with contextlib.suppress(OSError):
                os.unlink(tmp)

    def __enter__(self) -> Outputs:
        return self

    def __exit__(self, kind, exc, tb) -> None:
        staged = list(self._staged)
        self.rollback()
        if isinstance(exc, (ExportError, InputError)):
            # A writer given a temporary path names it in its error: name the file the user asked for.
            message = str(exc)
            for tmp, _, given, _ in staged:
                message = message.replace(os.fsdecode(tmp), _show(given))
            if message != str(exc):
                raise type(exc)(message) from None


def check_input_file(path, *, what: str = "file") -> Path:
    """``path`` as an existing regular file this process may read, or the one-line InputError saying why not."""
    path = Path(path)
    shown = _show(path)
    try:
        info = os.stat(path)
    except FileNotFoundError:
        raise MissingFileError(f"{shown}: no such file") from None
    except OSError as exc:
        raise InputError(f"{shown}: cannot read the {what} ({_reason(exc)})") from None
    if stat.S_ISDIR(info.st_mode):
        raise InputError(f"{shown}: is a folder, not a {what}")
    if not stat.S_ISREG(info.st_mode):
        raise InputError(f"{shown}: is not a regular file (a device, pipe or socket); give a {what}")
    if not os.access(path, os.R_OK):
        raise InputError(f"{shown}: cannot read the {what} (permission denied)")
    return path


def child_python() -> str | None:
    """A Python to run a child process of ours with (sparrow's, a batch's workers): this one, or inside FreeCAD
    (whose ``sys.executable`` is FreeCAD's) the system's Python of the same version on PATH; None if there is
    none (the caller says what could not start)."""
    if Path(sys.executable).name.startswith("python"):
        return sys.executable
    return shutil.which(f"python{sys.version_info.major}.{sys.version_info.minor}") or shutil.which("python3")


def csv_table(fh, columns, *, where: str, what: str):
    """A ``csv.DictReader`` over ``fh`` whose header (any case, spaces around) names every one of ``columns``;
    InputError naming ``where`` and the columns missing otherwise (``what``: "a bend table")."""
    import csv

    reader = csv.DictReader(fh)
    header = [h.strip().lower() for h in (reader.fieldnames or [])]
    missing = [c for c in columns if c not in header]
    if missing:
        raise InputError(f"{where}: {what} needs the columns {', '.join(columns)}; missing {', '.join(missing)}")
    return reader
