"""The flat blank of a bent sheet-metal part: one outline, its holes, its bend lines.

:func:`patterns.unfold` returns a :class:`Blank`.  Its outline and holes are
loops of exact pieces (:class:`~patterns.curves.Line`,
:class:`~patterns.curves.Arc`, :class:`~patterns.curves.Polyline`) so that a
drilled hole stays a circle in the DXF; :meth:`~patterns.curves.Loop.points`
samples them for areas and drawings.  Millimetres throughout.  A blank is what
is cut: :func:`patterns.pieces.piece_of` turns it into a
:class:`~patterns.pieces.Piece`, which every writer, the nester and the
report take (``patterns.write(blank, "bracket.dxf")``).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np
import shapely

from .bendsheet import bend_rows, numbered
from .curves import Arc, Loop, Motion
from .findings import Finding, Severity
from .text import counted

__all__ = ["Bend", "Blank", "Rim"]


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
    k_factor : float or None
        The K-factor the bend was developed with; None when a bend table gave it.
    sequence : int
        Its place in the press brake's order, 1 for the first bend to make
        (:func:`patterns.bendsheet.sequence`): numbered once, when the blank is made (0 until then).
    flange : float
        The depth of its outer flange, mm (what the order sorts by), measured with the sequence.
    """

    line: np.ndarray
    angle: float
    inside_radius: float
    direction: str
    allowance: float
    faces: tuple
    k_factor: float | None = None
    sequence: int = 0
    flange: float = 0.0

    def __post_init__(self):
        line = np.array(self.line, dtype=np.float64).reshape(2, 2)
        line.setflags(write=False)
        object.__setattr__(self, "line", line)

    @property
    def label(self) -> str:
        """What the drawing says at the line: ``UP 90.0° R2.4``."""
        return f"{self.direction.upper()} {self.angle:.1f}° R{self.inside_radius:g}"

    def moved(self, motion: Motion) -> Bend:
        return replace(self, line=motion(self.line))


@dataclass(frozen=True, eq=False)
class Rim:
    """The rim of a countersunk or counterbored hole: a circle to mark, not to cut.

    The laser cuts the hole at its through diameter (one of the blank's holes); the countersink or
    counterbore is machined afterwards, from the side the rim is on.

    Attributes
    ----------
    circle : patterns.curves.Arc
        The rim on the blank, a full counter-clockwise circle (centre (2,) float64, mm; radius mm).
    through : float
        The through hole's diameter, mm (the hole cut at the same centre).
    kind : str
        ``"countersink"`` (a cone from the rim down to the hole) or ``"counterbore"`` (a cylinder of the
        rim's diameter down to a flat step).
    side : str
        ``"near"``: on the fixed face's side of the sheet (the side the blank is drawn from, as a bend's
        direction is seen); ``"far"``: on the other side.
    depth : float
        How deep the countersink or counterbore goes from the rim's side, mm.
    angle : float or None
        A countersink's included angle, degrees (90 for a 90° countersink); None for a counterbore.
    face : int
        The planar CAD face the hole is in (``shape.faces()`` index).
    """

    circle: Arc
    through: float
    kind: str
    side: str
    depth: float
    angle: float | None
    face: int

    @property
    def center(self) -> np.ndarray:
        """(2,) float64, mm."""
        return self.circle.center

    @property
    def diameter(self) -> float:
        """The rim's diameter, mm."""
        return 2 * self.circle.radius

    def moved(self, motion: Motion) -> Rim:
        circle = self.circle.moved(motion)
        return replace(self, circle=circle.reversed() if motion.mirrored else circle)

    def to_dict(self) -> dict:
        """JSON-ready: centre, diameters and depth in mm, the angle in degrees."""
        return {"kind": self.kind, "side": self.side, "center": np.round(self.center, 4).tolist(),
                "diameter_mm": round(self.diameter, 4), "through_mm": round(self.through, 4),
                "depth_mm": round(self.depth, 4), "angle_deg": None if self.angle is None else round(self.angle, 3),
                "face": self.face}


@dataclass(frozen=True, eq=False)
class Blank:
    """The flat blank of a sheet-metal part (:func:`patterns.unfold`).

    Attributes
    ----------
    name : str
    outline : patterns.curves.Loop
        The outer contour, counter-clockwise.
    holes : tuple of patterns.curves.Loop
        Every hole and cut-out, clockwise; drilled holes as one full-circle :class:`~patterns.curves.Arc`, a
        countersunk or counterbored one at its through diameter (its rim is in ``rims``).
    bends : tuple of Bend
    thickness : float
        Sheet thickness read from the model, mm.
    k_factor : float
        The K-factor the bends were developed with (None when a bend table gave every bend).
    fixed_face : int
        The CAD face that keeps its place (``shape.faces()`` index).
    findings : tuple of patterns.Finding
        Errors (``flanges-overlap``: the blank cannot be cut as it is) and notes
        (``bend-without-flange``, ``meshed-face``), as :func:`patterns.check` reports them.
    material : str or None
        The material whose table gave each bend its K-factor (``material=``), or None.
    rims : tuple of Rim
        The rims of countersunk and counterbored holes: marked, not cut (the hole is cut at its through
        diameter, one of ``holes``).
    """

    name: str
    outline: Loop
    holes: tuple
    bends: tuple
    thickness: float
    k_factor: float | None
    fixed_face: int
    findings: tuple
    material: str | None = None
    rims: tuple = ()

    def __post_init__(self):
        if any(b.sequence == 0 for b in self.bends):  # numbered once, here; a moved blank keeps its numbers
            object.__setattr__(self, "bends", numbered(self.polygon, self.bends))

    @property
    def ok(self) -> bool:
        """No finding that stops the blank being cut."""
        return not any(f.severity is Severity.ERROR for f in self.findings)

    @cached_property
    def polygon(self) -> shapely.Polygon:
        """The blank as one shapely polygon (outline with holes), sampled within 0.001 mm."""
        return shapely.Polygon(self.outline.points(), [h.points() for h in self.holes])

    @property
    def area(self) -> float:
        """Material area: the outline less the holes, mm², exactly (arcs as arcs)."""
        return self.outline.area - sum(h.area for h in self.holes)

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

    def bend_sheet(self) -> tuple:
        """The press brake's bend sheet: one :class:`~patterns.bendsheet.BendRow` per bend, in the order to
        bend them (outside-in, :func:`patterns.bendsheet.sequence`), lengths in mm, the bend lines' ends in
        the blank's own coordinates (``patterns.write(blank, "bends.csv")`` writes them in the DXF's)."""
        return bend_rows(self.name, self.bends)

    def moved(self, motion: Motion) -> Blank:
        """The blank moved rigidly (as laid out in a drawing or nested): outline, holes, rims, bend lines and the
        findings' points; nothing is scaled."""
        findings: tuple[Finding, ...] = tuple(f.moved(motion) for f in self.findings)
        return replace(self, outline=self.outline.moved(motion), holes=tuple(h.moved(motion) for h in self.holes),
                       bends=tuple(b.moved(motion) for b in self.bends), findings=findings,
                       rims=tuple(r.moved(motion) for r in self.rims))

    def __repr__(self) -> str:
        w, h = self.size
        return (f"Blank({self.name!r}, {w:.1f} x {h:.1f} mm, {self.thickness:g} mm thick, "
                f"{counted(len(self.bends), 'bend')}, {counted(len(self.holes), 'hole')}, "
                f"{'ok' if self.ok else 'not ok'})")

    def to_dict(self) -> dict:
        """Size, area, usage, bends and findings, JSON-ready (the report's ``blanks`` entries)."""
        w, h = self.size
        return {
            "name": self.name, "ok": self.ok, "thickness_mm": round(self.thickness, 4),
            "k_factor": self.k_factor, "fixed_face": self.fixed_face,
            "size_mm": [round(w, 3), round(h, 3)], "area_mm2": round(self.area, 3),
            "outer_perimeter_mm": round(self.perimeter, 3), "holes": len(self.holes),
            "usage": round(self.usage, 4),
            "material": self.material,
            "bends": [{"sequence": b.sequence, "angle_deg": round(b.angle, 3), "inside_radius_mm": round(b.inside_radius, 4),
                       "direction": b.direction, "allowance_mm": round(b.allowance, 4), "k_factor": b.k_factor,
                       "line": np.round(b.line, 4).tolist(), "faces": list(b.faces)} for b in self.bends],
            "rims": [r.to_dict() for r in self.rims],
            "findings": [f.to_dict() for f in self.findings],
        }
