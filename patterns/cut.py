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
    corner_angles,
    edge_graph,
    edge_tables,
    trace_loops,
)

__all__ = ["Cut", "cut_along", "cut_to_disk", "pieces"]


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


def pieces(faces: np.ndarray, n_vertices: int, *, name: str = "mesh") -> list[np.ndarray]:
    """Split faces into connected pieces (joined through shared edges).

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
    pairs = t.edge_faces[t.edge_faces[:, 1] >= 0]
    m = len(faces)
    adjacency = sp.coo_matrix((np.ones(len(pairs), dtype=np.int8), (pairs[:, 0], pairs[:, 1])), shape=(m, m))
    n, label = csgraph.connected_components(adjacency, directed=False)
    order = np.argsort(label, kind="stable")
    groups = np.split(order, np.cumsum(np.bincount(label, minlength=n))[:-1])
    groups.sort(key=lambda g: g[0])
    return groups


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
        One piece (see :func:`pieces`).
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
    """Cut a mesh along one path of edges (a slit or a dart from the boundary).

    Parameters
    ----------
    vertices : (n, 3) float64
    faces : (m, 3) int64
    path : (p,) int64
        Vertex indices joined by mesh edges; where it starts or ends on the
        boundary the cut opens there, where it ends inside the surface the slit
        stops.
    name : str

    Returns
    -------
    Cut
        The input vertices keep their indices; the copies on the cut's second
        side come after them.
    """
    path = np.asarray(path, dtype=np.int64)
    t = edge_tables(faces, len(vertices), name=name)
    return _cut_along(vertices, faces, t, [path])
