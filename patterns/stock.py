"""The stock a nest on sheets is cut from: one sheet size, or several (the stock on hand: full sheets and
remnants), each with how many are on hand (:attr:`patterns.NestOptions.sheet`).

A size is ``(length, width)`` in mm, or ``(length, width, count)`` for a size of which only ``count`` sheets are
on hand (a remnant); a size without a count is bought as needed.  The command line writes the same as
``2500x1250`` or ``2500x1250,1200x800:2``.
"""

from __future__ import annotations

from dataclasses import dataclass

from .errors import InputError
from .options import check_number

__all__ = ["SheetSize", "check_sheet", "parse_sheet", "sheet_sizes"]

LARGEST_SHEET = 1e7
"""mm: the longest side a sheet may have (a roll of sheet stock is the longest there is)."""


@dataclass(frozen=True)
class SheetSize:
    """One size of sheet on hand.

    Attributes
    ----------
    length : float
        Along the roll's direction (the pieces' grain), mm.
    width : float
        Across it, mm.
    count : int or None
        How many sheets of this size are on hand; None: as many as the nest needs.
    """

    length: float
    width: float
    count: int | None = None

    @property
    def area(self) -> float:
        """mm^2."""
        return self.length * self.width

    def __str__(self) -> str:
        return f"{self.length:g} x {self.width:g} mm" + ("" if self.count is None else f" ({self.count} on hand)")


def _size(value, option_name: str) -> tuple:
    """One size as ``(length, width)`` or ``(length, width, count)`` (floats, an int count)."""
    try:
        numbers = list(value)
        if len(numbers) not in (2, 3) or isinstance(value, (str, bytes, dict)):
            raise ValueError
    except (TypeError, ValueError):
        raise InputError(f"{option_name} must be (length, width) in mm, or (length, width, sheets on hand), or a "
                         f"list of them, got {value!r}") from None
    length = check_number(numbers[0], f"{option_name} length (mm)", low=0, low_open=True, high=LARGEST_SHEET)
    width = check_number(numbers[1], f"{option_name} width (mm)", low=0, low_open=True, high=LARGEST_SHEET)
    if len(numbers) == 2:
        return (float(length), float(width))
    count = check_number(numbers[2], f"{option_name} sheets on hand", low=1, high=10**6, integer=True)
    return (float(length), float(width), int(count))


def check_sheet(value, option_name: str):
    """``value`` (one size, or a list of sizes) checked: one size without a count as ``(length, width)``, else a
    tuple of sizes, each ``(length, width)`` or ``(length, width, count)``; None stays None."""
    if value is None:
        return None
    try:
        first = next(iter(value))
    except (TypeError, StopIteration):
        first = None
    if isinstance(value, (str, bytes, dict)) or first is None or not isinstance(first, (list, tuple)):
        return _size(value, option_name)  # one size (or a value that is none: named there)
    sizes = tuple(_size(item, f"{option_name}[{k}]") for k, item in enumerate(value))
    if len(sizes) == 1 and len(sizes[0]) == 2:
        return sizes[0]
    if len({s[:2] for s in sizes}) != len(sizes):
        raise InputError(f"{option_name} names a size twice: give each size once (with its count on hand)")
    return sizes


def sheet_sizes(value) -> tuple:
    """The sizes of a checked ``sheet`` value as :class:`SheetSize` records, in the order given; () for None."""
    if value is None:
        return ()
    items = (value,) if not isinstance(value[0], tuple) else value
    return tuple(SheetSize(*item) for item in items)


def parse_sheet(text: str):
    """``"2500x1250"`` (command line) as ``(2500.0, 1250.0)``; ``"2500x1250,1200x800:2"`` as
    ``((2500.0, 1250.0), (1200.0, 800.0, 2))``."""
    sizes = []
    for item in text.split(","):
        size, sep, count = item.strip().partition(":")
        parts = size.lower().replace("*", "x").split("x")
        try:
            if len(parts) != 2:
                raise ValueError
            numbers = [float(p) for p in parts] + ([int(count)] if sep else [])
        except ValueError:
            raise ValueError(f"expected LENGTHxWIDTH in mm (several: 2500x1250,1200x800:2 for two of the second "
                             f"on hand), got {text!r}") from None
        sizes.append(tuple(numbers))
    return sizes[0] if len(sizes) == 1 else tuple(sizes)
