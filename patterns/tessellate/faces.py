"""Face meshing: each face filled with a near-equilateral lattice, triangulated, its edges kept.

:func:`mesh_face` lays the face's boundary points (from the edge division) out
in the face's development, fills the inside with a lattice kept clear of the
boundary, triangulates (Delaunay), and checks that every boundary segment is a
triangle edge.  If one is lost it returns :class:`RefineEdges` -- the edges to
divide finer -- instead of a mesh; otherwise the triangles are improved on the
exact surface (:func:`patterns.tessellate.remesh.remesh`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import CadError
from ..mesh import unique_ints
from .edges import EdgeDivision
from .remesh import remesh
from .sizes import Sizes
from .topology import Topology

__all__ = ["FaceMesh", "RefineEdges", "mesh_face"]


@dataclass(frozen=True, eq=False)
class FaceMesh:
    """One face's mesh before assembly: boundary slots (global points) then interior points.

    Attributes
    ----------
    slot_gid : (b,) int64
        The boundary points, as indices into :attr:`EdgeDivision.points`.
    interior : (i, 3) float64, mm
        Interior points, on the surface.
    triangles : (m, 3) int64
        Over slots then interior points, wound as the face.
    occurrences : tuple of (edge index, number of points)
        Each use of an edge by the face's wires.
    occ_slots : tuple of (k,) int64
        Per occurrence, the slot of each of the edge's points.
    param : (b + i, 2) float64
        Surface parameters of the slots (approximate) and interior points.
    """

    slot_gid: np.ndarray
    interior: np.ndarray
    triangles: np.ndarray
    occurrences: tuple
    occ_slots: tuple
    param: np.ndarray


@dataclass(frozen=True)
class RefineEdges:
    """The result of a face that lost boundary segments: these edges need more points."""

    edges: frozenset


@dataclass(frozen=True, eq=False)
class _Boundary:
    """A face's boundary in its development: slots (distinct points), rings of slots, occurrences."""

    slot_gid: np.ndarray  # (b,) int64
    xy: np.ndarray  # (b, 2) development coordinates
    rings: tuple  # of lists of slots
    occurrences: tuple
    occ_slots: tuple


def mesh_face(topology: Topology, sizes: Sizes, division: EdgeDivision, k: int) -> FaceMesh | RefineEdges:
    """Mesh face ``k`` with the edges' points as its boundary; or the edges to divide finer."""
    from OCP.TopAbs import TopAbs_REVERSED

    h, dev = sizes.face_h[k], sizes.developments[k]
    bnd = _boundary(topology, division, k, dev, h)
    polygon = _polygon(bnd)
    interior = _lattice(polygon, bnd, h)
    points = np.concatenate([bnd.xy, interior])
    tri = _triangulate(points, polygon, len(bnd.xy), h, f"{topology.name}: face {k}")
    segs = np.stack([np.concatenate([np.asarray(r) for r in bnd.rings]),
                     np.concatenate([np.roll(np.asarray(r), -1) for r in bnd.rings])], axis=1)
    lost = _lost_edges(tri, segs, bnd, topology.degenerate, len(points))
    if lost is not None:
        if not lost:
            raise CadError(f"{topology.name}: face {k}: boundary segments lost in the triangulation")
        return RefineEdges(frozenset(lost))
    uv_b = dev.inverse(bnd.xy)  # only for orientation checks; boundary points stay where they are
    uv_in = dev.inverse(interior)
    xyz_b = division.points[bnd.slot_gid]
    uv_in, xyz_in, tri = remesh(sizes.surfaces[k], xyz_b, uv_b, uv_in, tri, segs)
    if topology.faces[k].Orientation() == TopAbs_REVERSED:
        tri = tri[:, [0, 2, 1]]
    return FaceMesh(bnd.slot_gid, xyz_in, tri, bnd.occurrences, bnd.occ_slots, np.concatenate([uv_b, uv_in]))


def _boundary(topology: Topology, division: EdgeDivision, k: int, dev, h: float) -> _Boundary:
    """The face's wires as rings of slots in its development (consecutive repeats of a point merged)."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve2d
    from OCP.TopAbs import TopAbs_REVERSED
    from OCP.TopoDS import TopoDS

    face = topology.faces[k]
    loops, occurrences = [], []  # per wire: (gids, uv, occurrence, positions); (edge, number of points)
    for walk in topology.wires[k]:
        raw = []
        for e, edge in walk:
            params, gids = division.params[e], division.gids[e]
            occ = len(occurrences)
            c2 = BRepAdaptor_Curve2d(TopoDS.Edge(edge), face)
            if topology.degenerate[e]:
                q = c2.Value(0.5 * (c2.FirstParameter() + c2.LastParameter()))
                occurrences.append((e, 1))
                raw.append((gids[:1], np.array([[q.X(), q.Y()]]), occ, np.zeros(1, dtype=int)))
                continue
            uv = np.array([(q.X(), q.Y()) for q in (c2.Value(t) for t in params)])
            pos = np.arange(len(params))
            if edge.Orientation() == TopAbs_REVERSED:
                uv, pos = uv[::-1], pos[::-1]
            occurrences.append((e, len(params)))
            raw.append((gids[pos], uv, occ, pos))
        loops.append(raw)
    return _slots(loops, occurrences, dev, h, f"{topology.name}: face {k}")


def _slots(loops, occurrences, dev, h: float, where: str) -> _Boundary:
    """Number the boundary points of a face's wires as slots; rings of at least three slots."""
    slot_gid, slot_uv = [], []
    occ_slots = [np.full(count, -1, dtype=np.int64) for _, count in occurrences]
    rings = []
    near = 0.01 * h

    def same(a, b) -> bool:  # np.allclose(a, b, atol=near), without its cost per point
        return abs(a[0] - b[0]) <= near + 1e-5 * abs(b[0]) and abs(a[1] - b[1]) <= near + 1e-5 * abs(b[1])

    for raw in loops:
        ring = []
        for gids, uv, occ, pos in raw:
            for g, p, q in zip(gids, dev.forward(uv), pos):
                if ring and slot_gid[ring[-1]] == g and same(slot_uv[ring[-1]], p):
                    occ_slots[occ][q] = ring[-1]
                    continue
                slot_gid.append(int(g))
                slot_uv.append(p)
                ring.append(len(slot_gid) - 1)
                occ_slots[occ][q] = ring[-1]
        if len(ring) > 1 and slot_gid[ring[0]] == slot_gid[ring[-1]] and same(slot_uv[ring[0]], slot_uv[ring[-1]]):
            last = ring.pop()
            for occ in {occ for _, _, occ, _ in raw}:  # the slot is this wire's own: only its edges hold it
                o = occ_slots[occ]
                o[o == last] = ring[0]
            slot_gid.pop()
            slot_uv.pop()
        if len(ring) >= 3:
            rings.append(ring)
    if not rings:
        raise CadError(f"{where} has no usable boundary")
    return _Boundary(np.asarray(slot_gid, dtype=np.int64), np.array(slot_uv, dtype=np.float64), tuple(rings),
                     tuple(occurrences), tuple(occ_slots))


def _polygon(bnd: _Boundary):
    """The face's domain in its development (shapely), outer ring counter-clockwise."""
    import shapely

    ring_xy = [bnd.xy[r] for r in bnd.rings]
    signed = [0.5 * np.sum(r[:, 0] * np.roll(r[:, 1], -1) - np.roll(r[:, 0], -1) * r[:, 1]) for r in ring_xy]
    outer = int(np.argmax(np.abs(signed)))
    shell = ring_xy[outer] if signed[outer] > 0 else ring_xy[outer][::-1]
    holes = [r if s < 0 else r[::-1] for i, (r, s) in enumerate(zip(ring_xy, signed)) if i != outer]
    polygon = shapely.Polygon(shell, holes)
    return polygon if polygon.is_valid else shapely.make_valid(polygon)


def _lattice(polygon, bnd: _Boundary, h: float) -> np.ndarray:
    """Interior points (i, 2): a triangular lattice of spacing ``h`` inside, kept clear of the boundary."""
    import shapely

    x0, y0, x1, y1 = polygon.bounds
    dy = h * np.sqrt(3) / 2
    pts = [np.column_stack([xs, np.full(len(xs), yv)])
           for r, yv in enumerate(np.arange(y0 + 0.5 * dy, y1, dy))
           for xs in [np.arange(x0 + (0.25 if r % 2 else 0.75) * h, x1, h)]]
    interior = np.concatenate(pts) if pts else np.zeros((0, 2))
    if not len(interior):
        return interior
    interior = interior[shapely.contains_xy(polygon, interior[:, 0], interior[:, 1])]
    if not len(interior):
        return interior
    a = np.concatenate([np.asarray(r) for r in bnd.rings])
    b = np.concatenate([np.roll(np.asarray(r), -1) for r in bnd.rings])
    lines = shapely.linestrings(np.stack([bnd.xy[a], bnd.xy[b]], axis=1))
    seg_len = np.linalg.norm(bnd.xy[b] - bnd.xy[a], axis=1)
    tree = shapely.STRtree(lines)
    (_, near), dist = tree.query_nearest(shapely.points(interior), return_distance=True, all_matches=False)
    interior = interior[dist >= 0.55 * np.maximum(h, seg_len[near])]
    tip = _tip_points(bnd, h)
    if len(tip) and len(interior):
        from scipy.spatial import cKDTree

        gap, _ = cKDTree(tip).query(interior)  # not an (interior, tip) table: both can be large
        interior = interior[gap >= 0.5 * h]
    return np.concatenate([interior, tip]) if len(tip) else interior


def _tip_points(bnd: _Boundary, h: float) -> np.ndarray:
    """Interior points (t, 2) in the narrow tip of a face around an apex (a cone's point).

    There the face's seam line runs out from the apex on both sides of its
    development -- the same 3D points twice, closer together than the lattice
    can fill -- and a triangle between boundary points alone would have all
    three on one straight line in 3D (zero area).  Across each pair of copies
    narrower than ``2 h``, two points are put, at a third and two thirds of the
    way, so that every triangle of the tip has a corner off the seam line.
    """
    out = []
    for ring in bnd.rings:
        ring = np.asarray(ring)
        n = len(ring)
        for i in range(n):
            for k in range(1, n // 2):
                left, right = ring[(i - k) % n], ring[(i + k) % n]
                if bnd.slot_gid[left] != bnd.slot_gid[right]:
                    break
                a, b = bnd.xy[left], bnd.xy[right]
                if np.linalg.norm(b - a) >= 2 * h:
                    break
                out += [a + (b - a) / 3, a + 2 * (b - a) / 3]
    return np.array(out).reshape(-1, 2)


def _triangulate(points: np.ndarray, polygon, nb: int, h: float, where: str) -> np.ndarray:
    """Delaunay triangles (m, 3) of ``points`` inside ``polygon``, counter-clockwise; slivers dropped."""
    import shapely
    from scipy.spatial import Delaunay

    try:
        tri = Delaunay(points).simplices.astype(np.int64)
    except Exception as exc:  # noqa: BLE001 - qhull errors
        raise CadError(f"{where} could not be triangulated ({exc})") from None
    p = points[tri]
    area2 = ((p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
             - (p[:, 1, 1] - p[:, 0, 1]) * (p[:, 2, 0] - p[:, 0, 0]))
    tri[area2 < 0] = tri[area2 < 0][:, [0, 2, 1]]
    centre = p.mean(axis=1)
    keep = shapely.contains_xy(polygon, centre[:, 0], centre[:, 1]) & (np.abs(area2) > 1e-12 * h * h)
    # A sliver across three boundary points on a straight boundary (a seam
    # line) has its centre on the boundary itself: it is not inside.
    keep &= ~(np.all(tri < nb, axis=1) & (np.abs(area2) < 1e-6 * h * h))
    return tri[keep]


def _lost_edges(tri: np.ndarray, segs: np.ndarray, bnd: _Boundary, degenerate, n_points: int):
    """None if every boundary segment is a triangle edge; else the (non-degenerate) edges they lie on."""
    have = unique_ints(np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
                       @ np.array([n_points, 1]))
    need = np.sort(segs, axis=1) @ np.array([n_points, 1])
    missing = ~np.isin(need, have)
    if not missing.any():
        return None
    bad = set(segs[missing].ravel().tolist())
    return {e for (e, _), slots in zip(bnd.occurrences, bnd.occ_slots)
            if not degenerate[e] and bad & set(slots.tolist())}
