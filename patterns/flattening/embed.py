"""Classic planar embeddings, used as fold-free starting layouts for the relaxation.

* :func:`tutte_embedding` -- Tutte's barycentric embedding with the boundary on
  a circle.  Guaranteed one-to-one for a disk (every interior vertex the mean
  of its neighbours, the boundary convex), but it crowds the interior of a
  strongly curved surface into a small area.
* :func:`lscm` -- least-squares conformal map with a free boundary (Lévy et
  al. 2002): angles nearly kept, so triangles keep their shapes and only their
  sizes vary.  Usually, not always, one-to-one.

Both return positions at the surface's own scale (Tutte: boundary circle as long
as the 3D boundary; LSCM: two boundary vertices pinned at their 3D distance).
"""

from __future__ import annotations

import math

import numpy as np
import qdldl
import scipy.sparse as sp

from ..measure import local_coordinates
from ..mesh import Connectivity
from .numbering import dissection_order

__all__ = ["LDL", "Factor", "LDLFactor", "factorize", "lscm", "tutte_embedding"]


EXACT_SIZE = 200_000
"""The largest matrix (unknowns) :func:`factorize` hands to qdldl, whose solves are the same bits on every CPU;
a larger one goes to SuperLU, about 6 times faster there (a million-face cap's Laplacian: 2.6 s against 15.5 s
a factorisation), whose bits follow the CPU's BLAS kernels."""


class Factor:
    """A sparse factorisation of a symmetric (or Hermitian) positive definite ``(n, n)`` matrix: qdldl's
    ``L D L^T`` (up to :data:`EXACT_SIZE` unknowns) or SuperLU's LU."""

    def __init__(self, solve, order: np.ndarray | None = None):
        self._solve, self._order = solve, order

    def solve(self, b: np.ndarray) -> np.ndarray:
        """``A^-1 b`` for ``b`` of shape ``(n,)`` or ``(n, k)``: float64 (complex128 for a Hermitian matrix)."""
        b = np.asarray(b)
        if self._order is not None:
            x = np.empty_like(b, dtype=np.result_type(b, np.float64))
            x[self._order] = self._solve(b[self._order])
            return x
        return self._solve(b)


def factorize(matrix: sp.spmatrix, *, single: bool = False, order: np.ndarray | None = None) -> Factor:
    """Sparse factorisation of a symmetric or Hermitian positive definite matrix.

    Up to :data:`EXACT_SIZE` unknowns it is qdldl's ``L D L^T`` (AMD ordering): plain C with no BLAS beneath,
    so a solve gives the same bits on every CPU.  SuperLU, used for every size before, calls the BLAS in its
    supernodes, and OpenBLAS picks its kernels by the CPU (fused multiply-adds on one, not on another): the
    same cup flattened to different bits under ``OPENBLAS_CORETYPE=Haswell`` and ``Sandybridge``, and the
    darts a search cut followed those bits (issue 51).  Larger matrices (a scan of a million faces) go to
    SuperLU still, in the order given, for its speed: their layouts may differ in the last bits between CPUs.

    Parameters
    ----------
    matrix : (n, n) sparse, float64 or complex128
        A complex Hermitian matrix goes to qdldl as the real symmetric ``[[Re, -Im], [Im, Re]]`` of twice
        its size.
    single : bool
        SuperLU only (past :data:`EXACT_SIZE`): factorise in single precision (float32, real matrices), a
        third faster, for a preconditioner that need not be exact; :meth:`Factor.solve` still takes and
        returns float64.
    order : (n,) int64, optional
        A numbering to put the matrix in first (:func:`patterns.flattening.numbering.dissection_order`):
        SuperLU's elimination order; qdldl's AMD orders it from there.

    Returns
    -------
    Factor

    See Also
    --------
    LDL : numeric-only refactorisations of matrices of one pattern.
    """
    matrix = sp.csc_matrix(matrix)
    if order is not None:
        matrix = sp.csc_matrix(matrix[order][:, order])
    n = matrix.shape[0]
    complex_ = np.iscomplexobj(matrix.data)
    if (2 * n if complex_ else n) > EXACT_SIZE:
        return Factor(_superlu(matrix, single=single and not complex_), order)
    if complex_:
        re, im = sp.csc_matrix(matrix.real), sp.csc_matrix(matrix.imag)
        matrix = sp.bmat([[re, -im], [im, re]], format="csc")
    upper = sp.triu(matrix, format="csc")
    upper.sort_indices()
    solver = qdldl.Solver(upper, upper=True)

    def solve(b):
        if b.ndim == 2:
            return np.column_stack([solve(b[:, k]) for k in range(b.shape[1])])
        if complex_:  # [[Re, -Im], [Im, Re]] [x; y] = [Re b; Im b]
            x = solver.solve(np.ascontiguousarray(np.r_[b.real, b.imag], dtype=np.float64))
            return x[:n] + 1j * x[n:]
        return solver.solve(np.ascontiguousarray(b, dtype=np.float64))

    return Factor(solve, order)


def _superlu(matrix: sp.csc_matrix, *, single: bool):
    """SuperLU's solve of ``matrix`` in the order it is in; in float32 when ``single`` (divided by its mean
    diagonal first, and each right-hand side brought to unit size, so that the rounding does not depend on
    the unit: a mesh in inches factorises like the same mesh in mm)."""
    import scipy.sparse.linalg as spla

    scale = float(np.abs(matrix.diagonal()).mean()) if single else 0.0
    if single:
        matrix = sp.csc_matrix(matrix / scale, dtype=np.float32)
    # Panels of 4 columns (SuperLU's default is 10) factorise these mesh
    # Laplacians about a fifth faster; the factor itself is the same.
    lu = spla.splu(matrix, permc_spec="NATURAL", panel_size=4, options={"SymmetricMode": True},
                   diag_pivot_thresh=0.0)
    if not single:
        return lu.solve

    def solve(b):
        size = float(np.abs(b).max()) or 1.0
        return lu.solve((b / size).astype(np.float32)).astype(np.float64) * (size / scale)

    return solve


class LDL:
    """Repeated ``L D L^T`` factorisations of symmetric positive definite matrices of one pattern.

    The ordering (AMD) and the elimination tree are computed once, from the
    pattern; :meth:`factorize` then factorises only the numbers (qdldl).  On
    Aphrodite's 55 598-vertex Laplacian a refactorisation takes 0.06 s, where
    SuperLU took 0.18 s even with the elimination order given.  A solver
    object in the sense of potpourri3d: the set-up is the part worth keeping.

    Parameters
    ----------
    n : int
        Matrix size.
    rows, cols : (k,) int64
        The upper triangle's entries (``rows <= cols``), each once, the
        diagonal included; the order in which :meth:`factorize` takes values.

    Notes
    -----
    The factor is overwritten in place: a :class:`LDLFactor` from an earlier
    :meth:`factorize` call refuses to solve (``RuntimeError``) instead of
    silently solving with the newer matrix.
    """

    def __init__(self, n: int, rows: np.ndarray, cols: np.ndarray):
        marker = np.arange(1, len(rows) + 1, dtype=np.float64)
        upper = sp.csc_matrix((marker, (rows, cols)), shape=(n, n))
        self._slot = upper.data.astype(np.int64) - 1  # CSC position -> input position
        self._indices, self._indptr, self._n = upper.indices, upper.indptr, n
        self._solver = None
        self._generation = 0

    def factorize(self, values: np.ndarray) -> LDLFactor:
        """Factorise the matrix with these upper-triangle ``values`` ``(k,) float64``."""
        upper = sp.csc_matrix((np.asarray(values, dtype=np.float64)[self._slot], self._indices, self._indptr),
                              shape=(self._n, self._n))
        if self._solver is None:
            self._solver = qdldl.Solver(upper, upper=True)
        else:
            self._solver.update(upper, upper=True)
        self._generation += 1
        return LDLFactor(self, self._generation)


class LDLFactor:
    """The latest factorisation of an :class:`LDL`; valid until its next :meth:`LDL.factorize`."""

    def __init__(self, owner: LDL, generation: int):
        self._owner, self._generation = owner, generation

    def solve(self, b: np.ndarray) -> np.ndarray:
        """``A^-1 b`` for ``b`` of shape ``(n,)`` or ``(n, k)``, float64."""
        if self._generation != self._owner._generation:
            raise RuntimeError("this factor was overwritten by a later LDL.factorize")
        solver = self._owner._solver
        b = np.asarray(b, dtype=np.float64)
        if b.ndim == 1:
            return solver.solve(b)
        return np.column_stack([solver.solve(np.ascontiguousarray(b[:, k])) for k in range(b.shape[1])])


def tutte_embedding(vertices: np.ndarray, faces: np.ndarray, conn: Connectivity) -> np.ndarray:
    """Tutte embedding: outer loop on a circle, everything else barycentric.

    Holes are filled for the solve by one virtual vertex each (joined to the
    hole's loop), so the hole loops come out star-shaped and inside the outer
    loop.

    Parameters
    ----------
    vertices : (n, 3) float64
    faces : (m, 3) int64
    conn : Connectivity

    Returns
    -------
    (n, 2) float64
        The outer loop on a circle of the 3D boundary length (points spaced by
        3D arc length, counter-clockwise); one-to-one.
    """
    n = len(vertices)
    outer, holes = conn.loops[0], conn.loops[1:]
    seg = np.linalg.norm(vertices[np.roll(outer, -1)] - vertices[outer], axis=1)
    perimeter = seg.sum()
    theta = 2 * np.pi * np.concatenate([[0.0], np.cumsum(seg)[:-1]]) / perimeter
    radius = perimeter / (2 * np.pi)
    edges = [conn.edges]
    for k, loop in enumerate(holes):  # virtual vertex n + k in each hole
        edges.append(np.column_stack([loop, np.full(len(loop), n + k)]))
    e = np.concatenate(edges)
    size = n + len(holes)
    adjacency = sp.coo_matrix((np.ones(2 * len(e)), (np.r_[e[:, 0], e[:, 1]], np.r_[e[:, 1], e[:, 0]])),
                              shape=(size, size)).tocsr()
    laplacian = sp.diags(np.asarray(adjacency.sum(axis=1)).ravel()) - adjacency
    fixed = np.zeros(size, dtype=bool)
    fixed[outer] = True
    xy = np.zeros((size, 2))
    xy[outer] = radius * np.column_stack([np.cos(theta), np.sin(theta)])
    lap = laplacian.tocsr()
    free = ~fixed
    rhs = -(lap[free][:, fixed] @ xy[fixed])
    points = np.concatenate([vertices, [vertices[loop].mean(axis=0) for loop in holes]]) if holes else vertices
    inner = np.flatnonzero(free)
    if len(inner) == 0:  # every vertex on the outer loop (a strip one triangle wide): the circle is the embedding
        return xy[:n]
    index = np.full(size, -1, dtype=np.int64)
    index[inner] = np.arange(len(inner))
    inner_edges = index[e[free[e[:, 0]] & free[e[:, 1]]]]
    xy[free] = factorize(lap[free][:, free], order=dissection_order(points[inner], inner_edges)).solve(rhs)
    return xy[:n]


def lscm(vertices: np.ndarray, faces: np.ndarray, conn: Connectivity, *, local: np.ndarray | None = None) -> np.ndarray:
    """Least-squares conformal map with a free boundary.

    Minimises, over all triangles, the squared Cauchy-Riemann residual of the
    triangle's map times its area, with two far-apart boundary vertices pinned:
    one at the origin, the other on +u at their 3D distance.

    Parameters
    ----------
    vertices : (n, 3) float64
    faces : (m, 3) int64
    conn : Connectivity
    local : (m, 3) complex128, optional
        The triangles in their own frames, if already computed.

    Returns
    -------
    (n, 2) float64
    """

    n, m = len(vertices), len(faces)
    z = local_coordinates(vertices, faces) if local is None else local
    # A triangle's Cauchy-Riemann residual (u_x - v_y) + i (u_y + v_x) is
    # complex-linear in its corners' flat positions u + i v: sum_k w_k z_k.  So
    # the energy is |W z|^2 with W complex (m, n), and its minimiser solves an
    # n x n Hermitian system -- a third of the time of the equivalent real
    # 2n x 2n one (the same answer to round-off).
    weight = np.stack([z[:, 2] - z[:, 1], z[:, 0] - z[:, 2], z[:, 1] - z[:, 0]], axis=1)
    weight /= np.sqrt(np.abs((np.conj(z[:, 1]) * z[:, 2]).imag))[:, None]
    system = sp.csc_matrix((weight.ravel(), (np.repeat(np.arange(m), 3), faces.ravel())), shape=(m, n))
    loop = conn.loops[0]
    p0 = loop[np.argmax(np.linalg.norm(vertices[loop] - vertices[loop[0]], axis=1))]
    p1 = loop[np.argmax(np.linalg.norm(vertices[loop] - vertices[p0], axis=1))]
    fixed = np.array([p0, p1])
    values = np.array([0.0, math.hypot(*(vertices[p1] - vertices[p0]))], dtype=np.complex128)  # no BLAS
    free = np.ones(n, dtype=bool)
    free[fixed] = False
    a_free, a_fixed = system[:, free], system[:, fixed]
    adjoint = a_free.conj().T
    x = np.zeros(n, dtype=np.complex128)
    x[fixed] = values
    index = np.cumsum(free) - 1
    e = conn.edges[free[conn.edges[:, 0]] & free[conn.edges[:, 1]]]
    order = dissection_order(vertices[free], index[e])
    x[free] = factorize(adjoint @ a_free, order=order).solve(-(adjoint @ (a_fixed @ values)))
    return np.column_stack([x.real, x.imag])
