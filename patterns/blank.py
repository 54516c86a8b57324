"""The flat blank of a bent sheet-metal part: one outline, its holes, its bend lines.

:func:`patterns.unfold` returns a :class:`Blank`.  Its outline and holes are
loops of exact pieces (:class:`Line`, :class:`Arc`, :class:`Polyline`) so that a
drilled hole stays a circle in the DXF; :meth:`Loop.points` samples them for
areas and drawings.  Millimetres throughout.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum
from functools import cached_property

import numpy as np
import shapely

__all__ = ["Arc", "Bend", "Blank", "BlankCode", "BlankFinding", "Line", "Loop", "Polyline"]


@dataclass(frozen=True, eq=False)
class Line:
    """A straight piece from ``start`` to ``end``: (2,) float64, mm."""

    start: np.ndarray
    end: np.ndarray

    def points(self, tolerance: float) -> np.ndarray:
        """(2, 2) float64: its two ends."""
        return np.array([self.start, self.end])


@dataclass(frozen=True, eq=False)
class Arc:
    """A circular arc about ``center`` ((2,) float64, mm) of ``radius`` mm, from angle
    ``start`` through ``sweep`` (radians; positive counter-clockwise; 2 pi for a circle)."""

    center: np.ndarray
    radius: float
    start: float
    sweep: float

    @property
    def is_circle(self) -> bool:
        return abs(abs(self.sweep) - 2 * np.pi) < 1e-9

    def points(self, tolerance: float) -> np.ndarray:
        """(k, 2) float64: the arc sampled so that no chord is farther than ``tolerance`` mm from it."""
        step = 2 * np.arccos(max(1 - tolerance / self.radius, -1.0)) if self.radius > tolerance else np.pi / 2
        n = max(2, int(np.ceil(abs(self.sweep) / max(step, 1e-6))) + 1)
        a = self.start + np.linspace(0.0, self.sweep, n)
        return self.center + self.radius * np.column_stack([np.cos(a), np.sin(a)])


@dataclass(frozen=True, eq=False)
class Polyline:
    """A piece with no simpler exact form, sampled finely: (k, 2) float64, mm."""

    vertices: np.ndarray

    def points(self, tolerance: float) -> np.ndarray:
        return self.vertices


@dataclass(frozen=True, eq=False)
class Loop:
    """A closed contour: its pieces in order, each starting where the one before ends."""

    pieces: tuple

    def points(self, tolerance: float = 0.001) -> np.ndarray:
        """(k, 2) float64, mm: the contour sampled (chord error at most ``tolerance`` mm), not closed."""
        parts = [p.points(tolerance)[:-1] for p in self.pieces]
        return np.concatenate(parts) if parts else np.zeros((0, 2))

    @cached_property
    def polygon(self) -> shapely.Polygon:
        return shapely.Polygon(self.points())

    @property
    def area(self) -> float:
        """Enclosed area, mm² (positive)."""
        return float(self.polygon.area)

    @property
    def length(self) -> float:
        """Length of the contour, mm (arcs exactly)."""
        total = 0.0
        for p in self.pieces:
            if isinstance(p, Arc):
                total += p.radius * abs(p.sweep)
            else:
                pts = p.points(0.001)
                total += float(np.linalg.norm(np.diff(pts, axis=0), axis=1).sum())
        return total

    @property
    def is_circle(self) -> bool:
        return len(self.pieces) == 1 and isinstance(self.pieces[0], Arc) and self.pieces[0].is_circle


@dataclass(frozen=True, eq=False)
class Bend:
    """One bend of the part, as drawn on the blank.

    Attributes
    ----------
    line : (2, 2) float64, mm
        The bend centre line on the blank (the middle of the bend zone), end to end.
    angle : float
        The bend angle, degrees: how far the sheet turns in this bend (90 for a right-angle flange).
    inside_radius : float
        Inside bend radius, mm, read from the model.
    direction : str
        ``"up"`` or ``"down"``: the way the flange turns, seen from the side of the blank that faces
        the viewer (the fixed face's outside).
    allowance : float
        The developed width of the bend zone, mm: the neutral arc ``angle (inside_radius + k t)``, or
        from the bend table.
    faces : tuple of int
        The CAD faces of the bend (cylinders of the developed skin), ``shape.faces()`` indices.
    """

    line: np.ndarray
    angle: float
    inside_radius: float
    direction: str
    allowance: float
    faces: tuple

    @property
    def label(self) -> str:
        """What the drawing says at the line: ``UP 90.0° R2.4``."""
        return f"{self.direction.upper()} {self.angle:.1f}° R{self.inside_radius:g}"


class BlankCode(str, Enum):
    """What a :class:`BlankFinding` is about (also its JSON ``code``)."""

    FLANGES_OVERLAP = "flanges-overlap"
    BEND_WITHOUT_FLANGE = "bend-without-flange"
    MESHED_FACE = "meshed-face"


@dataclass(frozen=True, eq=False)
class BlankFinding:
    """A fault of a blank a shop must know about.

    Attributes
    ----------
    code : BlankCode
    error : bool
        True: the blank cannot be cut as it is (it is not written as DXF); False: a warning.
    message : str
        One line, starting with the part's name.
    point : (2,) float64, mm
        Where on the blank.
    """

    code: BlankCode
    error: bool
    message: str
    point: np.ndarray

    def to_dict(self) -> dict:
        return {"code": self.code.value, "severity": "error" if self.error else "warning",
                "message": self.message, "point": [round(float(x), 4) for x in self.point]}


@dataclass(frozen=True, eq=False)
class Blank:
    """The flat blank of a sheet-metal part (:func:`patterns.unfold`).

    Attributes
    ----------
    name : str
    outline : Loop
        The outer contour, counter-clockwise.
    holes : tuple of Loop
        Every hole and cut-out, clockwise; drilled holes as one full-circle :class:`Arc`.
    bends : tuple of Bend
    thickness : float
        Sheet thickness read from the model, mm.
    k_factor : float
        The K-factor the bends were developed with (None when a bend table gave every bend).
    fixed_face : int
        The CAD face that keeps its place (``shape.faces()`` index).
    findings : tuple of BlankFinding
    """

    name: str
    outline: Loop
    holes: tuple
    bends: tuple
    thickness: float
    k_factor: float | None
    fixed_face: int
    findings: tuple

    @property
    def ok(self) -> bool:
        """No finding that stops the blank being cut."""
        return not any(f.error for f in self.findings)

    @cached_property
    def polygon(self) -> shapely.Polygon:
        """The blank as one shapely polygon (outline with holes), sampled within 0.001 mm."""
        return shapely.Polygon(self.outline.points(), [h.points() for h in self.holes])

    @property
    def area(self) -> float:
        """Material area: the outline less the holes, mm²."""
        return float(self.polygon.area)

    @property
    def perimeter(self) -> float:
        """Length of the outer contour, mm."""
        return self.outline.length

    @property
    def size(self) -> tuple:
        """``(width, height)`` of the blank's bounding box, mm (as it lies: no rotation)."""
        x0, y0, x1, y1 = self.polygon.bounds
        return (x1 - x0, y1 - y0)

    @property
    def usage(self) -> float:
        """Material usage: the blank's area over its bounding box's (0..1)."""
        w, h = self.size
        return self.area / (w * h) if w * h > 0 else 0.0

    def to_dict(self) -> dict:
        """The report: size, area, usage, bends and findings, JSON-ready."""
        w, h = self.size
        return {
            "name": self.name, "ok": self.ok, "thickness_mm": round(self.thickness, 4),
            "k_factor": self.k_factor, "fixed_face": self.fixed_face,
            "size_mm": [round(w, 3), round(h, 3)], "area_mm2": round(self.area, 3),
            "outer_perimeter_mm": round(self.perimeter, 3), "holes": len(self.holes),
            "usage": round(self.usage, 4),
            "bends": [{"angle_deg": round(b.angle, 3), "inside_radius_mm": round(b.inside_radius, 4),
                       "direction": b.direction, "allowance_mm": round(b.allowance, 4),
                       "line": np.round(b.line, 4).tolist(), "faces": list(b.faces)} for b in self.bends],
            "findings": [f.to_dict() for f in self.findings],
        }

    def to_json(self, path, *, extra: dict | None = None) -> None:
        """Write :meth:`to_dict` (and ``extra`` entries) as JSON, atomically."""
        import json

        from .files import atomic_output

        text = json.dumps({**self.to_dict(), **(extra or {})}, indent=2, allow_nan=False)
        with atomic_output(path, what="report") as tmp:
            tmp.write_text(text + "\n", encoding="utf-8")

    def to_dxf(self, path, **options) -> None:
        """Write the blank as a DXF for a laser or plasma cutter (see :func:`patterns.export.sheet.write_blank_dxf`)."""
        from .export.sheet import write_blank_dxf

        write_blank_dxf(self, path, **options)
