"""Exact flat contours: lines, true arcs and polylines, chained into closed loops (mm).

A cutter cuts what these describe: a blank's drilled hole is one full-circle
:class:`Arc` (a DXF CIRCLE, an SVG arc), a straight edge one :class:`Line`, a
mesh outline one :class:`Polyline`.  :meth:`Loop.points` samples a loop for
areas and predicates; :meth:`Loop.vertices` gives it as ``(x, y, bulge)``
rows, the form DXF polylines and SVG paths are written from.  Every value is
immutable; :meth:`Loop.moved` returns a loop moved by a rigid motion (or a
reflection), never changing the one it is called on.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import shapely

__all__ = ["Arc", "Line", "Loop", "Motion", "Polyline", "Segment"]


def _frozen(array) -> np.ndarray:
    out = np.array(array, dtype=np.float64)
    out.setflags(write=False)
    return out


@dataclass(frozen=True)
class Motion:
    """A rigid motion of the plane, optionally mirrored: ``p -> p @ matrix.T + shift`` (mm).

    ``Motion(angle, dx, dy)`` turns by ``angle`` radians about the origin, then
    moves by ``(dx, dy)``; ``mirrored`` first reflects across the Y axis
    (``x -> -x``).  Motions compose with ``@`` (``(a @ b)(p) == a(b(p))``).
    """

    angle: float = 0.0
    dx: float = 0.0
    dy: float = 0.0
    mirrored: bool = False

    @property
    def matrix(self) -> np.ndarray:
        """(2, 2) float64: the linear part (determinant -1 when mirrored)."""
        c, s = float(np.cos(self.angle)), float(np.sin(self.angle))
        return np.array([[-c, -s], [-s, c]]) if self.mirrored else np.array([[c, -s], [s, c]])

    @property
    def shift(self) -> np.ndarray:
        return np.array([self.dx, self.dy])

    def __call__(self, points) -> np.ndarray:
        """(k, 2) or (2,) points moved, float64, mm (a new array)."""
        return _linear(self.matrix, np.asarray(points, dtype=np.float64)) + self.shift

    def direction(self, vectors) -> np.ndarray:
        """Directions (k, 2) or (2,) turned (and mirrored), not moved."""
        return _linear(self.matrix, np.asarray(vectors, dtype=np.float64))

    def turn(self, degrees: float) -> float:
        """The angle (degrees) a direction at ``degrees`` points at once moved."""
        d = self.direction([np.cos(np.radians(degrees)), np.sin(np.radians(degrees))])
        return float(np.degrees(np.arctan2(d[1], d[0])))

    def __matmul__(self, other: Motion) -> Motion:
        a, b = self.matrix, other.matrix
        m = np.array([[a[0, 0] * b[0, 0] + a[0, 1] * b[1, 0], a[0, 0] * b[0, 1] + a[0, 1] * b[1, 1]],
                      [a[1, 0] * b[0, 0] + a[1, 1] * b[1, 0], a[1, 0] * b[0, 1] + a[1, 1] * b[1, 1]]])
        shift = self(other.shift)
        mirrored = self.mirrored != other.mirrored
        lin = m * np.array([-1.0, 1.0]) if mirrored else m  # m @ diag(-1, 1): the first column's sign
        return Motion(float(np.arctan2(lin[1, 0], lin[0, 0])), float(shift[0]), float(shift[1]), mirrored)

    @property
    def is_identity(self) -> bool:
        return self.angle == 0.0 and self.dx == 0.0 and self.dy == 0.0 and not self.mirrored


def _linear(m: np.ndarray, p: np.ndarray) -> np.ndarray:
    """``p @ m.T`` for ``p`` (k, 2) or (2,), written out: a BLAS product rounds by the CPU's kernels (fused
    multiply-adds on one, not on another), and every coordinate of a written file passes through here."""
    x, y = p[..., 0], p[..., 1]
    return np.stack([m[0, 0] * x + m[0, 1] * y, m[1, 0] * x + m[1, 1] * y], axis=-1)


@dataclass(frozen=True, eq=False)
class Line:
    """A straight piece from ``start`` to ``end``: (2,) float64, mm."""

    start: np.ndarray
    end: np.ndarray

    def __post_init__(self):
        object.__setattr__(self, "start", _frozen(self.start))
        object.__setattr__(self, "end", _frozen(self.end))

    def points(self, tolerance: float = 0.001) -> np.ndarray:
        """(2, 2) float64: its two ends."""
        return np.array([self.start, self.end])

    @property
    def length(self) -> float:
        return math.hypot(*(self.end - self.start))

    def moved(self, motion: Motion) -> Line:
        return Line(motion(self.start), motion(self.end))

    def reversed(self) -> Line:
        return Line(self.end, self.start)


@dataclass(frozen=True, eq=False)
class Arc:
    """A circular arc about ``center`` ((2,) float64, mm) of ``radius`` mm, from angle
    ``start`` through ``sweep`` (radians; positive counter-clockwise; 2 pi for a circle)."""

    center: np.ndarray
    radius: float
    start: float
    sweep: float

    def __post_init__(self):
        object.__setattr__(self, "center", _frozen(self.center))

    @property
    def is_circle(self) -> bool:
        return abs(abs(self.sweep) - 2 * np.pi) < 1e-9

    @property
    def length(self) -> float:
        return float(self.radius * abs(self.sweep))

    @property
    def start_point(self) -> np.ndarray:
        return self.center + self.radius * np.array([np.cos(self.start), np.sin(self.start)])

    @property
    def end_point(self) -> np.ndarray:
        a = self.start + self.sweep
        return self.center + self.radius * np.array([np.cos(a), np.sin(a)])

    def points(self, tolerance: float = 0.001) -> np.ndarray:
        """(k, 2) float64: the arc sampled so that no chord is farther than ``tolerance`` mm from it."""
        step = 2 * np.arccos(max(1 - tolerance / self.radius, -1.0)) if self.radius > tolerance else np.pi / 2
        n = max(2, int(np.ceil(abs(self.sweep) / max(step, 1e-6))) + 1)
        a = self.start + np.linspace(0.0, self.sweep, n)
        return self.center + self.radius * np.column_stack([np.cos(a), np.sin(a)])

    def moved(self, motion: Motion) -> Arc:
        first = motion.direction([np.cos(self.start), np.sin(self.start)])
        sweep = -self.sweep if motion.mirrored else self.sweep
        return Arc(motion(self.center), self.radius, float(np.arctan2(first[1], first[0])), sweep)

    def reversed(self) -> Arc:
        return Arc(self.center, self.radius, self.start + self.sweep, -self.sweep)

    @classmethod
    def from_bulge(cls, a, b, bulge: float) -> Arc:
        """The arc from point ``a`` to ``b`` whose bulge (DXF: ``tan(sweep / 4)``) is ``bulge`` (not 0)."""
        a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
        sweep = 4 * np.arctan(bulge)
        chord = b - a
        half = 0.5 * math.hypot(*chord)
        radius = half / abs(np.sin(sweep / 2))
        mid = 0.5 * (a + b)
        normal = np.array([-chord[1], chord[0]]) / (2 * half)
        # The centre lies to the left of a -> b for a counter-clockwise arc under a semicircle.
        centre = mid + normal * half / np.tan(sweep / 2)
        start = float(np.arctan2(*(a - centre)[::-1]))
        return cls(centre, float(radius), start, float(sweep))


@dataclass(frozen=True, eq=False)
class Polyline:
    """A piece with no simpler exact form: its points, (k, 2) float64, mm, both ends included."""

    vertices: np.ndarray

    def __post_init__(self):
        object.__setattr__(self, "vertices", _frozen(self.vertices))

    def points(self, tolerance: float = 0.001) -> np.ndarray:
        return self.vertices

    @property
    def length(self) -> float:
        return float(np.linalg.norm(np.diff(self.vertices, axis=0), axis=1).sum())

    def moved(self, motion: Motion) -> Polyline:
        return Polyline(motion(self.vertices))

    def reversed(self) -> Polyline:
        return Polyline(self.vertices[::-1])


Segment = Line | Arc | Polyline
"""One piece of a :class:`Loop`."""


@dataclass(frozen=True, eq=False)
class Loop:
    """A closed contour: its pieces in order, each starting where the one before ends."""

    pieces: tuple

    @classmethod
    def of_points(cls, points) -> Loop:
        """A loop through ``points`` ((k, 2) mm, not repeated at the end): one closed :class:`Polyline`."""
        pts = np.asarray(points, dtype=np.float64)
        return cls((Polyline(np.vstack([pts, pts[:1]])),))

    @classmethod
    def of_vertices(cls, rows) -> Loop:
        """A loop from ``(x, y, bulge)`` rows ((k, 3): each row's bulge bends the piece to the next row,
        the last to the first), as DXF polylines and :func:`patterns.pieces.arcs.fit_arcs` give them;
        runs of straight pieces become one :class:`Polyline`."""
        rows = np.asarray(rows, dtype=np.float64)
        pieces, run = [], [rows[0, :2]]
        for k in range(len(rows)):
            a, b, bulge = rows[k, :2], rows[(k + 1) % len(rows), :2], rows[k, 2]
            if bulge == 0.0:
                run.append(b)
                continue
            if len(run) > 1:
                pieces.append(Polyline(np.array(run)))
            pieces.append(Arc.from_bulge(a, b, bulge))
            run = [b]
        if len(run) > 1:
            pieces.append(Polyline(np.array(run)))
        return cls(tuple(pieces))

    def points(self, tolerance: float = 0.001) -> np.ndarray:
        """(k, 2) float64, mm: the contour sampled (chord error at most ``tolerance`` mm), not closed."""
        parts = [p.points(tolerance)[:-1] for p in self.pieces]
        return np.concatenate(parts) if parts else np.zeros((0, 2))

    def vertices(self) -> np.ndarray:
        """(k, 3) float64: ``(x, y, bulge)`` of every piece's start (a polyline: of each of its points),
        the bulge bending the way to the next row (DXF's LWPOLYLINE, an SVG path's arcs)."""
        rows = []
        for p in self.pieces:
            if isinstance(p, Arc):
                a = p.start_point
                rows.append((a[0], a[1], np.tan(p.sweep / 4)))
            else:
                rows.extend((x, y, 0.0) for x, y in p.points()[:-1])
        return np.array(rows, dtype=np.float64).reshape(-1, 3)

    @cached_property
    def polygon(self) -> shapely.Polygon:
        return shapely.Polygon(self.points())

    @property
    def signed_area(self) -> float:
        """Enclosed area, mm², exactly (arcs as arcs): positive when the loop runs counter-clockwise."""
        rows = self.vertices()
        x, y = rows[:, 0], rows[:, 1]
        polygon = 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))
        arcs = [p for p in self.pieces if isinstance(p, Arc)]
        return polygon + sum(0.5 * a.radius**2 * (a.sweep - np.sin(a.sweep)) for a in arcs)

    @property
    def area(self) -> float:
        """Enclosed area, mm² (positive), exactly: the polygon through the pieces' points and, for every
        arc, the circular segment between it and its chord."""
        return abs(self.signed_area)

    @property
    def length(self) -> float:
        """Length of the contour, mm (arcs exactly)."""
        return float(sum(p.length for p in self.pieces))

    @property
    def is_circle(self) -> bool:
        return len(self.pieces) == 1 and isinstance(self.pieces[0], Arc) and self.pieces[0].is_circle

    @property
    def counter_clockwise(self) -> bool:
        return self.signed_area > 0

    def moved(self, motion: Motion) -> Loop:
        """The loop moved by ``motion``; a mirrored motion also reverses it, so that it keeps its turning
        sense (an outline stays counter-clockwise, a hole clockwise)."""
        loop = Loop(tuple(p.moved(motion) for p in self.pieces))
        return loop.reversed() if motion.mirrored else loop

    def reversed(self) -> Loop:
        return Loop(tuple(p.reversed() for p in reversed(self.pieces)))
