"""One validator for the numbers every option takes.

Every numeric option of the API (and so of the command line, which calls it)
is checked here, the same way: a real number (Python or numpy, never a
``bool``), finite unless said otherwise, within its bounds; an
:class:`~patterns.errors.InputError` naming the option and what it takes
otherwise.
"""

from __future__ import annotations

import numbers

import numpy as np

from .errors import InputError

__all__ = ["check_number", "is_number"]


def is_number(value, *, integer: bool = False) -> bool:
    """True for a real number (``int``, ``float``, numpy's), not a ``bool``; integers only if ``integer``."""
    if isinstance(value, (bool, np.bool_)):
        return False
    kind = numbers.Integral if integer else numbers.Real
    return isinstance(value, kind)


def check_number(value, option: str, *, low=None, high=None, low_open: bool = False, high_open: bool = False,
                 integer: bool = False, finite: bool = True, name: str | None = None):
    """``value`` as a Python ``float`` (``int`` if ``integer``), or InputError naming ``option``.

    Parameters
    ----------
    value
        What the caller gave.
    option : str
        The option's name, for the message (``"max_strain"``).
    low, high : float, optional
        Bounds, inclusive unless ``low_open`` / ``high_open``.
    integer : bool
        Only integers.
    finite : bool
        Refuse NaN and infinities (default).
    name : str, optional
        What the option belongs to (a file or model name), put first in the message.
    """
    ok = is_number(value, integer=integer) and not (finite and not np.isfinite(value))
    if ok and low is not None:
        ok = value > low if low_open else value >= low
    if ok and high is not None:
        ok = value < high if high_open else value <= high
    if not ok:
        prefix = f"{name}: " if name else ""
        raise InputError(f"{prefix}{option} must be {_describe(low, high, low_open, high_open, integer)}, "
                         f"got {value!r}")
    return int(value) if integer else float(value)


def _describe(low, high, low_open, high_open, integer) -> str:
    """``"a positive number"``, ``"an integer >= 0"``, ``"a number between 0 and 1"``, ..."""
    kind = "integer" if integer else "number"
    article = "an" if integer else "a"
    if low is not None and high is not None:
        return f"{article} {kind} between {low:g} and {high:g}"
    if low == 0 and low_open:
        return f"a positive {kind}"
    if low is not None:
        return f"{article} {kind} {'>' if low_open else '>='} {low:g}"
    if high is not None:
        return f"{article} {kind} {'<' if high_open else '<='} {high:g}"
    return f"a finite {kind}"
