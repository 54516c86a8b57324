"""Material tables: the K-factor of a bend by material, sheet thickness and inside radius.

A material table is a CSV with the columns ``material, thickness_min,
thickness_max, rt_min, rt_max, k_factor``: each row gives the K-factor of the
bends of one material whose sheet thickness lies in ``[thickness_min,
thickness_max]`` mm and whose inside radius over that thickness (``r/t``) lies
in ``[rt_min, rt_max]``, as the published K-factor tables give it (one value a
class of ``r/t``).  Where two rows meet (``r/t`` exactly 1 between a class
``0-1`` and a class ``1-3``) the row that starts there gives it.  A bend no row
covers is refused, naming its thickness and ``r/t`` and what the table covers:
the table is never extrapolated.

:data:`BUNDLED` is the table ``patterns`` ships (:func:`bundled_materials`):
Machinery's Handbook's K-factors for air bending, by ``r/t`` class, for soft
(aluminium 5052), medium (mild steel, aluminium 6061) and hard (stainless)
materials; docs/sheet-metal.md ("Materials") gives the source and how to
write your own.
"""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..files import check_input_file, csv_table

__all__ = ["BUNDLED", "COLUMNS", "MaterialTable", "bundled_materials", "material_name", "read_material_table"]

COLUMNS = ("material", "thickness_min", "thickness_max", "rt_min", "rt_max", "k_factor")
"""A material table's columns (mm, the ratio r/t, the K-factor)."""

_CLASSES = {  # Machinery's Handbook, air bending: K for r/t in [0, 1], [1, 3], [3, 100]
    "aluminium-5052": (0.33, 0.40, 0.50),   # soft materials
    "aluminium-6061": (0.38, 0.43, 0.50),   # medium materials
    "mild-steel": (0.38, 0.43, 0.50),       # medium materials
    "stainless": (0.40, 0.45, 0.50),        # hard materials
}
BUNDLED = "material,thickness_min,thickness_max,rt_min,rt_max,k_factor\n" + "".join(
    f"{name},0.4,6.35,{lo:g},{hi:g},{k:.2f}\n" for name, ks in _CLASSES.items()
    for (lo, hi), k in zip(((0, 1), (1, 3), (3, 100)), ks))
"""The bundled table as CSV text: sheet 0.4-6.35 mm (a press brake's range, to 1/4 in), r/t 0 to 100."""

MAX_TABLE_BYTES = 1_000_000
"""A material table larger than this is refused unread."""
EPS = 1e-6
"""Slack of every range (mm, and r/t): a 3 mm radius in 3 mm sheet is r/t 1 however it was rounded."""


@dataclass(frozen=True, eq=False)
class MaterialTable:
    """K-factors by material, thickness and ``r/t`` (see the module).

    Attributes
    ----------
    path : str or None
        The CSV it was read from (None: the bundled table).
    names : tuple of str
        The materials, in the order the table first names them.
    rows : (n, 5) float64
        ``thickness_min, thickness_max, rt_min, rt_max, k_factor`` of each row.
    materials : tuple of str
        Each row's material.
    """

    path: str | None
    names: tuple
    rows: np.ndarray
    materials: tuple

    @property
    def where(self) -> str:
        """What messages call the table."""
        return self.path or "the bundled material table"

    def k_factor(self, material: str, thickness: float, inside_radius: float, *, what: str = "a bend") -> float:
        """The K-factor of a bend of ``inside_radius`` mm in ``thickness`` mm sheet of ``material``.

        Raises
        ------
        InputError
            An unknown material (the message lists the known ones), or no row covering the thickness and
            ``r/t`` (the message says what the rows cover); ``what`` names the bend.
        """
        material = material_name(material)
        if material not in self.names:
            raise InputError(f"unknown material {material!r}; {self.where} has {', '.join(self.names)}")
        mine = self.rows[[m == material for m in self.materials]]
        rt = inside_radius / thickness
        fits = mine[(mine[:, 0] - EPS <= thickness) & (thickness <= mine[:, 1] + EPS)
                    & (mine[:, 2] - EPS <= rt) & (rt <= mine[:, 3] + EPS)]
        if len(fits) == 0:
            covered = "; ".join(f"{a:g}-{b:g} mm at r/t {c:g}-{d:g}" for a, b, c, d, _ in mine)
            raise InputError(f"{what}: {thickness:g} mm {material}, inside radius {inside_radius:g} mm (r/t "
                             f"{rt:.3g}): no row of {self.where} covers it (it covers {covered}; a table is never "
                             f"extrapolated)")
        return float(fits[np.argmax(fits[:, 2]), 4])  # where two rows meet, the one that starts there


@lru_cache(maxsize=1)
def bundled_materials() -> MaterialTable:
    """The bundled material table (:data:`BUNDLED`)."""
    return _parse(io.StringIO(BUNDLED), None)


def read_material_table(path) -> MaterialTable:
    """Read a material table (CSV with a header naming :data:`COLUMNS`; other columns, a source, are kept out).

    Raises
    ------
    InputError
        Missing or unreadable file, one over 1 MB, a missing column, a value that is not a number, a row out of
        range (thickness not positive, an empty range, a K-factor outside 0-1), or two rows of one material
        that overlap (which would give one bend two K-factors), naming the file and line.
    """
    path = check_input_file(path, what="material table (CSV)")
    if path.stat().st_size > MAX_TABLE_BYTES:
        raise InputError(f"{path}: {path.stat().st_size} bytes; a material table is at most 1 MB")
    try:
        with open(path, newline="", encoding="utf-8") as fh:
            return _parse(fh, str(path))
    except UnicodeDecodeError:
        raise InputError(f"{path}: not a text (CSV) file") from None


def material_name(text: str) -> str:
    """A material's name as the tables, the option and the lookup all spell it: stripped, lower case."""
    return text.strip().lower()


def _parse(fh, path: str | None) -> MaterialTable:
    where = path or "the bundled material table"
    reader = csv_table(fh, COLUMNS, where=where, what="a material table")
    rows, materials = [], []
    try:
        for line, row in enumerate(reader, start=2):
            row = {k.strip().lower(): (v or "").strip() for k, v in row.items() if k is not None}
            name = material_name(row["material"])
            try:
                values = [float(row[c]) for c in COLUMNS[1:]]
            except ValueError:
                raise InputError(f"{where}, line {line}: every value but the material must be a number") from None
            _check_row(where, line, name, *values)
            rows.append(values)
            materials.append(name)
    except csv.Error as exc:
        raise InputError(f"{where}, line {reader.line_num}: not a CSV material table ({exc})") from None
    if not rows:
        raise InputError(f"{where}: the material table has no rows")
    table = np.array(rows, dtype=np.float64).reshape(-1, 5)
    _check_overlaps(where, table, materials)
    return MaterialTable(path, tuple(dict.fromkeys(materials)), table, tuple(materials))


def _check_row(where, line, name, t0, t1, rt0, rt1, k) -> None:
    at = f"{where}, line {line}"
    if not name:
        raise InputError(f"{at}: the material has no name")
    if not all(np.isfinite([t0, t1, rt0, rt1, k])):
        raise InputError(f"{at}: every value must be a finite number")
    if not 0 < t0 <= t1:
        raise InputError(f"{at}: thickness_min must be positive and at most thickness_max (mm)")
    if not 0 <= rt0 < rt1:
        raise InputError(f"{at}: rt_min must be at least 0 and below rt_max (the inside radius over the thickness)")
    if not 0 <= k <= 1:
        raise InputError(f"{at}: k_factor {k:g} is not a K-factor (0 to 1: the neutral layer inside the sheet)")


def _check_overlaps(where, table, materials) -> None:
    """InputError naming two rows of one material whose thickness and r/t ranges overlap (by more than EPS in
    both): a bend they both cover would have two K-factors.  Each row's range is a box, shrunk by EPS / 2, in
    an STRtree, queried a block of rows at a time: tables of tens of thousands of rows in well under a second
    (the pair-by-pair loop took 51 s for 10,000 rows); the pair named is the first by row."""
    import shapely

    names = np.array(materials, dtype=object)
    half = EPS / 2
    boxes = shapely.box(table[:, 0] + half, table[:, 2] + half, table[:, 1] - half, table[:, 3] - half)
    tree = shapely.STRtree(boxes)
    for start in range(0, len(table), 256):
        rows = np.arange(start, min(start + 256, len(table)))
        i, j = tree.query(boxes[rows], predicate="intersects")
        i = rows[i]
        keep = (j < i) & (names[i] == names[j])
        i, j = i[keep], j[keep]
        a, b = table[i], table[j]
        over = (np.minimum(a[:, 1], b[:, 1]) - np.maximum(a[:, 0], b[:, 0]) > EPS) & \
            (np.minimum(a[:, 3], b[:, 3]) - np.maximum(a[:, 2], b[:, 2]) > EPS)
        if over.any():
            k = np.lexsort((j[over], i[over]))[0]
            i, j = int(i[over][k]), int(j[over][k])
            a, b = table[i], table[j]
            raise InputError(f"{where}: rows {j + 2} and {i + 2} both give {materials[i]} at "
                             f"{max(a[0], b[0]):g}-{min(a[1], b[1]):g} mm, r/t {max(a[2], b[2]):g}-"
                             f"{min(a[3], b[3]):g}: one bend, two K-factors")


def _path_or_table(value, option) -> MaterialTable:
    if isinstance(value, MaterialTable):
        return value
    if isinstance(value, (str, Path)):
        return read_material_table(value)
    raise InputError(f"{option} must be a CSV file's path or a MaterialTable, got {type(value).__name__}")
