"""Geometric predicates on flat layouts: is a flattening one-to-one, where do its outlines cross.

For a flattening of a planar-domain mesh (a disk, or a disk with holes) the
verdict rests on a degree argument: if no triangle is folded (every flat signed
area is positive) and the flat boundary loops form a valid polygon -- the outer
loop simple and counter-clockwise, every hole loop simple, clockwise, inside the
outer loop and outside the other holes -- then every point of the plane is
covered as many times as the boundary winds around it, i.e. once inside the
polygon and never outside, so the map is one-to-one.  Otherwise the verdict
says what failed and where.

A kernel beneath the engine (:mod:`patterns.flattening` keeps its layouts
one-to-one with these) and the report (:mod:`patterns.audit` turns them into
findings).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely

from .measure import folded_faces

__all__ = ["flat_polygon", "Overlap", "boundary_crossings", "crossing_segments", "overlap_verdict"]


@dataclass(frozen=True, eq=False)
class Overlap:
    """The overlap verdict of a flattening.

    Attributes
    ----------
    folded : (k,) int64
        Faces whose flat signed area is <= 0 (read-only).
    loops_simple : tuple of bool
        For each boundary loop: does its flat image not cross itself?
    nested : bool
        The flat loops form a valid polygon with holes, correctly oriented.
    one_to_one : bool
        No fold and ``nested``: the flattening does not overlap itself.
    message : str
        "one-to-one", or what failed and where (the first crossing point).
    """

    folded: np.ndarray
    loops_simple: tuple
    nested: bool
    one_to_one: bool
    message: str

    @property
    def n_folded(self) -> int:
        return len(self.folded)


def overlap_verdict(uv: np.ndarray, faces: np.ndarray, loops) -> Overlap:
    """Decide whether the flat mesh ``(uv, faces)`` overlaps itself.

    Parameters
    ----------
    uv : array_like, (n, 2) float
        Flat positions (any unit).
    faces : array_like, (m, 3) int
    loops : sequence of array_like (k,) int
        Boundary loops of the mesh, the surface to their left
        (:attr:`patterns.mesh.Connectivity.loops`).

    Returns
    -------
    Overlap
    """
    # A diverged flattening overflows here; its verdict is still exact.
    uv, faces = np.asarray(uv, dtype=np.float64), np.asarray(faces, dtype=np.int64)
    loops = [np.asarray(loop, dtype=np.int64) for loop in loops]
    with np.errstate(over="ignore", invalid="ignore"):
        return _verdict(uv, faces, loops)


def _verdict(uv: np.ndarray, faces: np.ndarray, loops) -> Overlap:
    folded = folded_faces(uv, faces)
    folded.setflags(write=False)
    problems = []
    if len(folded):
        problems.append(f"{len(folded)} folded triangles (first: face {int(folded[0])})")
    if not np.all(np.isfinite(uv)):
        return Overlap(folded, tuple(False for _ in loops), False, False, "non-finite flat coordinates")
    rings = [shapely.linearrings(uv[loop]) for loop in loops]
    simple = tuple(bool(x) for x in shapely.is_simple(rings))
    for i, ok in enumerate(simple):
        if not ok:
            where = _first_crossing(rings[i])
            problems.append(f"boundary loop {i} crosses itself{where}")
    outer = int(np.argmax(shapely.area(shapely.polygons(rings))))
    ccw = shapely.is_ccw(rings)
    oriented = bool(ccw[outer]) and not any(ccw[i] for i in range(len(loops)) if i != outer)
    if not oriented:
        problems.append("boundary loops are wrongly oriented (the flat pattern is turned inside out)")
    polygon = shapely.Polygon(uv[loops[outer]], [uv[loop] for i, loop in enumerate(loops) if i != outer])
    valid = bool(shapely.is_valid(polygon))
    if not valid and all(simple):
        problems.append(f"boundary loops are not properly nested: {shapely.is_valid_reason(polygon)}")
    nested = valid and oriented
    one_to_one = nested and not len(folded)
    return Overlap(folded, simple, nested, one_to_one, "one-to-one" if one_to_one else "; ".join(problems))


def _first_crossing(ring) -> str:
    reason = shapely.is_valid_reason(shapely.Polygon(ring))
    if "[" in reason:
        return " at " + reason[reason.index("[") :]
    return ""


def crossing_segments(uv: np.ndarray, loops):
    """Pairs of flat boundary segments that touch or cross, neighbours along a loop left out.

    Returns
    -------
    lines : (s,) shapely LineStrings
        Every boundary segment, loop after loop.
    pair : (s, 2) int64
        Each segment's two vertex indices.
    i, j : (c,) int64
        Indices into ``lines`` of the segments that meet, ``i < j``.
    """
    starts = np.concatenate(loops)
    ends = np.concatenate([np.roll(loop, -1) for loop in loops])
    lines = shapely.linestrings(np.stack([uv[starts], uv[ends]], axis=1))
    i, j = shapely.STRtree(lines).query(lines, predicate="intersects")
    keep = i < j
    i, j = i[keep], j[keep]
    pair = np.stack([starts, ends], axis=1)
    adjacent = (pair[i][:, :, None] == pair[j][:, None, :]).any(axis=(1, 2))
    return lines, pair, i[~adjacent], j[~adjacent]


def boundary_crossings(uv: np.ndarray, loops) -> list[tuple[int, int, np.ndarray]]:
    """Where flat boundary segments cross.

    Parameters
    ----------
    uv : (n, 2) float64
    loops : sequence of (k,) int64

    Returns
    -------
    list of (loop_a, loop_b, points (p, 2) float64)
        One entry per pair of loops that cross (``loop_a == loop_b`` for a loop
        crossing itself), with the crossing points.  Segments that share a
        vertex are not counted as crossing there.
    """
    loop_of = np.concatenate([np.full(len(loop), i) for i, loop in enumerate(loops)])
    lines, _, i, j = crossing_segments(uv, loops)
    out = {}
    for a, b in zip(i, j):
        key = (int(min(loop_of[a], loop_of[b])), int(max(loop_of[a], loop_of[b])))
        geom = shapely.intersection(lines[a], lines[b])
        pts = shapely.get_coordinates(geom)
        if len(pts):
            out.setdefault(key, []).append(pts.mean(axis=0))
    return [(a, b, np.array(p)) for (a, b), p in sorted(out.items())]


def flat_polygon(uv: np.ndarray, loops, *, holes: bool = True):
    """The shapely polygon of a flat panel: ``uv[loops[0]]`` the outline, the other loops its holes.

    Parameters
    ----------
    uv : (n, 2) float64
    loops : sequence of (k,) int64
        Outline first (as :attr:`patterns.Panel.loops` orders them).
    holes : bool
        False: the outline alone (what nesting places).
    """
    uv = np.asarray(uv, dtype=np.float64)
    return shapely.Polygon(uv[loops[0]], [uv[loop] for loop in loops[1:]] if holes else None)
