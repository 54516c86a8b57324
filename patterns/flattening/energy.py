"""Distortion energies of a flat layout, with their gradients: what the relaxation minimises.

Every energy here is a sum over triangles weighted by 3D area, so that it
measures the map from the surface to the plane, not the mesh: refining a
triangulation or changing its shape changes the sum only by the discretisation
error of the surface itself.  (The edge stress of earlier versions,
``sum over edges (l_flat / l_3d - 1)**2``, counts edges instead: slivers and
pole fans pull it, and the same surface gave 0.94 %, 1.57 % and 3.11 % strain
on three meshes.)

A triangle's map to the plane is affine; in its own orthonormal 3D frame
(:func:`patterns.measure.local_coordinates`) its Jacobian is ``J = P R^-1``,
``P`` (2 x 2) the flat sides ``u1 - u0, u2 - u0`` as columns and ``R`` the same
sides in the 3D frame.  ``sigma1 >= sigma2`` are its singular values (the
principal stretches).  With ``|J|^2 = sigma1**2 + sigma2**2`` and
``det J = sigma1 sigma2``:

* :class:`Arap` -- ``sum_t W_t ((sigma1 - 1)**2 + (sigma2 - 1)**2)``, the
  area-weighted sum of squared principal strains: libigl's ARAP energy
  ``min_R |J - R|^2`` (rotations only), ``|J|^2 - 2 sqrt(|J|^2 + 2 det J) + 2``.
  Bounded as a triangle collapses: on its own it may crush triangles.
* :class:`SymmetricDirichlet` -- ``sum_t W_t (|J|^2 + |J^-1|^2 - 4)``
  ``= sum_t W_t ((sigma1 - 1/sigma1)**2 + (sigma2 - 1/sigma2)**2)`` (SLIM's
  energy, shifted to 0 at an isometry): four times the squared strains for
  small strains, unbounded as a triangle collapses.
* :class:`Hybrid` -- ``(ARAP + SD / 4) / 2``: the squared strains, with the
  symmetric Dirichlet energy's resistance to crushing where triangles are
  squeezed.  What ``"auto"`` (the relaxation's default) falls back to where
  ARAP's least-strain layout would fold and the fold-free one presses
  triangles flat.
* :class:`InverseTerm` -- ``sum_t W_t |J^-1|^2`` (the collapse barrier of the
  relaxation's first stages) or, with a floor, the guard against crushed
  triangles ``sum_t W_t max(0, |J^-1|^2 - floor)**2``.
* :class:`EdgeLengths` -- an augmented-Lagrangian term holding chosen edges
  (the seams) at target lengths.

``W_t`` is the triangle's 3D area over the mean triangle area, so an energy
counts about as many terms as there are triangles, in any unit.  Coordinates
are gathered column by column (several times faster than ``(m, 2)`` rows) and
gradients scattered to vertices by sparse products.  Values are summed by
``einsum``, which uses no BLAS threads: the result does not depend on how many
threads the machine has.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.sparse as sp

from ..measure import local_coordinates

__all__ = ["BY_NAME", "ENERGIES", "Arap", "EdgeLengths", "Frames", "Hybrid", "InverseTerm", "Jacobian", "SymmetricDirichlet",
           "dot", "frames"]



def dot(a: np.ndarray, b: np.ndarray) -> float:
    """Sum of the elementwise product of two arrays of one shape.

    ``einsum`` rather than BLAS (``vdot``): BLAS splits long sums between its
    threads, so the rounding, and through it a relaxation's path, would
    depend on the machine's thread count.
    """
    spec = "i,i->" if a.ndim == 1 else "ij,ij->"
    return float(np.einsum(spec, a, b))


@dataclass(frozen=True, eq=False)
class Frames:
    """The 3D reference of every triangle, shared by the energies.

    Attributes
    ----------
    faces : (m, 3) int64
    inverse : tuple of four (m,) float64
        ``R^-1``'s entries ``(r11, r12, r21, r22)``, in 1 / mesh unit.
    det_r : (m,) float64
        ``det R``, twice the 3D area (positive).
    weight : (m,) float64
        ``W_t``: 3D area over the mean triangle area (dimensionless).
    corners : tuple of three (m,) int64
        The faces' corner columns, contiguous (fast gathers).
    n_vertices : int
    """

    faces: np.ndarray
    inverse: tuple
    det_r: np.ndarray
    weight: np.ndarray
    corners: tuple
    n_vertices: int

    @cached_property
    def scatter(self) -> sp.csc_matrix:
        """``(n, 2 m)`` sparse: per-triangle derivatives with respect to the columns of ``P`` (first the ``m``
        for ``u1 - u0``, then the ``m`` for ``u2 - u0``) to vertex gradients.  Built on first use: a
        value-only evaluation (is a start already exact?) needs none."""
        m = len(self.faces)
        c0, c1, c2 = self.corners
        # Column c < m: +1 at corner 1, -1 at corner 0 of face c; column m + c: corner 2 and corner 0.
        # Two entries a column, built straight in CSC form (no sort).
        rows = np.empty(4 * m, dtype=np.int64)
        rows[0:2 * m:2], rows[1:2 * m:2] = c1, c0
        rows[2 * m::2], rows[2 * m + 1::2] = c2, c0
        return sp.csc_matrix((np.tile([1.0, -1.0], 2 * m), rows, np.arange(0, 4 * m + 1, 2)),
                             shape=(self.n_vertices, 2 * m))

    def jacobian(self, u: np.ndarray) -> Jacobian:
        """The :class:`Jacobian` of every triangle for the layout ``u`` ``(n, 2)``."""
        x, y = np.ascontiguousarray(u[:, 0]), np.ascontiguousarray(u[:, 1])  # gathers from columns: twice as fast
        f0, f1, f2 = self.corners
        x0, y0 = x.take(f0), y.take(f0)
        a, b, c, d = x.take(f1) - x0, x.take(f2) - x0, y.take(f1) - y0, y.take(f2) - y0
        r11, r12, r21, r22 = self.inverse
        return Jacobian(a * r11 + b * r21, a * r12 + b * r22, c * r11 + d * r21, c * r12 + d * r22)

    def gradient(self, g11, g12, g21, g22) -> np.ndarray:
        """Vertex gradient ``(n, 2)`` of a sum of per-triangle terms, from their derivatives ``dE/dJ``.

        ``J = P R^-1``, so ``dE/dP = dE/dJ R^-T``; the columns of ``P`` are
        ``u1 - u0`` and ``u2 - u0``.
        """
        r11, r12, r21, r22 = self.inverse
        out = np.empty((self.scatter.shape[0], 2))
        out[:, 0] = self.scatter @ np.concatenate([g11 * r11 + g12 * r12, g11 * r21 + g12 * r22])
        out[:, 1] = self.scatter @ np.concatenate([g21 * r11 + g22 * r12, g21 * r21 + g22 * r22])
        return out

    def dirichlet_weights(self, scale=None) -> np.ndarray:
        """Edge coefficients ``(m, 3)`` of ``sum_t s_t W_t |J_t|^2`` as ``sum c (u_i - u_j)**2``, per coordinate.

        Column ``k`` belongs to the side from corner ``k`` to corner ``k + 1``
        (:attr:`patterns.mesh.Connectivity.face_edges`).  Summed per edge they
        are the weights of the cotangent Laplacian (times the triangle scales
        ``s_t``, default 1), whose quadratic form is positive semidefinite for any
        positive ``s_t`` even where single coefficients are negative (obtuse
        triangles).
        """
        r11, r12, r21, r22 = self.inverse
        g11, g12, g22 = r11 * r11 + r12 * r12, r11 * r21 + r12 * r22, r21 * r21 + r22 * r22  # R^-1 R^-T
        w = self.weight if scale is None else self.weight * scale
        return np.column_stack([w * (g11 + g12), -w * g12, w * (g22 + g12)])


@dataclass(frozen=True, eq=False)
class Jacobian:
    """Every triangle's 2 x 2 Jacobian ``J = [[j11, j12], [j21, j22]]``, entries ``(m,)``.

    In complex form ``J z = alpha z + beta conj(z)``: ``sigma1 = |alpha| + |beta|``,
    ``sigma2 = |alpha| - |beta|`` (negative where folded), ``det J = |alpha|**2 - |beta|**2``.
    """

    j11: np.ndarray
    j12: np.ndarray
    j21: np.ndarray
    j22: np.ndarray

    @property
    def det(self) -> np.ndarray:
        return self.j11 * self.j22 - self.j12 * self.j21

    def conformal_parts(self):
        """``(alpha.real, alpha.imag, beta.real, beta.imag)``."""
        return (0.5 * (self.j11 + self.j22), 0.5 * (self.j21 - self.j12),
                0.5 * (self.j11 - self.j22), 0.5 * (self.j21 + self.j12))

    def inverse_transpose_cubed(self, det):
        """``J^-T J^-1 J^-T`` entries (the derivative of ``|J^-1|^2`` is minus twice this)."""
        # J^-1 = [[j22, -j12], [-j21, j11]] / det.
        a, b, c, d = self.j22 / det, -self.j12 / det, -self.j21 / det, self.j11 / det  # J^-1 = [[a, b], [c, d]]
        # J^-T J^-1 = [[a a + c c, a b + c d], [b a + d c, b b + d d]]; times J^-T = [[a, c], [b, d]].
        m11, m12, m22 = a * a + c * c, a * b + c * d, b * b + d * d
        return m11 * a + m12 * b, m11 * c + m12 * d, m12 * a + m22 * b, m12 * c + m22 * d

    def smallest_stretch_squared(self) -> np.ndarray:
        """``sigma2**2`` of every triangle, in the cancellation-free form ``det**2 / sigma1**2``."""
        det2, norm2 = self.det ** 2, self.norm2
        return 2.0 * det2 / (norm2 + np.sqrt(np.maximum(norm2 * norm2 - 4.0 * det2, 0.0)))

    @property
    def norm2(self) -> np.ndarray:
        """``|J|_F**2 = sigma1**2 + sigma2**2``."""
        return self.j11 * self.j11 + self.j12 * self.j12 + self.j21 * self.j21 + self.j22 * self.j22


def frames(vertices: np.ndarray, faces: np.ndarray, *, local: np.ndarray | None = None) -> Frames:
    """The :class:`Frames` of a mesh.

    Parameters
    ----------
    vertices : (n, 3) float64
    faces : (m, 3) int64
    local : (m, 3) complex128, optional
        :func:`patterns.measure.local_coordinates`, if at hand.
    """
    n = len(vertices)
    z = local_coordinates(vertices, faces) if local is None else local
    r1, r2 = z[:, 1] - z[:, 0], z[:, 2] - z[:, 0]
    # R = [[r1.x, r2.x], [r1.y, r2.y]] (the sides as columns).
    det_r = r1.real * r2.imag - r2.real * r1.imag
    inverse = (r2.imag / det_r, -r2.real / det_r, -r1.imag / det_r, r1.real / det_r)
    area = 0.5 * np.abs(det_r)
    corners = tuple(np.ascontiguousarray(faces[:, k]) for k in range(3))
    return Frames(faces, inverse, det_r, area / area.mean(), corners, n)


class _TriangleEnergy:
    """A sum of per-triangle terms: subclasses give :meth:`terms`, ``(value, dE/dJ entries)`` or None where folded.

    The distortion energies are ``sum_t W_t (f(sigma1) + f(sigma2))`` with
    ``f(s) = p (s - 1)**2 + q (s**2 + s**-2 - 2)``; ``stretch`` is their ``(p, q)``
    (what SLIM's proxy and the projected Hessian of :mod:`.hessian` are built from).
    """

    stretch: tuple[float, float] | None = None

    def __init__(self, fr: Frames):
        self.fr = fr

    def terms(self, jac: Jacobian, *, grad: bool = True):  # pragma: no cover - abstract
        """``(value, dE/dJ entries)``, the entries None where not ``grad``; None where folded."""
        raise NotImplementedError

    def __call__(self, u: np.ndarray, jac: Jacobian | None = None, *, grad: bool = True):
        """``(value, gradient (n, 2))``; ``(inf, None)`` where the energy sees a folded triangle; the gradient
        None where not ``grad`` (the value the same to the last bit)."""
        out = self.terms(self.fr.jacobian(u) if jac is None else jac, grad=grad)
        if out is None:
            return np.inf, None
        value, derivative = out
        return value, self.fr.gradient(*derivative) if grad else None


class Arap(_TriangleEnergy):
    """``sum_t W_t ((sigma1 - 1)**2 + (sigma2 - 1)**2)``: the squared principal strains (see the module).

    Computed as ``2 (|alpha| - 1)**2 + 2 |beta|**2`` (``min_R |J - R|^2`` over
    rotations), whose derivative is ``2 (J - R)``, ``R`` the rotation of
    ``alpha``: free of the cancellation of ``|J|^2 - 2 (sigma1 + sigma2) + 2``,
    which would blur strains below 1e-8.
    """

    name = "arap"
    stretch = (1.0, 0.0)  # (p, q) of the per-stretch term, see _TriangleEnergy

    def terms(self, jac, *, grad=True):
        ar, ai, br, bi = jac.conformal_parts()
        size = np.hypot(ar, ai)
        excess = size - 1.0
        w = self.fr.weight
        value = 2.0 * dot(w, excess * excess + br * br + bi * bi)
        if not grad:
            return value, None
        # 2 W (J - R), R = [[ar, -ai], [ai, ar]] / |alpha|.
        k = 2.0 * w * excess / np.maximum(size, 1e-300)
        w2 = 2.0 * w
        return value, (k * ar + w2 * br, -k * ai + w2 * bi, k * ai + w2 * bi, k * ar - w2 * br)


def _stretch_excess(jac: Jacobian):
    """``(sigma1 - 1, sigma2 - 1)`` without cancellation."""
    ar, ai, br, bi = jac.conformal_parts()
    excess, b = np.hypot(ar, ai) - 1.0, np.hypot(br, bi)
    return excess + b, excess - b


class SymmetricDirichlet(_TriangleEnergy):
    """``sum_t W_t (|J|^2 + |J^-1|^2 - 4)``: infinite where a triangle folds (see the module).

    The value is summed as ``(sigma - 1/sigma)**2 = ((sigma - 1)(sigma + 1) / sigma)**2``
    per principal stretch, free of cancellation; the derivative is
    ``2 (J - J^-T J^-1 J^-T)``.
    """

    name = "symmetric-dirichlet"
    stretch = (0.0, 1.0)

    def terms(self, jac, *, grad=True):
        det = jac.det
        if not np.all(det > 0):
            return None
        e1, e2 = _stretch_excess(jac)
        t1, t2 = e1 * (e1 + 2.0) / (e1 + 1.0), e2 * (e2 + 2.0) / (e2 + 1.0)
        w = self.fr.weight
        value = dot(w, t1 * t1 + t2 * t2)
        if not grad:
            return value, None
        m11, m12, m21, m22 = jac.inverse_transpose_cubed(det)
        w2 = 2.0 * w
        return value, (w2 * (jac.j11 - m11), w2 * (jac.j12 - m12), w2 * (jac.j21 - m21), w2 * (jac.j22 - m22))


class Hybrid(_TriangleEnergy):
    """``(1 - t) ARAP + t SD / 4``, ``t = 1/2``: the squared strains, with the symmetric Dirichlet energy's
    resistance to crushing.

    ``SD / 4`` has ARAP's curvature at an isometry, so for small strains the two
    halves agree; where a triangle is squeezed, the ``1 / sigma**2`` of ``SD``
    holds it open.  Infinite where a triangle folds.
    """

    name = "hybrid"
    share = 0.5  # t
    stretch = (1.0 - share, 0.25 * share)

    def __init__(self, fr: Frames):
        super().__init__(fr)
        self._arap, self._sd = Arap(fr), SymmetricDirichlet(fr)

    def terms(self, jac, *, grad=True):
        sd = self._sd.terms(jac, grad=grad)
        if sd is None:
            return None
        arap = self._arap.terms(jac, grad=grad)
        a, b = self.stretch
        if not grad:
            return a * arap[0] + b * sd[0], None
        return a * arap[0] + b * sd[0], tuple(a * x + b * y for x, y in zip(arap[1], sd[1]))


class InverseTerm(_TriangleEnergy):
    """``sum_t W_t |J^-1|^2`` (``floor == 0``, the barrier) or ``sum_t W_t max(0, |J^-1|^2 - floor)**2``.

    ``|J^-1|^2 = 1/sigma1**2 + 1/sigma2**2`` is 2 for a rigid motion and grows
    without bound as the triangle collapses; both are infinite where a
    triangle is folded.  The guard (``floor > 0``) is zero wherever no
    triangle is squeezed below the stretch the floor stands for.
    """

    def __init__(self, fr: Frames, floor: float = 0.0):
        super().__init__(fr)
        self.floor = float(floor)

    def terms(self, jac, *, grad=True):
        det = jac.det
        if not np.all(det > 0):
            return None
        inv2 = jac.norm2 / (det * det)  # |J^-1|^2
        w = self.fr.weight
        if self.floor > 0:
            excess = np.maximum(inv2 - self.floor, 0.0)
            value = dot(w, excess * excess)
            k = -4.0 * w * excess
        else:
            value = dot(w, inv2)
            k = -2.0 * w
        if not grad:
            return value, None
        m11, m12, m21, m22 = jac.inverse_transpose_cubed(det)
        return value, (k * m11, k * m12, k * m21, k * m22)

    def stiffness(self, u: np.ndarray) -> np.ndarray:
        """Per-triangle curvature of ``|J^-1|^2`` relative to the Dirichlet form's, ``(m,)``: ``3 / sigma_min**4``."""
        smin2 = self.fr.jacobian(u).smallest_stretch_squared()
        with np.errstate(divide="ignore", over="ignore"):
            return np.minimum(3.0 / (smin2 * smin2), 1e12)


class EdgeLengths:
    """Chosen runs of edges held at target lengths, by an augmented Lagrangian.

    Each group ``g`` of edges (a seam side, or a single edge) has the
    constraint ``c_g = sum_{e in g} l_e / T_g - 1 = 0``, ``T_g`` the sum of its
    edges' targets; the term is ``sum_g W_g (lam_g c_g + rho / 2 c_g**2)``.
    After each minimisation the multipliers take up the force the penalty
    carried (:meth:`update`), so that the lengths reach their targets without
    an ill-conditioning penalty weight.  ``W_g`` is the 3D area of the
    group's triangles over the mean triangle area: a run is held about as
    firmly as the triangles along it are.

    Parameters
    ----------
    n : int
        Number of vertices.
    edges : (k, 2) int64
    target : (k,) float64
        Lengths, in the mesh unit.
    group : (k,) int64
        Each edge's group, ``0 .. g - 1``.
    weight : (g,) float64
        ``W_g``.
    rho : float
        Penalty weight relative to ``W_g``.
    """

    def __init__(self, n: int, edges: np.ndarray, target: np.ndarray, group: np.ndarray, weight: np.ndarray,
                 rho: float):
        self.edges, self.target, self.group, self.weight, self.rho = edges, target, group, weight, float(rho)
        self.total = np.bincount(group, target, len(weight))
        self.lam = np.zeros(len(weight))
        self._e0, self._e1 = np.ascontiguousarray(edges[:, 0]), np.ascontiguousarray(edges[:, 1])
        k = len(edges)
        self._scatter = sp.csr_matrix((np.r_[np.ones(k), -np.ones(k)], (np.r_[self._e1, self._e0],
                                                                         np.r_[np.arange(k), np.arange(k)])),
                                      shape=(n, k))

    def _lengths(self, u):
        x, y = np.ascontiguousarray(u[:, 0]), np.ascontiguousarray(u[:, 1])
        dx = x.take(self._e1) - x.take(self._e0)
        dy = y.take(self._e1) - y.take(self._e0)
        return dx, dy, np.sqrt(dx * dx + dy * dy)

    def residual(self, u: np.ndarray) -> np.ndarray:
        """``c_g``, ``(g,)``: each group's flat length over its target, minus 1."""
        return np.bincount(self.group, self._lengths(u)[2], len(self.weight)) / self.total - 1.0

    def __call__(self, u: np.ndarray, jac=None, *, grad: bool = True):
        dx, dy, length = self._lengths(u)
        c = np.bincount(self.group, length, len(self.weight)) / self.total - 1.0
        value = dot(self.weight, self.lam * c + 0.5 * self.rho * c * c)
        if not grad:
            return value, None
        force = self.weight * (self.lam + self.rho * c) / self.total  # dE/d(sum of lengths), per group
        k = force[self.group] / np.maximum(length, 1e-300)
        return value, self._scatter @ np.column_stack([k * dx, k * dy])

    def update(self, u: np.ndarray) -> float:
        """Move the multipliers by the penalty's force; returns the largest ``|c_g|`` before the update."""
        c = self.residual(u)
        self.lam = self.lam + self.rho * c
        return float(np.abs(c).max()) if len(c) else 0.0

    def edge_weights(self) -> np.ndarray:
        """The term's curvature along each edge if each were its own group, ``W rho / T**2`` (the preconditioner's)."""
        w = self.weight[self.group] / np.bincount(self.group, minlength=len(self.weight))[self.group]
        return w * self.rho / (self.target * self.target)


BY_NAME = {"arap": Arap, "hybrid": Hybrid, "symmetric-dirichlet": SymmetricDirichlet}
"""The distortion energies by their ``name`` (every one of :data:`ENERGIES` but ``"auto"``): a new energy's one
line besides its class."""
ENERGIES = ("auto", *BY_NAME)
"""The energies the relaxation takes (``"auto"``: ARAP, or the hybrid where ARAP crushes triangles): made
from :data:`BY_NAME`, so a new energy's name is one line there."""

