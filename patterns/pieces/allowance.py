"""The seam allowance: a panel's cut line, its seam line offset outwards by each edge's allowance.

The cut line is the seam line offset outwards with shapely: mitred corners
(bevelled past ``mitre_limit`` allowances, default 2, as garment CAD limits them), bevelled ones, or squared ones (each side's allowance run straight on past
the corner); where allowances change along an outline the step is square.
Holes shrink by their allowance.  Every contour is then cleaned for a cutter:
points closer than 1e-6 mm merged, straight runs one segment (a point within
:data:`STRAIGHT` of the line through its neighbours dropped).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import shapely

from ..errors import InputError

__all__ = ["STRAIGHT", "allowance_lookup", "allowance_outline", "snap", "straight_runs"]


def allowance_outline(polygon, loops, per_segment, corners, *, mitre_limit: float = 2.0):
    """The cut outline: the seam line offset outwards by each segment's allowance.

    ``corners="mitre"``: offset lines meet at a point, unless it lies further than ``mitre_limit`` allowances
    from the corner, where the corner is cut square to its bisector at that distance (a gore's tip: a 20 degree
    tip's mitre is 5.8 allowances long).  ``"bevel"``: every corner so cut one allowance out (the allowance
    holds everywhere: nothing inside the round corner it would have).
    ``"square"``: at every sharp corner (turning by more than 30 degrees
    towards the material's outside) each side's allowance is run straight on
    past the corner by its own width, so the corner is squared off.
    """

    values = np.concatenate(per_segment)
    base = float(values.min())
    if corners == "square":
        return _square_allowance(polygon, loops, per_segment)
    # a bevel is the mitre cut square to the corner's bisector one allowance out: the allowance still holds
    # everywhere (shapely's own bevel joins the two offsets' ends, cutting into it at a sharp corner)
    limit = 1.0 if corners == "bevel" else mitre_limit
    cut = polygon.buffer(base, join_style="mitre", mitre_limit=limit) if base > 0 else polygon
    parts = [cut]
    for loop, allow in zip(loops, per_segment):
        if np.all(allow == base):
            continue
        # Runs of segments with the same larger allowance, buffered on their
        # outer (right-hand) side: the material lies to the left of every loop.
        n = len(loop)
        change = np.flatnonzero(allow != np.roll(allow, 1))
        starts = change if len(change) else np.array([0])
        for k, s in enumerate(starts):
            e = starts[(k + 1) % len(starts)] if len(starts) > 1 else s + n
            if e <= s:
                e += n
            a = float(allow[s % n])
            if a <= base:
                continue
            idx = np.arange(s, e + 1) % n
            line = shapely.LineString(loop[idx])
            parts.append(shapely.buffer(line, -a, single_sided=True, join_style="mitre", cap_style="flat",
                                        mitre_limit=limit))
    out = shapely.union_all(parts)
    if out.geom_type != "Polygon":
        out = max(getattr(out, "geoms", [out]), key=lambda g: g.area)
    return shapely.orient_polygons(out)


def _square_allowance(polygon, loops, per_segment):
    """Allowance with squared corners: each run between sharp corners offset on its own, extended."""

    parts = [polygon]
    for loop, allow in zip(loops, per_segment):
        n = len(loop)
        a_vec = loop - np.roll(loop, 1, axis=0)
        b_vec = np.roll(loop, -1, axis=0) - loop
        turn = np.arctan2(a_vec[:, 0] * b_vec[:, 1] - a_vec[:, 1] * b_vec[:, 0], (a_vec * b_vec).sum(axis=1))
        # Corners: sharp turns, and where the allowance changes.
        cut_at = np.flatnonzero((np.abs(turn) > np.radians(30)) | (allow != np.roll(allow, 1)))
        if not len(cut_at):
            cut_at = np.array([0])
        for k, s in enumerate(cut_at):
            e = cut_at[(k + 1) % len(cut_at)]
            if e <= s:
                e += n
            a = float(allow[s % n])
            if a <= 0:
                continue
            run = loop[np.arange(s, e + 1) % n].copy()
            # Run straight on past a convex corner (the material on the left turns left there).
            if turn[s % n] > np.radians(30):
                t = run[0] - run[1]
                run = np.vstack([run[0] + a * t / np.linalg.norm(t), run])
            if turn[e % n] > np.radians(30):
                t = run[-1] - run[-2]
                run = np.vstack([run, run[-1] + a * t / np.linalg.norm(t)])
            parts.append(shapely.buffer(shapely.LineString(run), -a, single_sided=True, join_style="mitre",
                                        cap_style="flat", mitre_limit=4.0))
    out = shapely.union_all(parts)
    if out.geom_type != "Polygon":
        out = max(getattr(out, "geoms", [out]), key=lambda g: g.area)
    # Holes of the panel shrink by their allowance: take the holes of the union.
    return shapely.orient_polygons(out)


def snap(loop: np.ndarray, tol: float = 1e-6) -> np.ndarray:
    """Drop points closer than ``tol`` mm to the previous one (a closed loop: also last to first)."""
    loop = np.asarray(loop, dtype=np.float64)
    keep = np.ones(len(loop), dtype=bool)
    d = np.linalg.norm(np.diff(loop, axis=0), axis=1)
    keep[1:] = d > tol
    loop = loop[keep]
    if len(loop) > 3 and np.linalg.norm(loop[-1] - loop[0]) <= tol:
        loop = loop[:-1]
    return loop


STRAIGHT = 0.001
"""A point within this (mm) of the line through its neighbours is dropped: a straight run is one segment."""


def straight_runs(loop: np.ndarray, tolerance: float = STRAIGHT) -> np.ndarray:
    """A closed loop (k, 2) with the points of its straight runs dropped (Douglas-Peucker within ``tolerance``)."""
    simple = shapely.simplify(shapely.LinearRing(loop), tolerance, preserve_topology=True)
    pts = np.asarray(simple.coords)[:-1]
    return pts if len(pts) >= 3 else np.asarray(loop)


def allowance_lookup(seam_allowance, seam_ids, path):
    """A function ``seam id or None -> allowance, mm`` from a checked number or mapping (:class:`DxfOptions`)."""
    if not isinstance(seam_allowance, Mapping):
        return lambda seam: seam_allowance
    for key in seam_allowance:
        if key is not None and key not in seam_ids:
            raise InputError(f"{path}: seam_allowance names seam {key!r}, which the pattern does not have "
                             f"(seams {sorted(seam_ids)}; None for every other edge)")
    default = seam_allowance.get(None, 0.0)
    return lambda seam: seam_allowance.get(seam, default)
