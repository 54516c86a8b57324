"""Notches and drill holes: where a piece is marked so that it sews back true.

A notch marks a seam point on the cut line, for the cutter's knife or the
sewer's eye, at equal 3D arc length on both sides of a seam
(:func:`notch_positions`).  With a seam allowance it runs from the cut line to
the seam line along the seam's own inward normal (taken from the side of the
seam its panel lies on, never from a probe near a corner), so at a panel
corner it lies in the allowance of the edge beyond; without one the cut line is
the seam line and a notch is a 3 mm snip into the piece along the outline's
inward normal (the bisector of the two edges at a corner).  A dart's legs are
notched where they meet the outline, and its point is a drill hole.
"""

from __future__ import annotations

import math

import numpy as np
import shapely

from ..mesh import polyline_arc

__all__ = ["drill_holes", "notch_positions", "notches", "runs_along_loop", "v_mouth"]


def notch_positions(flat_seam, side: int, uv: np.ndarray, spacing: float | None) -> list:
    """Where the notches of one side of a seam go: at equal 3D arc length on both sides.

    Parameters
    ----------
    flat_seam : patterns.FlatSeam
    side : int
        0 or 1.
    uv : (n, 2) float64
        The flat positions of that side's panel (as placed).
    spacing : float or None
        A notch every ``spacing`` mm of 3D seam length, and at both ends; None:
        at the ends only.

    Returns
    -------
    list of (float, (2,) float64, (2,) float64)
        The 3D arc length, the flat point, and the flat tangent (unit) there.
    """
    seam = flat_seam.seam
    pts = uv[seam.vertices[side]]
    c3 = polyline_arc(seam.points)
    total = c3[-1]
    if spacing:
        marks = np.arange(0.0, total, spacing)
        if total - marks[-1] < 0.25 * spacing:
            marks = marks[:-1]  # not a notch a hair before the end one
        marks = np.append(marks, total)
    else:
        marks = np.array([0.0, total])
    out = []
    for s in marks:
        j = int(np.clip(np.searchsorted(c3, s, side="right") - 1, 0, len(c3) - 2))
        t = (s - c3[j]) / max(c3[j + 1] - c3[j], 1e-300)
        point = pts[j] + t * (pts[j + 1] - pts[j])
        tangent = pts[j + 1] - pts[j]
        out.append((float(s), point, _unit(tangent)))
    return out


def notches(pattern, geo, allowance_of, spacing=None):
    """``(start on the cut line, inward direction, depth)`` of every notch on the panel, right by construction.

    With a seam allowance, a notch runs from the cut line to the seam line, square
    to the seam there: it starts where the ray from the seam point outwards (the
    seam's own outward normal, taken from which side of it the panel lies, not
    from a probe) meets the cut line, and ends on the seam point -- at a corner
    as well, where it lies in the allowance of the edge beyond.  Without one,
    the cut line is the seam line and the notch is a snip into the piece along the
    outline's inward normal, the bisector of the two edges at a corner (never
    along an edge).
    """
    flat = pattern.panels[geo.index]
    source = pattern.source_of(geo.index)
    cut = shapely.Polygon(geo.cut_loops[0], geo.cut_loops[1:])
    out = []
    for fs in pattern.seams:
        seam = fs.seam
        for side, p in enumerate(seam.panels):
            if p != source:
                continue
            along = runs_along_loop(flat.loops, seam.vertices[side])
            depth = allowance_of(seam.id)
            for _, point, tangent in notch_positions(fs, side, geo.uv, spacing):
                inward = along * np.array([-tangent[1], tangent[0]])  # the panel lies to the left of its loops
                out.append(_notch(cut, geo, point, inward, depth))
    depth = allowance_of(None)
    for point, normal in _dart_mouths(flat, geo, across=depth > 0):
        out.append(_notch(cut, geo, point, -normal, depth))
    return out


def runs_along_loop(loops, vertices) -> float:
    """+1 when a seam's vertices run the way its panel's boundary loop does (panel to their left), else -1."""
    a, b = int(vertices[0]), int(vertices[1])
    for loop in loops:
        at = np.flatnonzero(np.asarray(loop) == a)
        if len(at):
            return 1.0 if int(loop[(at[0] + 1) % len(loop)]) == b else -1.0
    return 1.0


def _notch(cut, geo, point, inward, depth):
    """One notch at a seam-line ``point`` whose inward normal is ``inward``: see :func:`_notches`."""
    if depth > 0:
        # Where the allowance steps from one seam to the next, the step of the cut line runs along
        # the ray from the seam's end: the notch moves half a millimetre along its own seam.
        along = np.array([inward[1], -inward[0]])
        for at in (point, point + 0.5 * along, point - 0.5 * along):
            ray = shapely.LineString([at, at - 3.0 * depth * inward])
            meet = ray.intersection(cut.boundary)
            hits = shapely.get_coordinates(meet)
            if len(hits) and shapely.get_type_id(meet) in (0, 4):  # points, not a run along the cut line
                start = hits[np.argmin(np.linalg.norm(hits - at, axis=1))]
                gap = math.hypot(*(start - at))
                inside = shapely.points(start + np.linspace(0.1, 0.9, 9)[:, None] * (at - start))
                along_cut = shapely.distance(cut.boundary, inside).min() < 1e-3  # partly on a step of it
                if not along_cut and (abs(gap - depth) < 1e-6 or (at is point and gap > 1e-9)):
                    return start, inward, gap
        return point - depth * inward, inward, float(depth)
    rings = [shapely.LinearRing(loop) for loop in geo.cut_loops]  # straight runs dropped within 0.001 mm:
    ring = rings[int(np.argmin([r.distance(shapely.Point(point)) for r in rings]))]  # start on the line drawn
    point = np.array(ring.interpolate(ring.project(shapely.Point(point))).coords[0])
    direction = inward
    for loop in geo.cut_loops:  # at a corner of the outline: the bisector of its two edges' inward normals
        k = np.flatnonzero(np.linalg.norm(loop - point, axis=1) < 1e-9)
        if len(k):
            i = int(k[0])
            before, after = loop[i] - loop[i - 1], loop[(i + 1) % len(loop)] - loop[i]
            normals = [_unit(np.array([-d[1], d[0]])) for d in (before, after)]
            if float(normals[0][0] * normals[1][0] + normals[0][1] * normals[1][1]) < np.cos(np.radians(10)):
                bisector = normals[0] + normals[1]
                if math.hypot(*bisector) > 1e-9:
                    direction = _unit(bisector)
                    if not shapely.contains_xy(cut, *(point + 0.5 * direction)):
                        direction = -direction
            break
    return point, direction, 3.0


def v_mouth(geo, start, width) -> tuple:
    """The two ends of a V notch's mouth: on the cut outline, half ``width`` along it either side of ``start``."""
    rings = [shapely.LinearRing(loop) for loop in geo.cut_loops]
    ring = rings[int(np.argmin([r.distance(shapely.Point(start)) for r in rings]))]
    at = ring.project(shapely.Point(start))
    return tuple(np.array(ring.interpolate((at + d) % ring.length).coords[0]) for d in (-0.5 * width, 0.5 * width))


def _dart_mouths(flat, geo, *, across: bool) -> list:
    """``(point, outward direction)`` where each leg of each dart meets the outline.

    ``across`` (a seam allowance is drawn): square to the leg, as at the end
    of a seam side (the two legs are sewn like one), so that the notch runs
    from the seam line out across the leg's allowance.  Otherwise the corner
    where leg and outline meet is a cut line both ways, and the notch is a
    snip into the piece along the corner's bisector (the direction returned
    is its opposite: notches without an allowance are drawn inwards).
    """
    out = []
    loops = [np.asarray(loop) for loop in flat.loops]
    for dart in flat.darts:
        for leg in dart.legs:
            mouth = geo.uv[leg[0]]
            along = geo.uv[leg[1]] - mouth
            along = _unit(along)
            if across:
                normal = np.array([along[1], -along[0]])
            else:
                (loop,) = [lp for lp in loops if np.any(lp == leg[0])]
                at = int(np.flatnonzero(loop == leg[0])[0])
                nbrs = [int(loop[at - 1]), int(loop[(at + 1) % len(loop)])]
                rim = geo.uv[nbrs[1] if nbrs[0] == leg[1] else nbrs[0]] - mouth
                normal = _unit(-(along + _unit(rim)))
            probe = mouth + 0.25 * math.hypot(*(geo.uv[leg[1]] - mouth)) * normal
            if shapely.contains_xy(geo.polygon, *probe):
                normal = -normal  # outward = away from the piece
            out.append((mouth, normal))
    return out


def drill_holes(flat, geo) -> np.ndarray:
    """(d, 2) float64, mm, placed: the tip of each dart (a drill hole marks it, on the DRILL layer or ASTM 13)."""
    return np.array([geo.uv[dart.tip] for dart in flat.darts]).reshape(-1, 2)


def _unit(d: np.ndarray) -> np.ndarray:
    """``d`` ``(2,) float64`` over its length (math.hypot: no BLAS dot product, whose last bit follows the CPU's
    kernels and would move a notch in the file written)."""
    return d / max(math.hypot(d[0], d[1]), 1e-300)
