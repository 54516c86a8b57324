"""The greedy region grower of Li & Xue, and its length-preserving variant.

The grower lays a seed triangle flat without distortion, then repeatedly places
a free vertex that shares a triangle edge with the flattened patch.  Each
triangle ``(a, b, c)`` incident to the free vertex ``c`` whose other corners
``a, b`` are already flat proposes a *candidate* position for ``c``; the vertex
goes to the area-weighted mean of its candidates.

How a triangle proposes its candidate is the *step*:

* :func:`similarity_step` -- the paper's step: the Cauchy-Riemann equations
  (eqs. 10-11) of the triangle's linear map with ``a`` and ``b`` fixed.  Their
  unique solution is the similarity that takes the triangle's edge ``ab`` onto
  the flat ``ab``: the triangle is scaled by ``|ab|_flat / |ab|_3d``.  Any length
  error in the front is therefore copied, as a scale factor, into every triangle
  built on it.
* :func:`rigid_step` -- the triangle keeps its true 3D shape and size and is
  rotated so that its edge ``ab`` lies along the flat ``ab``, centred on its
  midpoint.  Length errors of the front are not multiplied, but the rotation is
  read off the flat edge, i.e. off a *difference* of two placed positions.
* :func:`transported_step` -- the triangle keeps its true shape and size, is
  centred on the flat ``ab`` midpoint, and takes its rotation from a frame
  field carried across the mesh from the seed (:func:`transported_rotations`),
  not from the flat edge.  A vertex is then a convex combination of placed
  positions plus fixed offsets, and no error is amplified.

Why the first two are unstable.  Growing a flat patch outward from a front is
solving the Cauchy problem of an elliptic system (the Cauchy-Riemann equations
for :func:`similarity_step`, their isometric counterpart for :func:`rigid_step`),
which is ill-posed in Hadamard's sense: a wiggle of wavenumber ``k`` along the
front grows like ``exp(k d)`` after marching a distance ``d``.  Discretely, each
step turns a difference of neighbouring position errors (a derivative of the
noise) into the next triangle's scale (similarity) or rotation (rigid), so the
highest-frequency error modes gain a fixed factor per ring; the number of rings
grows with resolution, so a finer mesh flattens worse.  Taking the rotation from
the frame field removes every difference from the update, and the strain then
converges as the mesh is refined (measured in ``docs/algorithm.md``).

How the free vertices are ordered is the *growth*:

* :func:`grow_heap` -- the paper's order: one vertex at a time, always the one
  whose addition keeps the front (the patch's boundary) shortest; a binary heap
  with lazy updates, ``O(n log n)``, a Python loop.
* :func:`grow_fronts` -- the paper's other description ("examines all the
  triangles adjacent to the front-patch ... then redefines the front-patch"):
  every free vertex adjacent to the front is placed at once from the current
  patch, the front is redefined, and so on.  Each front is one vectorised numpy
  pass, so a million faces take a few hundred passes.
"""

from __future__ import annotations

import heapq
from collections.abc import Callable

import numpy as np
from scipy.sparse import coo_matrix, csgraph

from ..errors import FlattenError
from ..mesh import Connectivity, edge_graph, unique_ints

__all__ = [
    "grow_fronts",
    "grow_heap",
    "rigid_step",
    "seed_face",
    "seed_layout",
    "similarity_step",
    "transported_rotations",
    "transported_step",
]

Step = Callable[..., complex]


def similarity_step(za, zb, zc, wa, wb, r=None):
    """Candidate for ``c`` by the paper's Cauchy-Riemann step.

    Parameters
    ----------
    za, zb, zc : complex or (k,) complex128
        The triangle's corners in its own frame; ``(a, b, c)`` counter-clockwise.
    wa, wb : complex or (k,) complex128
        Flat positions of ``a`` and ``b``.
    r : complex or (k,) complex128, optional
        The triangle's frame rotation (unit); used by :func:`transported_step` only.

    Returns
    -------
    complex or (k,) complex128
        The flat position of ``c`` that makes the triangle's map conformal
        (a similarity): ``wa + (wb - wa) (zc - za) / (zb - za)``.
    """
    return wa + (wb - wa) * ((zc - za) / (zb - za))


def rigid_step(za, zb, zc, wa, wb, r=None):
    """Candidate for ``c`` from the triangle at its true size.

    The triangle is rotated so that its edge ``ab`` points along the flat
    ``wb - wa`` and translated so that the edge midpoints coincide.

    Parameters and return as :func:`similarity_step`.
    """
    r = (wb - wa) / (zb - za)
    r = r / abs(r)
    return 0.5 * (wa + wb) + r * (zc - 0.5 * (za + zb))


def transported_step(za, zb, zc, wa, wb, r):
    """Candidate for ``c`` from the triangle at its true size, rotated by ``r``.

    The triangle's own frame is turned by the unit complex ``r`` (from
    :func:`transported_rotations`) and its edge midpoint put on the flat midpoint
    of ``ab``.  Parameters and return as :func:`similarity_step`.
    """
    return 0.5 * (wa + wb) + r * (zc - 0.5 * (za + zb))


def transported_rotations(z: np.ndarray, faces: np.ndarray, conn: Connectivity, seed: int) -> np.ndarray:
    """A frame rotation for every triangle, carried from the seed across edges.

    Along a breadth-first tree of the triangles (neighbours through shared
    edges, rooted at ``seed``) each child is unfolded about the edge it shares
    with its parent: the rotation of its frame is the parent's, turned by the
    angle between the shared edge as seen in the two frames (the discrete
    Levi-Civita transport).  On a developable mesh this unfolds every triangle
    exactly; on a curved one the rotations differ from an ideal by the
    curvature enclosed between tree paths (the holonomy), which is small for
    gently curved parts.

    Parameters
    ----------
    z : (m, 3) complex128
        Triangles in their own frames.
    faces : (m, 3) int64
    conn : Connectivity
    seed : int

    Returns
    -------
    (m,) complex128
        Unit complex numbers; the seed's matches :func:`seed_layout`.
    """
    m = len(faces)
    ef = conn.edge_faces
    inner = ef[:, 1] >= 0
    dual = coo_matrix((np.ones(int(inner.sum()), dtype=np.int8), (ef[inner, 0], ef[inner, 1])), shape=(m, m)).tocsr()
    _, pred = csgraph.breadth_first_order(dual, seed, directed=False, return_predecessors=True)
    idx = np.arange(m)
    fe = conn.face_edges
    sides = ef[fe]  # (m, 3, 2): the two faces of each side
    across = np.where(sides[..., 0] == idx[:, None], sides[..., 1], sides[..., 0])
    child = idx[pred >= 0]
    parent = pred[child]
    k = np.argmax(across[child] == parent[:, None], axis=1)
    p, q = faces[child, k], faces[child, (k + 1) % 3]
    d_child = z[child, (k + 1) % 3] - z[child, k]
    of_parent = faces[parent]
    d_parent = z[parent, np.argmax(of_parent == q[:, None], axis=1)] - z[parent, np.argmax(of_parent == p[:, None], axis=1)]
    delta = np.zeros(m)
    delta[child] = np.angle(d_parent) - np.angle(d_child)
    delta[seed] = -np.angle(z[seed, 1] - z[seed, 0])
    # Sum the angles along every tree path by pointer jumping (log2(depth) passes).
    anc = pred.copy()
    anc[seed] = seed
    acc = delta.copy()
    acc[seed] = 0.0
    while np.any(anc != seed):
        acc += acc[anc] * (anc != seed)
        anc = anc[anc]
    acc += delta[seed]
    return np.exp(1j * acc)


def seed_face(vertices: np.ndarray, faces: np.ndarray, conn: Connectivity) -> int:
    """The face farthest from the boundary (geodesic along edges, 3D lengths).

    Returns
    -------
    int
        Index of the face whose corners have the largest summed edge-path
        distance to the nearest boundary vertex (the lowest index among
        faces within round-off of it).
    """
    graph = edge_graph(vertices, conn.edges)
    sources = unique_ints(np.concatenate(conn.loops))
    dist = csgraph.dijkstra(graph, directed=False, indices=sources, min_only=True)
    depth = dist[faces].sum(axis=1)
    # Faces as deep as the deepest up to round-off (a symmetric part has many)
    # are ties: the first of them, not whichever round-off favours.
    return int(np.flatnonzero(depth >= depth.max() * (1.0 - 1e-9))[0])


def seed_layout(z_seed: np.ndarray) -> np.ndarray:
    """Flat corners of the seed triangle: corner 0 at the origin, corner 1 on +u.

    Parameters
    ----------
    z_seed : (3,) complex128
        The seed triangle in its own frame.

    Returns
    -------
    (3,) complex128
        An exact (distortion-free) copy of the triangle.
    """
    w = z_seed - z_seed[0]
    return w * (np.conj(w[1]) / abs(w[1]))


def grow_fronts(z: np.ndarray, faces: np.ndarray, conn: Connectivity, weights: np.ndarray,
                seed: int, step: Step, *, rotations: np.ndarray | None = None, progress=None) -> np.ndarray:
    """Grow the flat patch front by front, each front in one vectorised pass.

    Parameters
    ----------
    z : (m, 3) complex128
        Every triangle in its own frame (:func:`patterns.measure.local_coordinates`).
    faces : (m, 3) int64
    conn : Connectivity
    weights : (m,) float64
        Weight of each triangle's candidate (its 3D area).
    seed : int
        Seed face.
    step : callable
        :func:`similarity_step`, :func:`rigid_step` or :func:`transported_step`.
    rotations : (m,) complex128, optional
        Frame rotations, required by :func:`transported_step`.
    progress : callable, optional
        Called as ``progress(n_placed, n_total)`` after each front.

    Returns
    -------
    (n,) complex128
        Flat position of every vertex, ``u + iv``.
    """
    n = conn.n_vertices
    m = len(faces)
    ptr, vfaces = conn.vertex_faces_ptr, conn.vertex_faces
    w = np.zeros(n, dtype=np.complex128)
    placed = np.zeros(n, dtype=bool)
    count = np.zeros(m, dtype=np.int8)
    new = faces[seed].copy()
    w[new] = seed_layout(z[seed])
    placed[new] = True
    n_placed = 3
    while True:
        # Faces around the vertices just placed; those with exactly one free
        # corner left form the next front.
        start, stop = ptr[new], ptr[new + 1]
        lens = stop - start
        idx = np.repeat(start - np.cumsum(lens) + lens, lens) + np.arange(lens.sum())
        # Each face met once with how many of its corners came now (a sort, not ``np.add.at``: a
        # million-face cap's fronts counted in a fifth of the time); the next front sorted, as before.
        inc = np.sort(vfaces[idx])
        first = np.flatnonzero(np.r_[True, inc[1:] != inc[:-1]]) if len(inc) else np.zeros(0, dtype=np.int64)
        met = inc[first]
        count[met] += np.diff(np.r_[first, len(inc)]).astype(np.int8)
        ready = met[count[met] == 2]
        if len(ready) == 0:
            break
        fr = faces[ready]
        j = np.argmin(placed[fr], axis=1)
        rows = np.arange(len(ready))
        ja, jb = (j + 1) % 3, (j + 2) % 3
        zr = z[ready]
        rot = None if rotations is None else rotations[ready]
        cand = step(zr[rows, ja], zr[rows, jb], zr[rows, j], w[fr[rows, ja]], w[fr[rows, jb]], rot)
        free = fr[rows, j]
        new, inv = unique_ints(free, return_inverse=True)
        wt = weights[ready]
        total = np.bincount(inv, wt)
        w[new] = (np.bincount(inv, wt * cand.real) + 1j * np.bincount(inv, wt * cand.imag)) / total
        placed[new] = True
        n_placed += len(new)
        if progress is not None:
            progress(n_placed, n)
    if n_placed != n:  # pragma: no cover - validate_mesh guarantees edge-connectivity
        raise FlattenError(f"the grower reached {n_placed} of {n} vertices")
    return w


def grow_heap(z: np.ndarray, faces: np.ndarray, conn: Connectivity, weights: np.ndarray,
              seed: int, step: Step, *, rotations: np.ndarray | None = None, progress=None) -> np.ndarray:
    """Grow the flat patch one vertex at a time, keeping the front shortest.

    The next vertex is the free vertex adjacent to the patch (through a triangle
    edge) whose addition increases the front's 3D length least.  Front lengths
    are compared on a grid of 1e-6 of the mean edge length, and ties go to the
    lowest vertex index, so that round-off (from a rigid motion of the input,
    say) cannot change the order on a regular mesh, where exact ties abound.
    Parameters and return as :func:`grow_fronts`.
    """
    n = conn.n_vertices
    front = _ShortestFront(z, faces, conn, weights, rotations)
    front.start(seed, seed_layout(z[seed]).tolist())
    n_placed = 3
    every = max(1, n // 100)
    while front.heap:
        _, v, ver = heapq.heappop(front.heap)
        if front.pos[v] is not None or ver != front.version[v]:
            continue
        front.place(v, front.candidate(v, step))
        n_placed += 1
        if progress is not None and n_placed % every == 0:
            progress(n_placed, n)
    if n_placed != n:  # pragma: no cover - validate_mesh guarantees edge-connectivity
        raise FlattenError(f"the grower reached {n_placed} of {n} vertices")
    if progress is not None:
        progress(n, n)
    return np.asarray(front.pos, dtype=np.complex128)


class _ShortestFront:
    """The state of :func:`grow_heap`: placed positions, the heap of candidates, per-face counts (Python lists)."""

    def __init__(self, z, faces, conn, weights, rotations):
        n = conn.n_vertices
        self.faces = faces.tolist()
        self.z = z.tolist()
        self.w = weights.tolist()
        self.r = [None] * len(self.faces) if rotations is None else rotations.tolist()
        self.ptr = conn.vertex_faces_ptr.tolist()
        self.vf = conn.vertex_faces.tolist()
        self.pos: list = [None] * n
        self.count = [0] * len(self.faces)
        self.version = [0] * n
        self.heap: list = []
        self.quantum = 1e-6 * float(np.mean(np.abs(z[:, 1] - z[:, 0])))

    def faces_of(self, v):
        return self.vf[self.ptr[v]:self.ptr[v + 1]]

    def ready_faces(self, v):
        """``[(face, corner of v)]``: the faces of ``v`` whose two other corners are placed."""
        return [(f, self.faces[f].index(v)) for f in self.faces_of(v) if self.count[f] == 2]

    def key(self, v):
        """How much placing ``v`` lengthens the front (3D), on the grid of ``quantum``."""
        added: dict = {}
        delta = 0.0
        for f, j in self.ready_faces(v):
            zf, tri = self.z[f], self.faces[f]
            za, zb, zc = zf[(j + 1) % 3], zf[(j + 2) % 3], zf[j]
            delta -= abs(zb - za)
            for other, zo in ((tri[(j + 1) % 3], za), (tri[(j + 2) % 3], zb)):
                added[other] = (added.get(other, (0, 0.0))[0] + 1, abs(zc - zo))
        for k, length in added.values():
            if k == 1:
                delta += length
        return round(delta / self.quantum)

    def start(self, seed, positions):
        """Lay the seed triangle's corners at ``positions`` and queue their neighbours."""
        tri = self.faces[seed]
        for v, position in zip(tri, positions):
            self.pos[v] = position
        for v in tri:
            for f in self.faces_of(v):
                self.count[f] += 1
        for v in tri:
            for f in self.faces_of(v):
                for u in self.faces[f]:
                    if self.pos[u] is None and self.ready_faces(u):
                        self.version[u] += 1
                        heapq.heappush(self.heap, (self.key(u), u, self.version[u]))

    def place(self, v, position):
        """Put ``v`` at ``position`` and requeue its free neighbours (older entries go stale)."""
        self.pos[v] = position
        for f in self.faces_of(v):
            self.count[f] += 1
        for f in self.faces_of(v):
            for u in self.faces[f]:
                if self.pos[u] is None:
                    self.version[u] += 1
                    if self.ready_faces(u):
                        heapq.heappush(self.heap, (self.key(u), u, self.version[u]))

    def candidate(self, v, step):
        """Where ``v`` goes: the area-weighted mean of ``step`` over its ready faces."""
        total, acc = 0.0, 0j
        for f, j in self.ready_faces(v):
            zf, tri = self.z[f], self.faces[f]
            a, b = tri[(j + 1) % 3], tri[(j + 2) % 3]
            acc += self.w[f] * step(zf[(j + 1) % 3], zf[(j + 2) % 3], zf[j], self.pos[a], self.pos[b], self.r[f])
            total += self.w[f]
        return acc / total
