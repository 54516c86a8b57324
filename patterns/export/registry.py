"""The writers' registry: every output profile by name, each one module of ``patterns/export``.

A :class:`Profile` names a writer ``write(drawing, path, options)``, the file
suffix it writes and whether it is that suffix's default.  The built-in
profiles are registered in :mod:`patterns.export.profiles`, one line each;
:func:`register` adds another (a shop's own DXF dialect, a plotter's HPGL).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from ..errors import InputError

__all__ = ["Profile", "names", "profile_for", "profiles", "register", "unregister"]


@dataclass(frozen=True)
class Profile:
    """One output profile.

    Attributes
    ----------
    name : str
        What ``profile=`` (``--profile``) calls it.
    suffix : str
        The file suffix it writes (``".dxf"``).
    write : callable
        ``write(drawing, path, options)``: a :class:`patterns.pieces.Drawing` into ``path`` (atomically), with
        the :class:`patterns.export.options.WriteOptions`.
    help : str
        One line for ``--help`` and the docs.
    default : bool
        The profile a file of this suffix gets when none is named (the only profile of a suffix is its
        default anyway).
    """

    name: str
    suffix: str
    write: Callable
    help: str
    default: bool = False


_PROFILES: dict = {}


def register(profile: Profile) -> Profile:
    """Add a profile (InputError if its name is taken, or its suffix has a default already and it claims to be
    one too)."""
    if profile.name in _PROFILES:
        raise InputError(f"a profile named {profile.name!r} is registered already")
    if profile.default and any(p.default and p.suffix == profile.suffix for p in _PROFILES.values()):
        raise InputError(f"{profile.suffix} files have a default profile already")
    _PROFILES[profile.name] = profile
    return profile


def unregister(name: str) -> None:
    """Remove a registered profile (a test's toy)."""
    _PROFILES.pop(name, None)


def profiles() -> tuple:
    """Every registered profile, in the order registered."""
    return tuple(_PROFILES.values())


def names() -> tuple:
    return tuple(_PROFILES)


def profile_for(path, name: str | None) -> Profile:
    """The profile that writes ``path``: the one named (its suffix must match), else its suffix's default."""
    suffix = Path(path).suffix.lower()
    if name is not None:
        if name not in _PROFILES:
            raise InputError(f"{path}: unknown profile {name!r}; the profiles are {', '.join(_PROFILES)}")
        profile = _PROFILES[name]
        if suffix != profile.suffix:
            raise InputError(f"{path}: the {name} profile writes {profile.suffix} files, not "
                             f"{suffix or '(no suffix)'!r}")
        return profile
    mine = [p for p in _PROFILES.values() if p.suffix == suffix]
    for profile in mine:
        if profile.default or len(mine) == 1:  # a suffix's default, or its only profile
            return profile
    known = sorted({p.suffix for p in _PROFILES.values()})
    raise InputError(f"{path}: cannot write {suffix or '(no suffix)'!r} files; write {', '.join(known)}")


