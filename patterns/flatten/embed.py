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

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..mesh import Connectivity

__all__ = ["Factor", "factorize", "lscm", "tutte_embedding"]


class Factor:
    """A sparse LU factorisation of a symmetric positive definite ``(n, n)`` matrix.

    Attributes
    ----------
    order : (n,) int64
        The fill-reducing elimination order (row/column ``order[k]`` is
        eliminated ``k``-th); a later matrix of the same pattern can reuse it
        (:func:`factorize`'s ``like``).
    """

    def __init__(self, lu, order: np.ndarray, permuted: bool, scale: float = 0.0):
        self._lu, self.order, self._permuted, self._scale = lu, order, permuted, scale

    def solve(self, b: np.ndarray) -> np.ndarray:
        """``A^-1 b`` for ``b`` of shape ``(n,)`` or ``(n, k)``, float64 in and out."""
        if self._scale:
            # Single precision: the right-hand side goes in at unit size, so
            # that the rounding -- and the result -- does not depend on the unit.
            size = float(np.abs(b).max()) or 1.0
            rhs = (b / size).astype(np.float32)
            factor = size / self._scale
        else:
            rhs, factor = b, 1.0
        if self._permuted:
            x = np.empty(b.shape)
            x[self.order] = self._lu.solve(rhs[self.order])
        else:
            x = self._lu.solve(rhs).astype(np.float64, copy=False)
        return x * factor if self._scale else x


def factorize(matrix: sp.spmatrix, *, like: Factor | None = None, single: bool = False) -> Factor:
    """Sparse LU of a symmetric positive definite matrix, minimum-degree ordered.

    Parameters
    ----------
    matrix : (n, n) sparse
    like : Factor, optional
        A factorisation of a matrix with the same sparsity pattern: its
        elimination order is reused, so only the numbers are factorised (the
        relaxation refactorises its preconditioner this way).
    single : bool
        Factorise in single precision (float32): about a third faster to
        factorise and to solve with, for a preconditioner that need not be
        exact.  :meth:`Factor.solve` still takes and returns float64.

    Returns
    -------
    Factor
    """
    # Panels of 4 columns (SuperLU's default is 10) factorise these mesh
    # Laplacians about a fifth faster; the factor itself is the same.
    options = {"SymmetricMode": True}
    matrix = sp.csc_matrix(matrix)
    scale = 0.0
    if single:
        # Divided by its mean diagonal first: float32 rounding is then the same
        # in any unit (a mesh in inches factorises like the same mesh in mm).
        scale = float(np.abs(matrix.diagonal()).mean())
        matrix = sp.csc_matrix(matrix / scale, dtype=np.float32)
    if like is None:
        lu = spla.splu(matrix, permc_spec="MMD_AT_PLUS_A", panel_size=4, options=options, diag_pivot_thresh=0.0)
        return Factor(lu, np.argsort(lu.perm_c), False, scale)
    order = like.order
    lu = spla.splu(matrix[order][:, order].tocsc(), permc_spec="NATURAL", panel_size=4, options=options,
                   diag_pivot_thresh=0.0)
    return Factor(lu, order, True, scale)


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
    xy[free] = factorize(lap[free][:, free]).solve(rhs)
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
    from ..measure import local_coordinates

    n, m = len(vertices), len(faces)
    z = local_coordinates(vertices, faces) if local is None else local
    weight = np.stack([z[:, 2] - z[:, 1], z[:, 0] - z[:, 2], z[:, 1] - z[:, 0]], axis=1)
    weight /= np.sqrt(np.abs((np.conj(z[:, 1]) * z[:, 2]).imag))[:, None]
    rows = np.repeat(np.arange(m), 3)
    cu = 2 * faces.ravel()  # unknowns interleaved, u0 v0 u1 v1 ...: a tighter factor
    cv = cu + 1
    a, b = weight.real.ravel(), weight.imag.ravel()
    # Rows 0..m-1: real part (a u - b v); rows m..2m-1: imaginary part (a v + b u).
    system = sp.coo_matrix(
        (np.r_[a, -b, b, a], (np.r_[rows, rows, rows + m, rows + m], np.r_[cu, cv, cu, cv])),
        shape=(2 * m, 2 * n),
    ).tocsc()
    loop = conn.loops[0]
    p0 = loop[np.argmax(np.linalg.norm(vertices[loop] - vertices[loop[0]], axis=1))]
    p1 = loop[np.argmax(np.linalg.norm(vertices[loop] - vertices[p0], axis=1))]
    fixed = np.array([2 * p0, 2 * p1, 2 * p0 + 1, 2 * p1 + 1])
    values = np.array([0.0, np.linalg.norm(vertices[p1] - vertices[p0]), 0.0, 0.0])
    free = np.ones(2 * n, dtype=bool)
    free[fixed] = False
    a_free, a_fixed = system[:, free], system[:, fixed]
    x = np.zeros(2 * n)
    x[fixed] = values
    x[free] = factorize(a_free.T @ a_free).solve(-(a_free.T @ (a_fixed @ values)))
    return x.reshape(n, 2)
