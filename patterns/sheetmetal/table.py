"""The options of an unfold, and bend-deduction tables (a shop's own bend data).

:class:`UnfoldOptions` is the one declaration of every unfold option for the
API, the command line and batches; :func:`read_bend_table` reads a CSV of
bend deductions that then gives every cylindrical bend's developed width
instead of the K-factor.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..options import Options, option

__all__ = ["BendTable", "UnfoldOptions", "read_bend_table"]


@dataclass(frozen=True, eq=False)
class BendTable:
    """A bend-deduction table (CSV: ``thickness, radius, angle, deduction``; mm and degrees).

    The deduction ``BD`` of a bend is how much shorter the blank is than its two
    flanges measured to the virtual sharp (the crossing of the outside skins);
    the developed width of the bend zone is then ``2 (r + t) tan(a / 2) - BD``.
    Rows of the same thickness and inside radius are interpolated linearly in
    the angle; a bend outside every row is refused (never extrapolated).

    Attributes
    ----------
    path : str
    rows : (n, 4) float64
        thickness mm, inside radius mm, angle degrees, deduction mm.
    """

    path: str
    rows: np.ndarray

    def allowance(self, thickness: float, radius: float, angle: float) -> float:
        """Developed width of a bend, mm (``angle`` in degrees); InputError when no row covers it."""
        near = self.rows[(np.abs(self.rows[:, 0] - thickness) <= 0.01) & (np.abs(self.rows[:, 1] - radius) <= 0.01)]
        if len(near) == 0 or not near[:, 2].min() - 0.01 <= angle <= near[:, 2].max() + 0.01:
            raise InputError(f"{self.path}: no row for thickness {thickness:g} mm, inside radius {radius:g} mm, "
                             f"angle {angle:.2f} degrees (the table is never extrapolated)")
        order = np.argsort(near[:, 2])
        deduction = float(np.interp(angle, near[order, 2], near[order, 3]))
        return 2 * (radius + thickness) * np.tan(np.radians(angle) / 2) - deduction


def read_bend_table(path) -> BendTable:
    """Read a bend-deduction table (CSV with a header naming ``thickness, radius, angle, deduction``).

    Raises
    ------
    InputError
        Missing file, missing column, or a value that is not a number, naming the file and line.
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: no such bend table")
    try:
        with open(path, newline="", encoding="utf-8") as fh:
            reader = csv.DictReader(fh)
            need = ("thickness", "radius", "angle", "deduction")
            header = [h.strip().lower() for h in (reader.fieldnames or [])]
            missing = [n for n in need if n not in header]
            if missing:
                raise InputError(f"{path}: a bend table needs the columns {', '.join(need)}; "
                                 f"missing {', '.join(missing)}")
            rows = []
            for line, row in enumerate(reader, start=2):
                row = {k.strip().lower(): v for k, v in row.items() if k is not None}
                try:
                    rows.append([float(row[n]) for n in need])
                except (TypeError, ValueError):
                    raise InputError(f"{path}, line {line}: every value must be a number") from None
    except UnicodeDecodeError:
        raise InputError(f"{path}: not a text (CSV) file") from None
    rows = np.array(rows, dtype=np.float64).reshape(-1, 4)
    if len(rows) == 0 or not np.isfinite(rows).all() or (rows[:, :3] <= 0).any():
        raise InputError(f"{path}: the table is empty or holds a non-positive thickness, radius or angle")
    return BendTable(str(path), rows)


def _table(value, option):
    if isinstance(value, BendTable):
        return value
    if isinstance(value, (str, Path)):
        return read_bend_table(value)
    raise InputError(f"{option} must be a CSV file's path or a BendTable, got {type(value).__name__}")


@dataclass(frozen=True, repr=False)
class UnfoldOptions(Options):
    """How a bent sheet-metal part is unfolded (:func:`unfold`, ``patterns unfold``)."""

    k_factor: float = option(0.5, "position of the neutral layer in the bends from the inside, as a fraction of "
                                  "the thickness (SolidWorks' and FreeCAD's K-factor)", low=0, high=1)
    bend_table: BendTable | None = option(None, "bend-deduction table, CSV with columns thickness, radius, angle, "
                                      "deduction (mm, degrees); it gives every bend instead of the K-factor",
                                optional=True, check=_table, metavar="CSV")
    fixed_face: int | None = option(None, "the CAD face that keeps its place (shape.faces() index; default the "
                                          "largest planar face)", integer=True, low=0, optional=True,
                                    metavar="N")
