"""Lengths units: the one table of what a unit is in millimetres and how DXF names it.

`patterns` works in millimetres throughout.  A mesh file in another unit is
converted on loading (``load(units=...)``), a DXF in another unit is written by
scaling on export (``to_dxf(units=...)``); both read this table.
"""

from __future__ import annotations

from enum import Enum

__all__ = ["LARGEST_LENGTH", "UNIT_NAMES", "Unit"]


class Unit(str, Enum):
    """A length unit (its value is the name used by the API and the CLI)."""

    MM = "mm"
    CM = "cm"
    M = "m"
    IN = "in"

    @property
    def mm(self) -> float:
        """How many millimetres one of this unit is (25.4 for an inch)."""
        return {"mm": 1.0, "cm": 10.0, "m": 1000.0, "in": 25.4}[self.value]

    @property
    def insunits(self) -> int:
        """The DXF ``$INSUNITS`` code (AutoCAD's: 4 mm, 5 cm, 6 m, 1 inch)."""
        return {"mm": 4, "cm": 5, "m": 6, "in": 1}[self.value]

    @property
    def measurement(self) -> int:
        """The DXF ``$MEASUREMENT`` code: 0 imperial (inch), 1 metric."""
        return 0 if self is Unit.IN else 1

    @property
    def label(self) -> str:
        """How drawings write it (``"MM"``, ``"IN"``)."""
        return self.value.upper()


UNIT_NAMES = tuple(u.value for u in Unit)
"""``("mm", "cm", "m", "in")``."""


LARGEST_LENGTH = 1e7
"""The largest length `patterns` takes, mm (10 km): every coordinate of a part and every length
option.  Beyond it a part is in the wrong unit, or its numbers are garbage; bounding them keeps
every area and squared distance far from overflow."""
