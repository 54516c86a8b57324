"""Manufacturability checks on a blank, as a service bureau runs them before it accepts a file.

Every rule works on the flat :class:`patterns.Blank` in 2D: its outline and
holes, its bends (centre line, developed width ``allowance``, inside radius,
angle) and its thickness ``t``.  A bend's **zone** is its centre line widened
by half its allowance on each side and limited to the line's extent: the
strip of the blank that the press brake bends, between its two tangent lines.

The rules share one model of the press brake: air bending in a V-die.  The
die's opening is ``V = DIE_WIDTH t`` (shops pick 6-8 t; the narrowest, 6 t, is
assumed, so that a part that fits no common die is what gets reported).

* ``hole-near-bend``: a hole within ``V / 2`` of a bend's centre line lies
  over the die's opening and is drawn into it (SendCutSend, "How To Avoid
  Deformation in Bent Sheet Metal Parts",
  https://sendcutsend.com/blog/avoid-deformation-bent-sheet-metal/: "keep all
  features at least half the full die width away from the center of each
  bend"); on the blank, the hole's distance to the zone must be at least ``V /
  2 - allowance / 2``, and never less than ``MIN_HOLE_CLEARANCE t`` (1.5 t,
  aPriori's hole-to-bend proximity threshold), which also holds beyond the ends
  of the bend.  A hole that overlaps a zone and reaches outside it is a cut
  across the bend (a relief, a window the bend is interrupted by), not a hole
  near it; one wholly inside the zone is at distance 0.
* ``short-flange``: a flange must rest on the die's shoulder through the whole
  stroke: its length outside the bend (the flat beyond the tangent line plus
  the outside setback ``(r + t) tan(a / 2)``) must be at least ``V / (2 cos(a /
  2))`` -- ``0.71 V = 4.24 t`` for 90 degrees, the 4 t minimum flange of
  SendCutSend (https://sendcutsend.com/designing-for-bending-and-forming/: "at
  least 1/2 in or 4x the material thickness, whichever is greater") and
  Protolabs.  The flat is measured square to the bend from its tangent line to
  the outline or to the next bend's zone, at :data:`STATIONS` stations; the
  flange's length is their median (a notched or chamfered end is not the
  flange).
* ``missing-relief``: where a bend ends beside unbent material, that material
  tears unless a relief is cut there (SendCutSend,
  https://sendcutsend.com/faq/what-are-your-bend-relief-requirements/: at least
  50 % of the thickness wide, ``r + t + 0.020 in`` deep).  Reported when, at a
  corner of the zone, the blank's material runs on past the zone's end across
  its tangent line with no cut between (probed ``RELIEF_PROBE t`` beyond both);
  where another bend's zone lies within the relief's depth, two bends meet at a
  corner, which corner reliefs treat, not this rule.
* ``open-contour``: a cut contour that does not close (an error: the blank is
  not cut; :func:`open_contours`).

A bend wider than the die's opening (a conical bend's sector, a large radius)
is not formed in a V-die: the rules skip it.
The first three are notes: a shop's warnings, the blank is still written.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely

from ..curves import Arc
from ..findings import Code, Finding, Severity

__all__ = ["DIE_WIDTH", "MIN_HOLE_CLEARANCE", "RELIEF_PROBE", "manufacturability", "open_contours"]

DIE_WIDTH = 6.0
"""The V-die's opening, in thicknesses: the narrowest of the 6-8 t press-brake shops use (air bending)."""
MIN_HOLE_CLEARANCE = 1.5
"""The least distance from a hole to a bend's zone, in thicknesses, however wide the bend (aPriori's
hole-to-bend proximity threshold: 1.5 times the stock thickness)."""
RELIEF_PROBE = 0.25
"""How far beyond the end and the tangent line of a bend's zone its corner is probed for unbent material, in
thicknesses: half the narrowest relief (SendCutSend's 0.5 t wide)."""
RELIEF_EXTRA = 0.508
"""mm a bend relief reaches past ``r + t`` (SendCutSend: relief depth ``r + t + 0.020 in``); another bend's zone
within ``r + t + RELIEF_EXTRA`` of a bend's end makes it a corner where bends meet (a corner relief's business)."""
MAX_FORMING_ANGLE = 135.0
"""Degrees: the flange-length rule is evaluated at most at this bend angle (a hem is pre-bent, then flattened)."""
STATIONS = 41
"""Stations along a bend at which its flanges are measured."""


@dataclass(frozen=True)
class _Zone:
    """A bend's frame on the blank: ``origin + s u + v n``, the zone ``0 <= s <= length``, ``|v| <= half``."""

    index: int
    origin: np.ndarray
    u: np.ndarray
    n: np.ndarray
    length: float
    half: float

    def at(self, s, v) -> np.ndarray:
        return self.origin + np.multiply.outer(s, self.u) + np.multiply.outer(v, self.n)

    def extended(self, by: float) -> shapely.Polygon:
        """The zone run on ``by`` mm past both ends of its line."""
        return shapely.Polygon(self.at(np.array([-by, self.length + by, self.length + by, -by]),
                                       np.array([-self.half, -self.half, self.half, self.half])))

    @property
    def polygon(self) -> shapely.Polygon:
        return shapely.Polygon(self.at(np.array([0, self.length, self.length, 0.0]),
                                       np.array([-self.half, -self.half, self.half, self.half])))


def _zones(blank, die_width: float) -> list:
    """The zones of the blank's bends a V-die forms: a bend wider than the die's opening (its allowance over
    ``die_width t``: a conical bend's sector, a large radius) is rolled or bump-bent, and not judged here."""
    zones = []
    for k, bend in enumerate(blank.bends):
        a, c = np.asarray(bend.line, dtype=np.float64)
        length = float(np.linalg.norm(c - a))
        if length <= 0 or bend.allowance > die_width * blank.thickness:
            continue
        u = (c - a) / length
        zones.append(_Zone(k, a, u, np.array([-u[1], u[0]]), length, 0.5 * bend.allowance))
    return zones


def _valid(geometry):
    """A blank whose flanges land on one another (an error already) has no valid polygon: measure its repair."""
    return geometry if geometry.is_valid else shapely.make_valid(geometry)


def _bend_label(bend) -> str:
    faces = ", ".join(map(str, bend.faces))
    return f"the bend at face{'s' if len(bend.faces) > 1 else ''} {faces} ({bend.label})"


def _hole_label(k: int, hole) -> str:
    """``hole 3 (Ø 4.00 mm)`` for a round hole (one full circle, or arcs of one circle), else the cut-out's size."""
    arcs = [p for p in hole.pieces if isinstance(p, Arc)]
    if len(arcs) == len(hole.pieces) and all(abs(a.radius - arcs[0].radius) < 1e-6 and
                                             np.linalg.norm(a.center - arcs[0].center) < 1e-6 for a in arcs):
        return f"hole {k} (Ø {2 * arcs[0].radius:.2f} mm)"
    x0, y0, x1, y1 = hole.polygon.bounds
    return f"cut-out {k} ({x1 - x0:.2f} x {y1 - y0:.2f} mm)"


def hole_clearance(thickness: float, allowance: float, *, die_width: float = DIE_WIDTH,
                   min_clearance: float = MIN_HOLE_CLEARANCE) -> float:
    """The least distance, mm, from a hole to a bend's zone: ``max(V / 2 - allowance / 2, min_clearance t)``
    with ``V = die_width t``."""
    return max(0.5 * die_width * thickness - 0.5 * allowance, min_clearance * thickness)


def _across(z: _Zone, ring) -> bool:
    """Whether a cut crosses a bend's zone from one tangent line to the other, or runs over an end of it (a
    relief or a window); a hole that only bites into the zone from one side is not across it."""
    side = [shapely.LineString(z.at(np.array([0.0, z.length]), np.array([v, v]))) for v in (-z.half, z.half)]
    ends = [shapely.LineString(z.at(np.array([s, s]), np.array([-z.half, z.half]))) for s in (0.0, z.length)]
    return all(ring.intersects(line) for line in side) or any(ring.intersects(line) for line in ends)


def holes_near_bends(blank, *, die_width: float = DIE_WIDTH, min_clearance: float = MIN_HOLE_CLEARANCE) -> list:
    """``hole-near-bend`` notes: every (hole, bend) closer than :func:`hole_clearance`."""
    out = []
    zones = _zones(blank, die_width)
    for k, hole in enumerate(blank.holes):
        ring = _valid(hole.polygon)
        for z in zones:
            bend = blank.bends[z.index]
            zone = z.polygon
            need = hole_clearance(blank.thickness, bend.allowance, die_width=die_width, min_clearance=min_clearance)
            if ring.intersects(zone) and not zone.covers(ring) and _across(z, ring):
                continue  # a cut across the bend: a relief at its end, or a window the bend is interrupted by
            d = float(zone.distance(ring))
            if d >= need:
                continue
            here, there = shapely.ops.nearest_points(ring, zone)
            where = "inside the bend's zone" if d == 0 else f"{d:.2f} mm from the bend's zone"
            out.append(Finding(
                Code.HOLE_NEAR_BEND, Severity.NOTE, (blank.name,), [here.coords[0], there.coords[0]], (), None,
                f"{blank.name}: {_hole_label(k, hole)} at ({ring.centroid.x:.2f}, {ring.centroid.y:.2f}) is "
                f"{where} of {_bend_label(bend)}; it needs {need:.2f} mm (the larger of half a "
                f"{die_width * blank.thickness:g} mm ({die_width:g} t) V-die from the bend's centre line and "
                f"{min_clearance:g} t): the press brake draws it out of shape"))
    return out


def _flat_beyond(z: _Zone, side: float, s: np.ndarray, boundary, outline: shapely.Polygon, others: list,
                 reach: float) -> np.ndarray:
    """(k,) float64, mm: the length of material square to the bend from its tangent line at each of the
    stations ``s`` on ``side`` (+1/-1), to the outline (its ``boundary``) or the next bend's zone; NaN where no
    flange starts there."""
    eps = 1e-6 * max(1.0, reach)
    starts = z.at(s, np.full(len(s), side * z.half))
    inside = shapely.contains_xy(outline, *(starts + side * 10 * eps * z.n).T)
    rays = shapely.linestrings(np.stack([starts, starts + side * reach * z.n], axis=1))
    ends = np.full(len(s), reach)
    for other in [boundary, *others]:
        cuts = shapely.intersection(rays, other)
        pts, which = shapely.get_coordinates(cuts, return_index=True)
        d = (pts - starts[which]) @ (side * z.n)
        far = d > 10 * eps
        np.minimum.at(ends, which[far], d[far])
    return np.where(inside, ends, np.nan)


def short_flanges(blank, *, die_width: float = DIE_WIDTH) -> list:
    """``short-flange`` notes: a flange of a bend (either side) shorter than the die can hold."""
    out = []
    zones = _zones(blank, die_width)
    outline = _valid(blank.outline.polygon)
    boundary = outline.boundary
    x0, y0, x1, y1 = outline.bounds
    reach = 2 * float(np.hypot(x1 - x0, y1 - y0))
    t = blank.thickness
    for z in zones:
        bend = blank.bends[z.index]
        others = [o.polygon for o in zones if o.index != z.index]
        a = np.radians(min(bend.angle, MAX_FORMING_ANGLE))
        setback = (bend.inside_radius + t) * np.tan(a / 2)
        need = 0.5 * die_width * t / np.cos(a / 2)
        margin = min(t, 0.25 * z.length)
        stations = np.linspace(margin, z.length - margin, STATIONS)
        for side in (-1.0, 1.0):
            lengths = _flat_beyond(z, side, stations, boundary, outline, others, reach)
            flats = [(f, s) for f, s in zip(lengths, stations) if not np.isnan(f)]
            if not flats:
                continue
            flat, s = sorted(flats)[len(flats) // 2]  # the median: a chamfered or notched end is not the flange
            flat = float(flat)
            if flat + setback >= need:
                continue
            start = z.at(s, side * z.half)
            out.append(Finding(
                Code.SHORT_FLANGE, Severity.NOTE, (blank.name,), [start, start + side * flat * z.n], (), None,
                f"{blank.name}: a flange of {_bend_label(bend)} is {flat + setback:.2f} mm long outside the bend "
                f"({flat:.2f} mm flat beyond its zone); a {die_width:g} t = {die_width * t:g} mm V-die needs {need:.2f} mm"))
    return out


def _run_end(z: _Zone, material: shapely.Polygon, v: float, end: int, reach: float) -> float | None:
    """Where the material along ``v`` (across the zone) ends at the zone's ``end`` (0 or 1), in ``s``."""
    line = shapely.LineString([z.at(-reach, v), z.at(z.length + reach, v)])
    runs = []
    for piece in getattr(material.intersection(line), "geoms", [material.intersection(line)]):
        if piece.is_empty or piece.geom_type != "LineString":
            continue
        s = (shapely.get_coordinates(piece) - z.origin) @ z.u
        if s.max() > 0 and s.min() < z.length:
            runs.append((s.min(), s.max()))
    if not runs:
        return None
    # an end cut askew reaches past the line's end by up to the zone's width; farther, the run is another face's
    last, first = max(r[1] for r in runs), min(r[0] for r in runs)
    if end:
        return last if last <= z.length + 2 * z.half else z.length
    return first if first >= -2 * z.half else 0.0


def missing_reliefs(blank, *, probe: float = RELIEF_PROBE, die_width: float = DIE_WIDTH) -> list:
    """``missing-relief`` notes: a corner of a bend's zone where unbent material runs on past its end."""
    out = []
    zones = _zones(blank, die_width)
    material = _valid(blank.polygon)
    boundary = material.boundary
    x0, y0, x1, y1 = material.bounds
    reach = 2 * float(np.hypot(x1 - x0, y1 - y0))
    d = probe * blank.thickness
    for z in zones:
        bend = blank.bends[z.index]
        if z.length <= 2 * d:
            continue
        corner = bend.inside_radius + blank.thickness + RELIEF_EXTRA  # another bend this near: a corner
        # another bend's zone, run on past its ends (a corner relief cuts it back), this near: a corner
        others = shapely.union_all([o.extended(corner).buffer(corner) for o in zones if o.index != z.index])
        for end in (0, 1):
            out_dir = 1.0 if end else -1.0
            for side in (-1.0, 1.0):
                s_end = _run_end(z, material, side * (z.half - d), end, reach)
                if s_end is None:
                    continue
                v = side * (z.half + d)  # beside the zone's end, across its tangent line
                p, q = z.at(s_end - out_dir * d, v), z.at(s_end + out_dir * d, v)
                if shapely.LineString([p, q]).intersects(boundary) or not material.contains(shapely.Point(q)) or \
                        others.contains(shapely.Point(q)):
                    continue
                at = z.at(s_end, side * z.half)
                out.append(Finding(
                    Code.MISSING_RELIEF, Severity.NOTE, (blank.name,), [at], (), None,
                    f"{blank.name}: {_bend_label(bend)} ends at ({at[0]:.2f}, {at[1]:.2f}) beside unbent "
                    f"material with no relief cut into it: the corner tears (cut a relief at least "
                    f"{0.5 * blank.thickness:.2f} mm wide and {corner:.2f} mm deep there)"))
    return out


def open_contours(gaps, name: str) -> tuple:
    """``open-contour`` errors: one per gap of the cut contour, ``gaps`` a list of (2, 2) float64 mm (where
    the contour stops, where it should have gone on)."""
    out = []
    for gap in gaps:
        a, b = np.asarray(gap, dtype=np.float64).reshape(2, 2)
        out.append(Finding(
            Code.OPEN_CONTOUR, Severity.ERROR, (name,), [a, b], (), None,
            f"{name}: the cut contour does not close: it stops at ({a[0]:.3f}, {a[1]:.3f}), "
            f"{np.linalg.norm(b - a):.3f} mm from where it should go on at ({b[0]:.3f}, {b[1]:.3f}); "
            f"a cutter must not get an open contour"))
    return tuple(out)


def manufacturability(blank, *, die_width: float = DIE_WIDTH, min_hole_clearance: float = MIN_HOLE_CLEARANCE,
                      relief_probe: float = RELIEF_PROBE) -> tuple:
    """A service bureau's checks of a blank: holes near bends, short flanges, bends without relief.

    Parameters
    ----------
    blank : patterns.Blank
        Its outline, holes, bends (``line``, ``allowance``, ``inside_radius``, ``angle``) and thickness, mm.
    die_width : float, optional
        The V-die's opening in thicknesses (default :data:`DIE_WIDTH`, 6).
    min_hole_clearance : float, optional
        The least hole-to-bend-zone distance in thicknesses (default :data:`MIN_HOLE_CLEARANCE`, 1.5).
    relief_probe : float, optional
        How far past a zone's corner unbent material is looked for, in thicknesses (default
        :data:`RELIEF_PROBE`, 0.25).

    Returns
    -------
    tuple of patterns.Finding
        ``hole-near-bend``, ``short-flange`` and ``missing-relief`` notes, in that order, each with where
        (points in the blank's coordinates, mm) and the measured and required lengths in its message.
    """
    return tuple(holes_near_bends(blank, die_width=die_width, min_clearance=min_hole_clearance)
                 + short_flanges(blank, die_width=die_width)
                 + missing_reliefs(blank, probe=relief_probe, die_width=die_width))
