"""The ``2 n`` by ``2 n`` systems that couple ``u`` and ``v``: SLIM's proxy and the projected Hessian.

A distortion energy ``sum_t W_t (f(sigma1) + f(sigma2))`` (:mod:`.energy`,
``f(s) = p (s - 1)**2 + q (s**2 + s**-2 - 2)``) sees each triangle through its
Jacobian ``J = U diag(sigma1, sigma2) V^T``.  Its Hessian in ``J`` has four
eigenpairs in closed form (Smith, de Goes, Kim 2019, *Analytic eigensystems for
isotropic distortion energies*): the two stretches ``u_i v_i^T`` with
``f''(sigma_i)``, the twist ``(u1 v2^T - u2 v1^T) / sqrt 2`` with
``(f'(sigma1) + f'(sigma2)) / (sigma1 + sigma2)`` and the flip
``(u1 v2^T + u2 v1^T) / sqrt 2`` with ``(f'(sigma1) - f'(sigma2)) / (sigma1 - sigma2)``.
Only the twist's can be negative (a squeezed triangle); clamped at zero it
gives the projected Newton Hessian, positive semidefinite, triangle by
triangle (:func:`projected_hessian`).  Each triangle's 6 x 6 block acts on its
corners' ``(u0, u1, u2, v0, v1, v2)``; :class:`PairSystem` holds the pattern,
scatters blocks into it and factorises (qdldl, the ordering kept), so that a
mesh pays for its symbolic analysis once.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .embed import LDL, LDLFactor
from .energy import Frames, Jacobian

__all__ = ["PAIRS", "PairFactor", "PairSystem", "corner_columns", "projected_hessian"]


PAIRS = np.array([(a, b) for a in range(6) for b in range(a, 6)], dtype=np.int64)
"""``(21, 2)``: the entries ``(a, b)``, ``a <= b``, of a triangle's symmetric 6 x 6 block, in packed order."""


def corner_columns(fr: Frames) -> np.ndarray:
    """``C``, ``(m, 3, 2)`` float64: ``J[k, j] = sum_c x[k, c] C[c, j]`` for a triangle's corner coordinates ``x``."""
    r11, r12, r21, r22 = fr.inverse
    return np.stack([np.column_stack([-(r11 + r21), r11, r21]), np.column_stack([-(r12 + r22), r12, r22])], axis=2)


def projected_hessian(fr: Frames, jac: Jacobian, stretch: tuple[float, float], *,
                      columns: np.ndarray | None = None, packed: bool = False) -> np.ndarray:
    """Every triangle's Hessian of ``W_t (f(sigma1) + f(sigma2))``, its negative eigenvalue clamped at 0.

    Parameters
    ----------
    fr : Frames
    jac : Jacobian
        Of a layout without folded triangles (``sigma2 > 0``).
    stretch : (float, float)
        ``(p, q)`` of ``f`` (an energy's ``stretch``).
    columns : (m, 3, 2) float64, optional
        :func:`corner_columns`, if at hand.
    packed : bool
        Return each block's 21 entries ``(a, b)``, ``a <= b``, in the order of :data:`PAIRS`.

    Returns
    -------
    (m, 6, 6) float64, or (m, 21) packed
        In the corner order ``(u0, u1, u2, v0, v1, v2)``; positive semidefinite.
    """
    p, q = stretch
    c = corner_columns(fr) if columns is None else columns
    ar, ai, br, bi = jac.conformal_parts()
    na, nb = np.hypot(ar, ai), np.hypot(br, bi)
    s1, s2 = na + nb, na - nb
    # J z = alpha z + beta conj(z): U turns by (arg alpha + arg beta) / 2, V by (arg beta - arg alpha) / 2.
    ta, tb = np.arctan2(ai, ar), np.arctan2(bi, br)
    cu, su = np.cos(0.5 * (ta + tb)), np.sin(0.5 * (ta + tb))
    cv, sv = np.cos(0.5 * (tb - ta)), np.sin(0.5 * (tb - ta))
    cv1 = c[:, :, 0] * cv[:, None] + c[:, :, 1] * sv[:, None]  # C v1, (m, 3)
    cv2 = c[:, :, 1] * cv[:, None] - c[:, :, 0] * sv[:, None]  # C v2
    inv1, inv2 = 1.0 / s1, 1.0 / s2
    stretch1 = 2.0 * p + 2.0 * q * (1.0 + 3.0 * inv1 ** 4)  # f''(s1)
    stretch2 = 2.0 * p + 2.0 * q * (1.0 + 3.0 * inv2 ** 4)
    twist = 2.0 * (p + q) - (4.0 * p + 2.0 * q * (inv1 ** 3 + inv2 ** 3)) / (s1 + s2)
    flip = 2.0 * (p + q) + 2.0 * q * (s1 * s1 + s1 * s2 + s2 * s2) * (inv1 * inv2) ** 3  # no 0/0 at s1 = s2
    w = fr.weight
    root = [np.sqrt(stretch1 * w), np.sqrt(stretch2 * w), np.sqrt(0.5 * np.maximum(twist, 0.0) * w),
            np.sqrt(0.5 * flip * w)]
    # The modes as 6-vectors vec(Q C^T), (k, c) at 3 k + c; u1 = (cu, su), u2 = (-su, cu).
    g = np.empty((len(w), 4, 6))
    g[:, 0, :3], g[:, 0, 3:] = (root[0] * cu)[:, None] * cv1, (root[0] * su)[:, None] * cv1
    g[:, 1, :3], g[:, 1, 3:] = (-root[1] * su)[:, None] * cv2, (root[1] * cu)[:, None] * cv2
    a0, a1 = cu[:, None] * cv2, su[:, None] * cv2  # u1 (x) C v2
    b0, b1 = -su[:, None] * cv1, cu[:, None] * cv1  # u2 (x) C v1
    g[:, 2, :3], g[:, 2, 3:] = root[2][:, None] * (a0 - b0), root[2][:, None] * (a1 - b1)
    g[:, 3, :3], g[:, 3, 3:] = root[3][:, None] * (a0 + b0), root[3][:, None] * (a1 + b1)
    if not packed:
        return np.einsum("mki,mkj->mij", g, g)  # einsum, not BLAS: the same bits on every CPU
    by_entry = np.ascontiguousarray(g.transpose(2, 1, 0))  # (6, 4, m): 21 products of rows, not a 6 x 6 matmul
    out = np.empty((len(w), len(PAIRS)))
    for k, (a, b) in enumerate(PAIRS):
        x = by_entry[a] * by_entry[b]
        out[:, k] = x[0] + x[1] + x[2] + x[3]
    return out


class PairSystem:
    """The pattern of a mesh's ``2 n`` by ``2 n`` matrices (unknown ``(k, i)`` at ``k n + i``), factorised repeatedly.

    Parameters
    ----------
    fr : Frames
    n : int
        Vertices.

    Attributes
    ----------
    columns : (m, 3, 2) float64
        The mesh's :func:`corner_columns`, for the blocks that go into it.
    """

    def __init__(self, fr: Frames, n: int):
        self.columns = corner_columns(fr)
        corners = np.column_stack(fr.corners)  # (m, 3)
        self.local = np.hstack([corners, corners + n])  # (m, 6): a triangle's unknowns
        a, b = self.local[:, PAIRS[:, 0]], self.local[:, PAIRS[:, 1]]  # (m, 21): each entry's two unknowns
        self._keys, slot = np.unique(np.minimum(a, b) * (2 * n) + np.maximum(a, b), return_inverse=True)
        self._slot = slot.reshape(a.shape)
        self.n, self.n_entries = n, len(self._keys)
        self.diagonal = np.flatnonzero(self._keys // (2 * n) == self._keys % (2 * n))  # (2 n,): unknown by unknown
        self._ldl = LDL(2 * n, self._keys // (2 * n), self._keys % (2 * n))

    def assemble(self, blocks: np.ndarray) -> np.ndarray:
        """The upper-triangle values ``(k,)`` of the sum of the triangles' blocks.

        ``blocks`` is ``(m, 6, 6)``, or ``(m, 21)`` packed: entry ``(a, b)``, ``a <= b``, of each block
        in the order of :data:`PAIRS`.
        """
        packed = blocks if blocks.ndim == 2 else blocks[:, PAIRS[:, 0], PAIRS[:, 1]]
        return np.bincount(self._slot.ravel(), weights=packed.ravel(), minlength=self.n_entries)

    def laplacian(self, edges: np.ndarray, weight: np.ndarray) -> np.ndarray:
        """Values ``(k,)`` of ``L (x) I``, ``L`` the graph Laplacian of mesh ``edges`` ``(e, 2)`` with ``weight`` ``(e,)``."""
        n2 = 2 * self.n
        lo, hi = edges.min(axis=1), edges.max(axis=1)
        out = np.zeros(self.n_entries)
        for shift in (0, self.n):
            off = np.searchsorted(self._keys, (lo + shift) * n2 + hi + shift)
            np.add.at(out, off, -weight)
            np.add.at(out, self.diagonal[lo + shift], weight)
            np.add.at(out, self.diagonal[hi + shift], weight)
        return out

    def matrix(self, values: np.ndarray) -> sp.csr_matrix:
        """The whole symmetric ``(2 n, 2 n)`` matrix of upper-triangle ``values`` ``(k,)``, as scipy CSR."""
        n2 = 2 * self.n
        rows, cols = self._keys // n2, self._keys % n2
        lower = rows != cols
        return sp.csr_matrix((np.r_[values, values[lower]], (np.r_[rows, cols[lower]], np.r_[cols, rows[lower]])),
                             shape=(n2, n2))

    def factorize(self, values: np.ndarray) -> PairFactor:
        """Factorise the matrix with these upper-triangle ``values`` ``(k,)``."""
        return PairFactor(self._ldl.factorize(values), self.n)


class PairFactor:
    """A factorised :class:`PairSystem` matrix; valid until the system's next :meth:`PairSystem.factorize`."""

    def __init__(self, factor: LDLFactor, n: int):
        self._factor, self._n = factor, n

    def solve(self, b: np.ndarray) -> np.ndarray:
        """``A^-1 b`` for ``b`` ``(n, 2)`` (columns ``u``, ``v``) or ``(2 n,)``, in the same shape."""
        if b.ndim == 1:
            return self._factor.solve(b)
        x = self._factor.solve(np.concatenate([b[:, 0], b[:, 1]]))
        return np.column_stack([x[:self._n], x[self._n:]])
