"""A batch's plan and its records: options, the files and their output names, the rows.

Everything a batch checks before any work lives here: :class:`BatchOptions`
(the one declaration of how a batch runs), the input files of a folder and
the names their outputs get (:func:`output_stems`), the output folder; and
what every file ends as, a :class:`Row` of a :class:`BatchResult`.
"""

from __future__ import annotations

import errno
import os
from dataclasses import dataclass
from pathlib import Path

from ..errors import InputError
from ..options import Options, option
from ..reading import CAD_SUFFIXES, MESH_SUFFIXES
from ..text import printable

__all__ = ["STATUSES", "BatchOptions", "BatchResult", "Row", "check_output_folder", "largest_first", "output_stems",
           "plan_batch", "skipped_in", "wanted"]

STATUSES = ("ok", "check failed", "failed", "timeout", "lost", "not run", "skipped")
"""What a row's status can be."""


@dataclass(frozen=True, repr=False)
class BatchOptions(Options):
    """How a batch runs (:func:`batch`, ``patterns batch``); the part's own options are those of ``flatten``
    (or, with ``unfold``, of ``unfold``)."""

    jobs: int | None = option(None, "parallel processes on this machine (default: its CPU count); each runs one "
                                    "BLAS thread when there are several", integer=True, low=1, high=1024, optional=True,
                              metavar="N")
    scheduler: str | None = option(None, "run on a Dask distributed cluster at this address (tcp://host:8786) "
                                         "instead of local processes; needs patterns[dask] here and patterns on "
                                         "every worker, no shared disk", optional=True, metavar="ADDRESS")
    wait: float = option(30.0, "Dask: seconds to wait for a first worker to join the scheduler", low=0,
                         low_open=True, high=86400, metavar="S")
    timeout: float = option(600.0, "seconds one file may take; a file still running then is stopped and reported "
                                   "(its worker replaced)", low=0, low_open=True, high=1e6, metavar="S")
    memory: float | None = option(None, "megabytes of memory (address space) one local worker process may use, "
                                        "at least 1024 (what starting one takes); a file that needs more fails "
                                        "alone (default: the machine's memory shared among the processes)",
                                  low=1024, optional=True, high=1e9, metavar="MB")
    report: bool = option(True, "write each part's JSON report (NAME.json); --no-report leaves it out",
                          off="write no JSON report (NAME.json) per part")
    preview: bool = option(False, "also render each DXF at 1:1 (NAME_preview.png)")
    heat_map: bool = option(False, "also draw each part's strain heat map (NAME_heatmap.png)")
    unfold: bool = option(False, "unfold every part as bent sheet metal into one blank each (NAME.dxf and NAME.json; "
                                 "--k-factor or --bend-table as for patterns unfold), instead of flattening it")
    quiet: bool = option(False, "no progress lines (the summary table still comes)")


@dataclass(frozen=True)
class Row:
    """One input file's fate.

    Attributes
    ----------
    file : str
        The input's name.
    status : str
        One of :data:`STATUSES`.
    reason : str
        Why it failed, timed out, was lost or fails its check ("" when ok).
    panels, seams : int or None
    strain_rms, strain_max : float or None
        The worst panel's, ratios.
    seconds : float
        Time on the worker (or until stopped).
    written : tuple of str
        The files written for it, in the output folder.
    """

    file: str
    status: str
    reason: str = ""
    panels: int | None = None
    seams: int | None = None
    strain_rms: float | None = None
    strain_max: float | None = None
    seconds: float = 0.0
    written: tuple = ()
    thickness: float | None = None
    """A blank's (``batch --unfold``): the sheet's thickness, mm."""
    size: tuple | None = None
    """A blank's ``(width, height)``, mm."""
    bends: int | None = None
    """A blank's bends."""


@dataclass(frozen=True)
class BatchResult:
    """Every row, in the order of the input files, and how the batch ended.

    Attributes
    ----------
    rows : tuple of Row
    where : str
        What ran it (``"2 processes"``, ``"Dask scheduler tcp://..."``).
    stopped : str
        ``""``, or ``"interrupted"`` (Ctrl-C) or ``"terminated"`` (SIGTERM).
    """

    rows: tuple
    where: str
    stopped: str = ""

    def count(self, status: str) -> int:
        return sum(r.status == status for r in self.rows)

    @property
    def exit_code(self) -> int:
        """0 all ok; 1 some only fail a check; 2 some failed, timed out or were lost; 130/143 stopped (an entry
        skipped, a folder or a pipe named like a part, is no failure: listed, not counted against the batch)."""
        if self.stopped:
            return 130 if self.stopped == "interrupted" else 143
        if any(r.status not in ("ok", "check failed", "skipped") for r in self.rows):
            return 2
        return 1 if self.count("check failed") else 0


def output_stems(files) -> dict:
    """``{input path: output stem}``: the name without its suffix, unless two inputs would share it.

    Names are compared case-folded, as a case-insensitive disk (macOS, Windows, a USB stick, a network share)
    compares them.  ``a.step`` and ``a.stl`` both give ``a``: then each keeps its whole name
    (``a.step.dxf``, ``a.stl.dxf``), so that neither overwrites the other; so do ``Part.step`` and
    ``part.stl``.  A stem that is not a plain name (``.``, ``..``, empty) keeps the whole name too.  Names that
    still collide -- ``Part.step`` and ``part.step``, or one name in two folders -- are numbered after the
    first, in the order of ``files`` (``part.step-2``).
    """
    stems = {}
    for path in files:
        stem = Path(path).stem
        stems[path] = stem if stem not in ("", ".", "..") else Path(path).name
    changed = True
    while changed:  # a whole name may meet another's stem (a.step, a.stl and a.step.obj): until none meet
        changed = False
        for group in _collisions(stems):
            for path in group:
                changed |= stems[path] != Path(path).name
                stems[path] = Path(path).name
    taken = {_fold(stem) for stem in stems.values()}
    for group in _collisions(stems):
        for path in group[1:]:
            number = 2
            while _fold(f"{stems[path]}-{number}") in taken:
                number += 1
            stems[path] = f"{stems[path]}-{number}"
            taken.add(_fold(stems[path]))
    return stems


def _fold(name: str) -> str:
    """A name as a case-insensitive disk compares it."""
    return name.casefold()


def _collisions(stems: dict) -> list:
    """The groups of inputs (in their order) whose stems are one name on a case-insensitive disk."""
    groups = {}
    for path, stem in stems.items():
        groups.setdefault(_fold(stem), []).append(path)
    return [group for group in groups.values() if len(group) > 1]


_SUFFIXES = {"pattern": "{}.dxf", "report": "{}.json", "preview": "{}_preview.png", "heat_map": "{}_heatmap.png"}


def wanted(options: BatchOptions) -> tuple:
    """The output kinds each part writes: its pattern or blank, then those the options ask for."""
    return ("pattern",) + tuple(k for k in ("report", "heat_map", "preview") if getattr(options, k))


def largest_first(files) -> list[int]:
    """The files' indices, largest file first: the longest work first balances the workers best (rows
    still come back in whatever order they end; the batch reports them in the files' order)."""
    sizes = [f.stat().st_size if f.exists() else 0 for f in files]
    return sorted(range(len(files)), key=lambda i: -sizes[i])


def plan_batch(folder, out, *, unfold: bool = False) -> tuple[list, dict]:
    """The input files and their output stems, checked before any work (InputError otherwise).

    With ``unfold``, CAD files only (a mesh is no bent solid)."""
    folder, out = Path(folder), Path(out)
    if not folder.is_dir():
        if folder.exists():
            raise InputError(f"{os.fsdecode(folder)}: is a file, not a folder; batch takes a folder of parts "
                             f"(every CAD and mesh file directly in it)")
        raise InputError(f"{os.fsdecode(folder)}: no such folder")
    kinds = CAD_SUFFIXES if unfold else CAD_SUFFIXES + MESH_SUFFIXES
    files = sorted(p for p in folder.iterdir() if p.suffix.lower() in kinds and p.is_file())
    if not files:
        what = "CAD (STEP, BREP, IGES)" if unfold else "CAD or mesh"
        raise InputError(f"{os.fsdecode(folder)}: no {what} files in this folder")
    check_output_folder(out)
    return files, output_stems(files)


def skipped_in(folder, *, unfold: bool = False) -> tuple:
    """``((name, why), ...)``: the entries of ``folder`` named like a part (a CAD or mesh suffix) that are no file
    to read -- a folder, a pipe, a device or socket (directly or through a link), a symbolic link to nothing or
    a loop of them -- each with why it is left out (a batch lists them as ``skipped`` rows, never silently)."""
    import stat

    kinds = CAD_SUFFIXES if unfold else CAD_SUFFIXES + MESH_SUFFIXES
    out = []
    for p in sorted(Path(folder).iterdir()):
        if p.suffix.lower() not in kinds or p.is_file():
            continue
        try:
            mode = os.stat(p).st_mode
        except OSError as exc:
            why = ("a loop of symbolic links" if exc.errno == errno.ELOOP else
                   "a symbolic link to nothing" if p.is_symlink() else f"cannot be read ({exc.strerror})")
        else:
            why = ("a folder" if stat.S_ISDIR(mode) else "a pipe (FIFO)" if stat.S_ISFIFO(mode) else
                   "a device" if stat.S_ISCHR(mode) or stat.S_ISBLK(mode) else "a socket" if stat.S_ISSOCK(mode)
                   else "not a regular file")
            if p.is_symlink():
                why += ", through a symbolic link"
        out.append((printable(p.name), why + ", not a part file"))
    return tuple(out)


def check_output_folder(out) -> None:
    """InputError unless ``out`` is a writable folder, or one that can be made (its folder exists, writable)."""
    out = Path(out)
    if out.exists():
        if not out.is_dir():
            raise InputError(f"{os.fsdecode(out)}: is a file; name a folder for the results")
        if not os.access(out, os.W_OK | os.X_OK):
            raise InputError(f"{os.fsdecode(out)}: the output folder is not writable (permission denied)")
    else:
        parent = out.parent if str(out.parent) else Path(".")
        if not parent.is_dir() or not os.access(parent, os.W_OK | os.X_OK):
            raise InputError(f"{os.fsdecode(out)}: cannot create the output folder (its folder "
                             f"{os.fsdecode(parent)} is missing or not writable)")
