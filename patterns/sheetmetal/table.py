"""The options of an unfold, and bend-deduction tables (a shop's own bend data).

:class:`UnfoldOptions` is the one declaration of every unfold option for the
API, the command line and batches; :func:`read_bend_table` reads a CSV of
bend deductions that then gives every cylindrical bend's developed width
instead of the K-factor; ``material`` takes each bend's K-factor from a
material table (:mod:`~patterns.sheetmetal.materials`).
"""

from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..files import check_input_file, csv_table
from ..options import Options, label, option
from .corners import CORNER_RELIEFS, SIZED_RELIEFS
from .materials import MaterialTable, _path_or_table, bundled_materials, material_name

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


MAX_TABLE_BYTES = 1_000_000
"""A bend table larger than this is refused unread (a shop's table is a few hundred rows)."""
K_SLACK = 0.5
"""How far outside the sheet (in thicknesses) a row's neutral layer may lie: a deduction whose implied
K-factor is outside ``[-K_SLACK, 1 + K_SLACK]`` is refused as a typing error (real tables give 0.2-0.5)."""
ROUNDING = 0.05
"""mm a deduction may be off the K-factor range for its rounding (small angles give tiny deductions)."""


def read_bend_table(path) -> BendTable:
    """Read a bend-deduction table (CSV with a header naming ``thickness, radius, angle, deduction``).

    Every row is checked: a positive thickness and inside radius, an angle
    between 0 and 180 degrees, and a deduction whose implied neutral layer lies
    within half a thickness of the sheet (:data:`K_SLACK`), so that no
    deduction can exceed the flanges it joins or make a blank kilometres long.

    Raises
    ------
    InputError
        Missing file, a folder, pipe or device, a file over 1 MB, a missing
        column, a value that is not a number, or a row out of range, naming the
        file and line.
    """
    path = check_input_file(path, what="bend table (CSV)")
    if path.stat().st_size > MAX_TABLE_BYTES:
        raise InputError(f"{path}: {path.stat().st_size} bytes; a bend table is at most "
                         f"{MAX_TABLE_BYTES // 1_000_000} MB (a few hundred rows)")
    need = ("thickness", "radius", "angle", "deduction")
    rows = []
    try:
        with open(path, newline="", encoding="utf-8") as fh:
            reader = csv_table(fh, need, where=str(path), what="a bend table")
            for line, row in enumerate(reader, start=2):
                row = {k.strip().lower(): v for k, v in row.items() if k is not None}
                try:
                    rows.append([float(row[n]) for n in need])
                except (TypeError, ValueError):
                    raise InputError(f"{path}, line {line}: every value must be a number") from None
                _check_row(path, line, *rows[-1])
    except UnicodeDecodeError:
        raise InputError(f"{path}: not a text (CSV) file") from None
    except csv.Error as exc:
        raise InputError(f"{path}, line {reader.line_num + 1}: not a CSV bend table ({exc})") from None
    if not rows:
        raise InputError(f"{path}: the bend table has no rows")
    return BendTable(str(path), np.array(rows, dtype=np.float64).reshape(-1, 4))


def deduction_range(thickness: float, radius: float, angle: float, *, slack: float = K_SLACK) -> tuple:
    """The bend deductions, mm, whose neutral layer lies at K-factor ``-slack`` to ``1 + slack`` (``angle`` in degrees).

    Returns ``(low, high)``: ``2 (r + t) tan(a / 2) - a (r + K t)`` at ``K = 1 + slack`` and ``K = -slack``.
    """
    a = np.radians(angle)
    sharp = 2 * (radius + thickness) * np.tan(a / 2)
    return sharp - a * (radius + (1 + slack) * thickness), sharp - a * max(radius - slack * thickness, 0.0)


def _check_row(path, line, thickness, radius, angle, deduction) -> None:
    where = f"{path}, line {line}"
    if not all(np.isfinite([thickness, radius, angle, deduction])):
        raise InputError(f"{where}: every value must be a finite number")
    if thickness <= 0 or radius <= 0:
        raise InputError(f"{where}: the thickness and inside radius must be positive mm")
    if not 0 < angle < 180:
        raise InputError(f"{where}: the bend angle must be between 0 and 180 degrees, got {angle:g}")
    low, high = deduction_range(thickness, radius, angle)
    if not low - ROUNDING <= deduction <= high + ROUNDING:
        raise InputError(f"{where}: deduction {deduction:g} mm is not a bend of {thickness:g} mm sheet, "
                         f"R {radius:g}, {angle:g} degrees: it would put the neutral layer outside the sheet "
                         f"(K-factor 0 to 1 gives {deduction_range(thickness, radius, angle, slack=0)[0]:.3f} to "
                         f"{deduction_range(thickness, radius, angle, slack=0)[1]:.3f} mm)")


def _material(value, option) -> str:
    if not isinstance(value, str) or not value.strip():
        raise InputError(f"{option} must be a material's name, got {value!r}")
    return material_name(value)


K_DEFAULT = 0.5
"""The K-factor when none is given (the neutral layer in the middle of the sheet)."""


def parse_face(text: str) -> int:
    """A face's index from the command line or a CAD program: ``21`` (0-based, as ``shape.faces()``) or
    FreeCAD's 1-based name ``Face21`` (index 20)."""
    text = text.strip()
    if text[:4].lower() == "face" and text[4:].isdigit() and int(text[4:]) >= 1:
        return int(text[4:]) - 1
    try:
        return int(text)
    except ValueError:
        raise ValueError(f"expected a face index (0, 1, ...) or FreeCAD's face name (Face1, Face2, ...), "
                         f"got {text!r}") from None


def _table(value, option):
    if isinstance(value, BendTable):
        return value
    if isinstance(value, (str, Path)):
        return read_bend_table(value)
    raise InputError(f"{option} must be a CSV file's path or a BendTable, got {type(value).__name__}")


def _both(other: str) -> InputError:
    """The refusal of ``material`` with ``other`` (``k_factor`` or ``bend_table``), named as the caller typed them."""
    return InputError(f"{label('material')} gives every bend its K-factor, {label(other)} gives them too: "
                      f"give one of {label('material')}, {label('k_factor')} and {label('bend_table')}")


@dataclass(frozen=True, repr=False)
class UnfoldOptions(Options):
    """How a bent sheet-metal part is unfolded (:func:`unfold`, ``patterns unfold``)."""

    k_factor: float = option(K_DEFAULT, "position of the neutral layer in the bends from the inside, as a fraction of "
                                  "the thickness (SolidWorks' and FreeCAD's K-factor)", low=0, high=1)
    bend_table: BendTable | None = option(None, "bend-deduction table, CSV with columns thickness, radius, angle, "
                                      "deduction (mm, degrees); it gives every bend instead of the K-factor",
                                optional=True, check=_table, metavar="CSV",
                                text=lambda table: table.path)
    fixed_face: int | None = option(None, "the CAD face that keeps its place (shape.faces() index, or FreeCAD's "
                                          "name FaceN for index N-1; default the largest planar face that starts a "
                                          "sheet)", integer=True, low=0, optional=True, metavar="N",
                                    parse=parse_face)
    corner_relief: str = option("none", "where two bends meet at a corner: none (the flanges' edges run on until "
                                        "they meet, as SolidWorks draws a closed corner), rectangular (the square "
                                        "where the bend zones cross cut out), round (a circle about the bend lines' "
                                        "crossing, clear of both zones), tear (a rip to the inside corner) or "
                                        "as-modelled (the model's corner faces developed as they are)",
                                choices=CORNER_RELIEFS)
    material: str | None = option(None, "the sheet's material: each bend's K-factor from the material table, by "
                                        "the thickness and the bend's inside radius over it (r/t); the bundled table "
                                        "has " + ", ".join(bundled_materials().names) + " (see docs/sheet-metal.md)",
                                  optional=True, check=_material, metavar="NAME")
    material_table: MaterialTable | None = option(None, "your own material table for material, CSV with columns "  # noqa: RUF009
                                                        "material, thickness_min, thickness_max, rt_min, rt_max, "
                                                        "k_factor (default: the bundled table)",
                                                  optional=True, check=_path_or_table, metavar="CSV",
                                                  text=lambda table: table.path)
    corner_relief_size: float | None = option(None, "the corner relief's size, mm: the square's side (rectangular) "
                                                    "or the circle's diameter (round), centred on the bend lines' "
                                                    "crossing, as SolidWorks' corner relief centred on bend lines "
                                                    "(default: just clear both bend zones)",
                                              optional=True, low=0, low_open=True, unit="mm")
    corner_relief_ratio: float | None = option(None, "the corner relief's size as a multiple of the thickness "
                                                     "(SolidWorks' ratio to thickness), instead of "
                                                     "corner_relief_size", optional=True, low=0, low_open=True,
                                               high=100, metavar="RATIO")

    def __post_init__(self):
        super().__post_init__()
        sized = [n for n in ("corner_relief_size", "corner_relief_ratio") if getattr(self, n) is not None]
        if len(sized) == 2:
            raise InputError(f"{label('corner_relief_size')} and {label('corner_relief_ratio')} both size the corner "
                             f"relief: give one")
        if sized and self.corner_relief not in SIZED_RELIEFS:
            raise InputError(f"{label(sized[0])} sizes a rectangular or round corner relief; "
                             f"{label('corner_relief')} is {self.corner_relief!r}, which has no size")
        if self.material is None:
            if self.material_table is not None:
                raise InputError(f"{label('material_table')} gives K-factors by material: name the material "
                                 f"({label('material')} NAME)")
            return
        given = [n for n, on in (("bend_table", self.bend_table is not None),
                                 ("k_factor", self.k_factor != K_DEFAULT)) if on]
        if given:
            raise _both(given[0])
        table = self.material_table or bundled_materials()
        if self.material not in table.names:
            raise InputError(f"unknown {label('material')} {self.material!r}; {table.where} has "
                             f"{', '.join(table.names)}")

    @classmethod
    def of(cls, options=None, keywords=None, *, name: str | None = None):
        """As :meth:`Options.of`; ``k_factor`` given with ``material`` is refused even at its default value
        (``--material X --k-factor 0.5``): the keywords say what was given, the record alone cannot."""
        made = super().of(options, keywords, name=name)
        if made.material is not None and "k_factor" in (keywords or {}):
            exc = _both("k_factor")
            raise InputError(f"{name}: {exc}" if name else str(exc))
        return made

    def relief_size(self, thickness: float) -> float | None:
        """The corner relief's size, mm (``corner_relief_size``, or ``corner_relief_ratio`` times the
        ``thickness``, mm), or None: just clear both bend zones."""
        if self.corner_relief_ratio is not None:
            return self.corner_relief_ratio * thickness
        return self.corner_relief_size

    def k_factor_at(self, thickness: float, inside_radius: float, *, what: str = "a bend") -> float:
        """A bend's K-factor: the material table's for its thickness and inside radius (mm) when ``material``
        is given (InputError when no row covers it, naming ``what``), else ``k_factor``."""
        if self.material is None:
            return self.k_factor
        return (self.material_table or bundled_materials()).k_factor(self.material, thickness, inside_radius,
                                                                      what=what)
