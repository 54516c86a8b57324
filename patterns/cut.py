"""Cutting meshes open: pieces, and seams that make a surface a flattenable disk.

A closed surface (a sphere, a box) and a tube (a duct, a sleeve: two boundary
loops that run *around* the surface) cannot be laid flat without a cut.  A disk
with real holes (a plate with a bolt hole) can, and is left alone.  The test is
the boundary's geodesic turning: walked with the surface on its left, the rim
of a hole turns by about -2 pi (it winds clockwise around the hole), the end of
a tube by about 0 (a circle on a cylinder is a geodesic).

Cuts follow the shortest path along mesh edges (3D lengths, Dijkstra): between
two far-apart vertices of a closed surface (a slit, which makes it a disk), and
from each tube end to the rest of the boundary.  Every cut is returned, so that
it can be reported and drawn as a seam.  Nothing is moved, merged or dropped:
the vertices on a cut are duplicated, one copy for each side.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse import csgraph

from .errors import MeshTopologyError
from .mesh import (
    _readonly,
    as_mesh_arrays,
    check_boundary_vertices,
    check_faces_have_area,
    corner_angles,
    edge_graph,
    edge_tables,
    trace_loops,
    unique_edges,
)

__all__ = ["Cut", "Inserted", "chains", "components", "crease_regions", "cut_along", "cut_to_disk", "insert_line",
           "is_closed", "shared_chains"]


@dataclass(frozen=True, eq=False)
class Cut:
    """A mesh cut open along seams (read-only arrays).

    Attributes
    ----------
    vertices : (k, 3) float64
        The input vertices followed by the copies made along the cuts.
    faces : (m, 3) int64
        The input faces re-indexed to the copies where they lie on a cut's
        second side.
    source : (k,) int64
        The input vertex each vertex comes from (``source[i] == i`` for
        ``i < n``).
    paths : tuple of (p,) int64
        Each cut as a path of input vertices.
    sides : tuple of ((p,) int64, (p,) int64)
        For each cut, its vertices on the left and on the right side (walking
        along the path, the surface on the left / right), indices into
        ``vertices``; equal where the cut ends inside the surface.
    """

    vertices: np.ndarray
    faces: np.ndarray
    source: np.ndarray
    paths: tuple
    sides: tuple


def components(faces: np.ndarray, n_vertices: int, *, name: str = "mesh") -> list[np.ndarray]:
    """Split faces into connected components (joined through shared edges): what a mesh file's panels are.

    Parameters
    ----------
    faces : (m, 3) int64
    n_vertices : int
    name : str
        For error messages.

    Returns
    -------
    list of (m_i,) int64
        Face indices of each piece, in order of their first face.
    """
    t = edge_tables(faces, n_vertices, name=name)
    return _face_groups(t.edge_faces[t.edge_faces[:, 1] >= 0], len(faces))


def _face_groups(pairs: np.ndarray, m: int) -> list[np.ndarray]:
    """The faces joined through the face ``pairs`` ``(k, 2)``, as groups in order of their first face."""
    adjacency = sp.coo_matrix((np.ones(len(pairs), dtype=np.int8), (pairs[:, 0], pairs[:, 1])), shape=(m, m))
    n, label = csgraph.connected_components(adjacency, directed=False)
    order = np.argsort(label, kind="stable")
    groups = np.split(order, np.cumsum(np.bincount(label, minlength=n))[:-1])
    groups.sort(key=lambda g: g[0])
    return groups


def is_closed(faces: np.ndarray, n_vertices: int, *, name: str = "mesh") -> bool:
    """True when a manifold piece has no boundary at all (a sphere, a box: it encloses a volume)."""
    return bool((edge_tables(faces, n_vertices, name=name).edge_faces[:, 1] >= 0).all())


def crease_regions(vertices: np.ndarray, faces: np.ndarray, *, angle: float, name: str = "mesh") -> list[np.ndarray]:
    """Split a piece into the regions its creases bound: edges whose two faces meet at more than ``angle``.

    Parameters
    ----------
    vertices : (n, 3) float64
    faces : (m, 3) int64
        One manifold, consistently wound piece.
    angle : float
        Degrees between the two faces' normals (0: coplanar; a box's edges: 90).
    name : str
        For error messages.

    Returns
    -------
    list of (m_i,) int64
        Face indices of each region, in order of their first face; one region
        (all faces) when no closed line of creases separates any.
    """
    t = edge_tables(faces, len(vertices), name=name)
    p = vertices[faces]
    normals = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-300)
    inner = t.edge_faces[t.edge_faces[:, 1] >= 0]
    cosine = np.einsum("ij,ij->i", normals[inner[:, 0]], normals[inner[:, 1]])
    return _face_groups(inner[cosine >= np.cos(np.radians(angle))], len(faces))


def shared_chains(faces: np.ndarray, groups: list) -> list[tuple[int, int, np.ndarray]]:
    """The lines along which regions of one mesh meet: ``(region a, region b, path)`` with ``a < b``.

    Parameters
    ----------
    faces : (m, 3) int64
    groups : list of (m_i,) int64
        A partition of the faces into regions (see :func:`crease_regions`).

    Returns
    -------
    list of (int, int, (p,) int64)
        Each maximal chain of edges between the same two regions, as a path of
        vertex indices; it ends where three regions meet, or is closed (its
        first vertex repeated at the end).
    """
    region = np.empty(len(faces), dtype=np.int64)
    for k, g in enumerate(groups):
        region[g] = k
    t = edge_tables(faces, int(faces.max()) + 1)
    inner = t.edge_faces[:, 1] >= 0
    ra, rb = region[t.edge_faces[:, 0]], np.where(inner, region[np.maximum(t.edge_faces[:, 1], 0)], -1)
    between = inner & (ra != rb)
    out = []
    pairs = np.stack([np.minimum(ra, rb), np.maximum(ra, rb)], axis=1)[between]
    edges = t.edges[between]
    for a, b in _unique_pairs(pairs):
        chosen = edges[(pairs[:, 0] == a) & (pairs[:, 1] == b)]
        out += [(int(a), int(b), path) for path in chains(chosen)]
    return out


def _unique_pairs(pairs: np.ndarray) -> np.ndarray:
    """The distinct rows of an ``(k, 2)`` int array, sorted."""
    return np.unique(pairs, axis=0) if len(pairs) else pairs.reshape(0, 2)


def chains(edges: np.ndarray) -> list[np.ndarray]:
    """Edges ``(k, 2)`` int64 joined into maximal vertex paths ((p,) int64: split where a vertex has other than
    two), then cycles (first vertex repeated last)."""
    neighbours: dict = {}
    for a, b in edges.tolist():
        neighbours.setdefault(a, []).append(b)
        neighbours.setdefault(b, []).append(a)
    used = set()
    paths = []

    def walk(start, nxt):
        path = [start]
        prev, cur = start, nxt
        used.add(frozenset((start, nxt)))
        while True:
            path.append(cur)
            if len(neighbours[cur]) != 2 or cur == start:
                return path
            step = [w for w in neighbours[cur] if frozenset((cur, w)) not in used]
            if not step:
                return path
            prev, cur = cur, step[0]
            used.add(frozenset((prev, cur)))

    for v in sorted(neighbours):
        if len(neighbours[v]) != 2:
            for w in neighbours[v]:
                if frozenset((v, w)) not in used:
                    paths.append(np.array(walk(v, w), dtype=np.int64))
    for v in sorted(neighbours):
        for w in neighbours[v]:
            if frozenset((v, w)) not in used:
                paths.append(np.array(walk(v, w), dtype=np.int64))  # a cycle: back at its start
    return paths


def loop_turning(vertices: np.ndarray, faces: np.ndarray, loop: np.ndarray) -> float:
    """Geodesic turning of a boundary loop: ``sum over its vertices of (pi - corner angles)``.

    Parameters
    ----------
    vertices : (n, 3) float64
    faces : (m, 3) int64
    loop : (k,) int64
        Vertex indices, the surface on the left.

    Returns
    -------
    float
        Radians: about ``+2 pi`` for the rim of a flat disk, ``-2 pi`` for a
        hole in it, 0 for the end of a straight tube.
    """
    total = np.bincount(faces.ravel(), corner_angles(vertices, faces).ravel(), len(vertices))
    return float(np.sum(np.pi - total[loop]))


def cut_to_disk(vertices: np.ndarray, faces: np.ndarray, *, name: str = "mesh") -> Cut:
    """Cut one connected, consistently wound, manifold surface into a flattenable domain.

    Parameters
    ----------
    vertices : (n, 3) float64
    faces : (m, 3) int64
        One component (see :func:`components`).
    name : str
        For error messages.

    Returns
    -------
    Cut
        With no paths when the surface already is a disk or a disk with holes.

    Raises
    ------
    MeshTopologyError
        A closed surface or tube with handles (genus > 0), which one cut cannot
        open; or a cut that could not be routed.
    """
    vertices, faces = as_mesh_arrays(vertices, faces, name=name)  # array_like in; checked shapes and values
    check_faces_have_area(vertices, faces, name=name)
    n, m = len(vertices), len(faces)
    t = edge_tables(faces, n, name=name)
    check_boundary_vertices(t, n, name=name)
    interior = t.edge_faces[:, 1] >= 0
    chi = n - len(t.edges) + m
    if interior.all():
        if chi != 2:
            raise MeshTopologyError(f"{name}: closed surface with handles (Euler characteristic {chi}); "
                                    f"cut it into disks first")
        paths = [_slit(vertices, t)]
    else:
        loops = trace_loops(t.boundary_from, t.boundary_to, n)
        if 2 - len(loops) - chi != 0:
            raise MeshTopologyError(f"{name}: the surface has handles (Euler characteristic {chi} with "
                                    f"{len(loops)} boundary loops); cut it into disks first")
        around = [loop for loop in loops if loop_turning(vertices, faces, loop) > -np.pi]
        paths = _join_loops(vertices, t, around, name) if len(around) > 1 else []
    if not paths:
        v, f = vertices.copy(), faces.copy()
        return Cut(_readonly(v), _readonly(f), _readonly(np.arange(n)), (), ())
    return _cut_along(vertices, faces, t, paths)


def _edge_graph(vertices, t, keep):
    return edge_graph(vertices, t.edges[keep])


def _backtrack(pred: np.ndarray, end: int) -> np.ndarray:
    path = [end]
    while pred[path[-1]] >= 0:
        path.append(int(pred[path[-1]]))
    return np.asarray(path[::-1], dtype=np.int64)


def _slit(vertices, t) -> np.ndarray:
    """Shortest path between two far-apart vertices (two Dijkstra sweeps)."""
    graph = _edge_graph(vertices, t, np.ones(len(t.edges), dtype=bool))
    d0 = csgraph.dijkstra(graph, indices=0)
    a = int(np.argmax(np.where(np.isfinite(d0), d0, -1)))
    da, pred = csgraph.dijkstra(graph, indices=a, return_predecessors=True)
    b = int(np.argmax(np.where(np.isfinite(da), da, -1)))
    return _backtrack(pred, b)


def _join_loops(vertices, t, loops, name) -> list[np.ndarray]:
    """Shortest interior paths joining each loop to those joined before it."""
    graph = _edge_graph(vertices, t, t.edge_faces[:, 1] >= 0)  # never along the boundary
    joined = loops[0]
    paths = []
    for loop in loops[1:]:
        dist, pred, _ = csgraph.dijkstra(graph, indices=loop, min_only=True, return_predecessors=True)
        reach = dist[joined]
        if not np.isfinite(reach).any():
            raise MeshTopologyError(f"{name}: no interior path joins two boundary loops; cannot cut it open")
        end = int(joined[np.argmin(reach)])
        paths.append(_backtrack(pred, end))
        joined = np.concatenate([joined, loop, paths[-1]])
    return paths


def _cut_along(vertices, faces, t, paths) -> Cut:
    """Duplicate the vertices on the paths, one copy per side of the cut.

    The corners of the faces around each vertex are joined across every edge
    that is not cut; each group of joined corners becomes one vertex.
    """
    n, m = len(vertices), len(faces)
    # Directed half-edges a -> b, sorted by key a * n + b, with their faces.
    half_key = (faces * n + np.roll(faces, -1, axis=1)).ravel()
    half_order = np.argsort(half_key)
    half_sorted = half_key[half_order]

    def face_left_of(a, b):
        """Faces holding the directed edges a -> b (-1 where none: the boundary)."""
        k = np.asarray(a) * n + np.asarray(b)
        pos = np.minimum(np.searchsorted(half_sorted, k), len(half_sorted) - 1)
        return np.where(half_sorted[pos] == k, half_order[pos] // 3, -1)

    edge_key = t.edges[:, 0] * n + t.edges[:, 1]
    lo, hi = t.edges[:, 0], t.edges[:, 1]
    cut = np.zeros(len(t.edges), dtype=bool)
    for path in paths:
        a, b = np.minimum(path[:-1], path[1:]), np.maximum(path[:-1], path[1:])
        cut[np.searchsorted(edge_key, a * n + b)] = True
    joined = (t.edge_faces[:, 1] >= 0) & ~cut
    f1, f2 = t.edge_faces[joined, 0], t.edge_faces[joined, 1]
    rows, cols = [], []
    for end in (lo[joined], hi[joined]):
        k1 = np.argmax(faces[f1] == end[:, None], axis=1)
        k2 = np.argmax(faces[f2] == end[:, None], axis=1)
        rows.append(3 * f1 + k1)
        cols.append(3 * f2 + k2)
    rows, cols = np.concatenate(rows), np.concatenate(cols)
    graph = sp.coo_matrix((np.ones(len(rows), dtype=np.int8), (rows, cols)), shape=(3 * m, 3 * m))
    _, label = csgraph.connected_components(graph, directed=False)
    corner_vertex = faces.ravel()
    # Each label becomes a vertex: the first label met for an input vertex keeps
    # its index, the others are appended in order.
    first_corner = np.full(label.max() + 1, 3 * m, dtype=np.int64)
    np.minimum.at(first_corner, label, np.arange(3 * m))
    label_source = corner_vertex[first_corner]
    order = np.lexsort((first_corner, label_source))
    new_index = np.empty(len(order), dtype=np.int64)
    is_first = np.ones(len(order), dtype=bool)
    is_first[1:] = label_source[order][1:] != label_source[order][:-1]
    new_index[order[is_first]] = label_source[order[is_first]]
    extra = order[~is_first]
    new_index[extra] = n + np.arange(len(extra))
    source = np.concatenate([np.arange(n), label_source[extra]])
    new_faces = new_index[label].reshape(m, 3)
    sides = []
    for path in paths:
        # Walking p -> next along the path, the face holding the directed edge
        # p -> next is on the left, the one holding next -> p on the right; at
        # the last vertex look back along the last edge instead.
        p = np.asarray(path)
        nxt = np.r_[p[1:], p[-2]]
        forward = np.r_[np.ones(len(p) - 1, dtype=bool), False]
        fa, fb = face_left_of(p, nxt), face_left_of(nxt, p)
        fa, fb = np.where(forward, fa, fb), np.where(forward, fb, fa)
        fa, fb = np.where(fa < 0, fb, fa), np.where(fb < 0, fa, fb)
        left = np.sum(new_faces[fa] * (faces[fa] == p[:, None]), axis=1)
        right = np.sum(new_faces[fb] * (faces[fb] == p[:, None]), axis=1)
        sides.append((_readonly(left.astype(np.int64)), _readonly(right.astype(np.int64))))
    return Cut(_readonly(vertices[source].copy()), _readonly(new_faces), _readonly(source),
               tuple(_readonly(np.asarray(p, dtype=np.int64)) for p in paths), tuple(sides))


def cut_along(vertices: np.ndarray, faces: np.ndarray, path, *, name: str = "mesh") -> Cut:
    """Cut a mesh along paths of edges (slits, or darts from the boundary).

    Parameters
    ----------
    vertices : (n, 3) float64
    faces : (m, 3) int64
    path : (p,) int64, or a sequence of them
        Vertex indices joined by mesh edges; where a path starts or ends on
        the boundary the cut opens there, where it ends inside the surface
        the slit stops.  Several paths are cut at once.
    name : str

    Returns
    -------
    Cut
        The input vertices keep their indices; the copies on the cuts'
        second sides come after them.
    """
    paths = [path] if np.ndim(path[0]) == 0 else list(path)
    paths = [np.asarray(p, dtype=np.int64) for p in paths]
    t = edge_tables(faces, len(vertices), name=name)
    return _cut_along(vertices, faces, t, paths)


@dataclass(frozen=True, eq=False)
class Inserted:
    """A mesh with a line inserted along its edges (read-only arrays).

    Attributes
    ----------
    vertices : (k, 3) float64
        The input vertices followed by the points made where the line crosses
        an edge (on that edge: the surface is unchanged).
    faces : (m', 3) int64
        The input faces, those the line crosses split along it (winding kept).
    uv : (k, 2) float64
        The layout, extended to the new points the same way.
    path : (p,) int64
        The line as a path of vertices joined by edges of ``faces``, from
        ``start`` towards ``end``.
    """

    vertices: np.ndarray
    faces: np.ndarray
    uv: np.ndarray
    path: np.ndarray


def insert_line(vertices: np.ndarray, faces: np.ndarray, uv: np.ndarray, start, end, *,
                snap: float = 0.1, keep_off=None) -> Inserted:
    """Insert the straight line from ``start`` to ``end`` of a layout into the mesh as a path of edges.

    A dart is drawn straight on a pattern; cut along the mesh's own edges it
    would zigzag, and the triangles along a zigzag leg are strained for
    nothing.  Where the segment crosses an edge a vertex is put on that edge
    (by linear interpolation, in 3D and in the layout: the surface does not
    move), and each crossed triangle is split along the segment.  A vertex
    closer to the segment than ``snap`` times its edges' mean flat length is
    taken onto the path instead (no sliver triangles).  ``snap`` trades the
    two: at 0.25 a dart's legs jog visibly (measured on the cup: each leg
    turns 4-8 rad in all, a zigzag), at 0.02 the slivers strain (a hemisphere's
    worst triangle 11 %), at 0.1 legs turn 1-2 rad and the strain is that of
    the surface.

    Parameters
    ----------
    vertices : (n, 3) float64
    faces : (m, 3) int64
        Counter-clockwise in ``uv``.
    uv : (n, 2) float64
        A one-to-one layout of the mesh (a flattening).
    start, end : (2,) float
        The segment, in the layout's coordinates; the path runs from the
        first crossing after ``start`` to the last before ``end``.
    snap : float
        In [0, 0.5).
    keep_off : (k,) int, optional
        Vertices never taken onto the path by snapping (those of lines put
        in before, so that two lines share no vertex).

    Returns
    -------
    Inserted
    """
    v, f, uv = np.asarray(vertices, dtype=np.float64), np.asarray(faces, dtype=np.int64), np.asarray(uv, np.float64)
    a, d = np.asarray(start, dtype=np.float64), np.asarray(end, dtype=np.float64) - np.asarray(start, dtype=np.float64)
    n = len(v)
    edges = unique_edges(f)
    flat_len = np.linalg.norm(uv[edges[:, 1]] - uv[edges[:, 0]], axis=1)
    mean_len = np.bincount(edges.ravel(), weights=np.repeat(flat_len, 2), minlength=n) / np.maximum(
        np.bincount(edges.ravel(), minlength=n), 1)
    length2 = float(d[0] * d[0] + d[1] * d[1])  # written out: a BLAS product rounds by the CPU's kernels
    rel = uv - a
    t_vertex = (rel[:, 0] * d[0] + rel[:, 1] * d[1]) / length2
    off = np.abs(rel[:, 0] * d[1] - rel[:, 1] * d[0]) / np.sqrt(length2)
    on_line = (off < snap * mean_len) & (t_vertex >= 0) & (t_vertex <= 1)
    if keep_off is not None:
        on_line[np.asarray(keep_off, dtype=np.int64)] = False
    # The start and the end themselves, when they are vertices: to round-off (``a + d`` may miss the end's
    # vertex in the last bit, which would then be crossed through its own edges).
    at_end = 1e-12 * np.sqrt(length2)
    on_line |= np.linalg.norm(rel, axis=1) <= at_end
    on_line |= np.linalg.norm(uv - np.asarray(end, dtype=np.float64), axis=1) <= at_end
    p, e = uv[edges[:, 0]], uv[edges[:, 1]] - uv[edges[:, 0]]
    denom = d[0] * e[:, 1] - d[1] * e[:, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        q = p - a
        t_edge = (q[:, 0] * e[:, 1] - q[:, 1] * e[:, 0]) / denom
        s_edge = (q[:, 0] * d[1] - q[:, 1] * d[0]) / denom
    crossed = ((denom != 0) & (t_edge >= 0) & (t_edge <= 1) & (s_edge > 0) & (s_edge < 1)
               & ~on_line[edges[:, 0]] & ~on_line[edges[:, 1]])
    cross_edges, cross_s, cross_t = edges[crossed], s_edge[crossed], t_edge[crossed]
    new_ids = n + np.arange(len(cross_edges))
    lo, hi = cross_edges[:, 0], cross_edges[:, 1]
    v_new = v[lo] + cross_s[:, None] * (v[hi] - v[lo])
    uv_new = uv[lo] + cross_s[:, None] * (uv[hi] - uv[lo])
    point_of = {(int(x), int(y)): int(k) for x, y, k in zip(lo, hi, new_ids)}
    out_faces = _split_faces(f, point_of, np.vstack([uv, uv_new]))
    stops = np.concatenate([np.flatnonzero(on_line), new_ids])
    order = np.argsort(np.concatenate([t_vertex[on_line], cross_t]), kind="stable")
    path = _joined(stops[order], out_faces, n + len(new_ids), np.vstack([v, v_new]))
    vertices_out, uv_out = np.vstack([v, v_new]), np.vstack([uv, uv_new])
    return Inserted(_readonly(vertices_out), _readonly(out_faces), _readonly(uv_out), _readonly(path))


def _split_faces(faces: np.ndarray, point_of: dict, uv: np.ndarray) -> np.ndarray:
    """Split every face with a new point on one or two of its edges (winding kept, order kept).

    Only the faces the line crosses are visited in Python; the others are kept as they are.
    """
    if not point_of:
        return faces.copy()
    n = len(uv)
    lo, hi = np.minimum(faces, np.roll(faces, -1, axis=1)), np.maximum(faces, np.roll(faces, -1, axis=1))
    keys = np.array([a * n + b for a, b in point_of], dtype=np.int64)  # side k of a face runs corner k -> k + 1
    touched = np.flatnonzero(np.isin(lo * n + hi, keys).any(axis=1))
    plans = []  # per face crossed: (index, [triangles]) or (index, (kept, first, second)) to choose from
    for i, face in zip(touched.tolist(), faces[touched].tolist()):
        marks = []
        for k in range(3):
            x, y = face[k], face[(k + 1) % 3]
            point = point_of.get((min(x, y), max(x, y)))
            if point is not None:
                marks.append((k, point))
        if len(marks) == 1:
            (k, pt), = marks
            x, y, z = face[k], face[(k + 1) % 3], face[(k + 2) % 3]
            plans.append((i, [[x, pt, z], [pt, y, z]]))
        elif len(marks) == 2:
            (k1, p1), (k2, p2) = marks
            if k2 != (k1 + 1) % 3:  # the points lie on edges k2 and k1: start from the earlier
                (k1, p1), (k2, p2) = (k2, p2), (k1, p1)
            x, y, z = face[k1], face[(k1 + 1) % 3], face[(k1 + 2) % 3]  # p1 on x-y, p2 on y-z
            plans.append((i, ([p1, y, p2], [[x, p1, p2], [x, p2, z]], [[x, p1, z], [p1, p2, z]])))
        else:  # a straight line crosses a triangle's sides at most twice
            raise MeshTopologyError("a straight line crossed all three sides of a triangle")
    choices = [tris for _, tris in plans if isinstance(tris, tuple)]
    # the quad beside the point on two sides split by the diagonal that keeps the larger smallest angle
    # (the first on a tie): every candidate's angles at once
    angles = _min_angles(uv[np.array([t for _, first, second in choices for t in (*first, *second)],
                                     dtype=np.int64).reshape(-1, 3)]) if choices else np.zeros(0)
    out, kept_from, c = [], 0, 0
    for i, tris in plans:
        out.append(faces[kept_from:i])  # the faces before this one, in their order
        kept_from = i + 1
        if isinstance(tris, tuple):
            kept, first, second = tris
            a = min(angles[4 * c], angles[4 * c + 1])
            b = min(angles[4 * c + 2], angles[4 * c + 3])
            c += 1
            tris = [kept, *(second if b > a else first)]
        out.append(np.array(tris))
    out.append(faces[kept_from:])
    return np.concatenate(out).astype(np.int64).reshape(-1, 3)


def _min_angles(points: np.ndarray) -> np.ndarray:
    """Smallest corner angle of each triangle ``points`` (k, 3, 2), radians (k,)."""
    s = np.roll(points, -1, axis=1) - points
    lengths = np.linalg.norm(s, axis=2)
    cos = -(s * np.roll(s, 1, axis=1)).sum(axis=2) / np.maximum(lengths * np.roll(lengths, 1, axis=1), 1e-300)
    return np.arccos(np.clip(cos, -1.0, 1.0)).min(axis=1)


def _joined(stops: np.ndarray, faces: np.ndarray, n: int, vertices: np.ndarray) -> np.ndarray:
    """The stops in order, joined by the shortest edge path wherever two in a row share no edge."""
    edges = unique_edges(faces)
    # whether each two stops in a row share an edge, all at once (a set of every edge's pair took a dart
    # search a third of its cutting time): sorted int64 keys, as unique_edges orders them
    size = max(n, int(faces.max()) + 1 if len(faces) else 1, int(np.max(stops)) + 1 if len(stops) else 1)
    keys = edges[:, 0] * size + edges[:, 1]

    def adjacent(a, b):  # (k,) int64 each: whether a[i]-b[i] is an edge
        key = np.minimum(a, b).astype(np.int64) * size + np.maximum(a, b).astype(np.int64)
        at = np.minimum(np.searchsorted(keys, key), max(len(keys) - 1, 0))
        return (keys[at] == key) if len(keys) else np.zeros(len(key), dtype=bool)

    near = adjacent(stops[:-1], stops[1:])
    path = [int(stops[0])] if len(stops) else []
    graph = None
    for k, nxt in enumerate(stops[1:].tolist()):
        # path[-1] is the stop before, but where a shortest path found no way to it
        if near[k] if path[-1] == stops[k] else adjacent(np.array([path[-1]]), np.array([nxt]))[0]:
            path.append(nxt)
            continue
        if graph is None:
            graph = edge_graph(vertices, edges)
        _, pred = csgraph.dijkstra(graph, indices=nxt, return_predecessors=True)
        step = path[-1]
        while step != nxt and pred[step] >= 0:
            step = int(pred[step])
            path.append(step)
    return np.asarray(path, dtype=np.int64)
