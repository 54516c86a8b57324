"""Fold-free relaxation of a flat layout towards true edge lengths.

The relaxation minimises the edge-length stress

    S(u) = sum over edges of (|u_i - u_j| / l_ij - 1)**2,

the sum of squared edge strains, while every triangle keeps its orientation and
the flat boundary never crosses itself.

Method
------
* **Energy.**  ``E = S + mu * B`` with the collapse barrier
  ``B = sum_t w_t |J_t^-1|_F**2`` (``J_t`` the triangle's Jacobian from its 3D
  frame to the plane; 2 for a rigid motion, unbounded as a triangle
  collapses).  ``mu`` starts at ``barrier`` and is cut tenfold each time
  progress stalls; the last stage has ``mu = 0`` and minimises the stress
  alone.  The barrier matters when the start is far from the answer (a
  conformal layout of a head, whose ears are shrunk a hundredfold): without it
  the stress squeezes triangles flat on the way and the steps stall.
* **Steps.**  L-BFGS whose initial inverse Hessian is ``L^-1 / 2``, ``L`` the
  graph Laplacian with weights ``1 / l**2`` (the stress's curvature at the
  answer), factorised once with SuperLU (in single precision: it only shapes
  the steps).  While the barrier is strong its curvature is added to the
  weights every few iterations and the matrix refactorised in double
  precision by qdldl's ``L D L^T``, whose ordering and elimination tree are
  kept from the first refactorisation so that only the numbers are factorised
  (:class:`~patterns.flatten.embed.LDL`; a scalar version of SLIM's proxy).  One solve per iteration; the L-BFGS memory is kept until the
  matrix changes.
* **Line search.**  Each step is capped at 0.9 of the first time any triangle
  would flip (exact quadratic roots, :func:`flip_free_steps`), then halved until
  the energy drops (Armijo) and the boundary loops are still a valid polygon
  (shapely).  A start without folds and with valid loops therefore ends
  without folds and without overlap, by the same degree argument as
  :mod:`patterns.check`.  Nothing is ever rescaled.
* **Pins** are reached first by stress-majorization steps cut vertex by vertex
  (:func:`_travel_to_pins`), then held while the rest relaxes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import shapely

from ..check import crossing_segments
from ..errors import InputError
from ..measure import local_coordinates, signed_areas
from ..mesh import Connectivity, edge_lengths
from .embed import LDL, LDLFactor, factorize

_WINDOW = 2  # iterations over which progress is judged
_STAGE_TOLERANCE = 30.0  # a barrier stage ends at this many times the tolerance
_REFRESH = 5  # iterations between refactorisations while the barrier is strong
_MEMORY = 8  # L-BFGS pairs kept
_DROP = 0.1  # the barrier weight is multiplied by this at each new stage
_WEAKEST = 1e-5  # the last barrier stage before the stress alone

__all__ = ["Relaxation", "align_to_pins", "best_scale", "flip_free_steps", "relax"]


@dataclass(frozen=True, eq=False)
class Relaxation:
    """Result of :func:`relax`.

    Attributes
    ----------
    uv : (n, 2) float64
    iterations : int
    converged : bool
        The relative decrease of the stress fell below the tolerance (and the
        pins, if any, were reached) before ``max_iterations``.
    """

    uv: np.ndarray
    iterations: int
    converged: bool


def flip_free_steps(faces: np.ndarray, uv: np.ndarray, step: np.ndarray, *, horizon: float = np.inf) -> np.ndarray:
    """Largest ``t`` per triangle such that ``uv + s * step`` keeps it positive for all ``s < t``.

    The signed area along the step is the quadratic ``a2 t**2 + a1 t + a0``
    (``a0 > 0``); its smallest positive root is returned, ``inf`` if none.

    Parameters
    ----------
    faces : (m, 3) int64
    uv, step : (n, 2) float64
    horizon : float
        Only roots below this matter: triangles whose area stays positive up to
        ``horizon`` get ``inf`` without solving (much faster when most are safe).

    Returns
    -------
    (m,) float64
    """
    # Column gathers: several times faster than gathering (m, 3, 2) blocks.
    i, j, k = faces[:, 0], faces[:, 1], faces[:, 2]
    x, y, dx, dy = uv[:, 0], uv[:, 1], step[:, 0], step[:, 1]
    x0, y0, dx0, dy0 = x[i], y[i], dx[i], dy[i]
    e1x, e1y, e2x, e2y = x[j] - x0, y[j] - y0, x[k] - x0, y[k] - y0
    d1x, d1y, d2x, d2y = dx[j] - dx0, dy[j] - dy0, dx[k] - dx0, dy[k] - dy0
    a0 = e1x * e2y - e1y * e2x
    a1 = e1x * d2y - e1y * d2x + d1x * e2y - d1y * e2x
    a2 = d1x * d2y - d1y * d2x
    t = np.full(len(faces), np.inf)
    if np.isfinite(horizon):
        # Positive at both ends of [0, horizon] and not dipping in between: safe.
        end = (a2 * horizon + a1) * horizon + a0
        with np.errstate(divide="ignore", invalid="ignore"):
            vertex = -a1 / (2 * a2)
            dips = (a2 > 0) & (vertex > 0) & (vertex < horizon) & (a0 - a1 * a1 / (4 * a2) <= 0)
        risky = np.flatnonzero((end <= 0) | dips)
    else:
        risky = np.arange(len(faces))
    a0, a1, a2 = a0[risky], a1[risky], a2[risky]
    r_best = np.full(len(risky), np.inf)
    with np.errstate(divide="ignore", invalid="ignore"):
        linear = np.abs(a2) <= 1e-14 * np.abs(a0)
        root = -a0 / a1
        r_best = np.where(linear & (root > 0), root, r_best)
        disc = a1 * a1 - 4 * a2 * a0
        sq = np.sqrt(np.maximum(disc, 0.0))
        for r in ((-a1 - sq) / (2 * a2), (-a1 + sq) / (2 * a2)):
            ok = ~linear & (disc >= 0) & (r > 0)
            r_best = np.where(ok & (r < r_best), r, r_best)
    t[risky] = r_best
    return t


def best_scale(vertices: np.ndarray, edges: np.ndarray, uv: np.ndarray) -> float:
    """The uniform factor ``s`` that minimises the summed squared edge strain of ``s * uv``.

    Used on starting layouts that have no scale of their own (Tutte, LSCM),
    never on a result.
    """
    r = np.linalg.norm(uv[edges[:, 1]] - uv[edges[:, 0]], axis=1) / np.linalg.norm(
        vertices[edges[:, 1]] - vertices[edges[:, 0]], axis=1)
    return float(r.sum() / (r * r).sum())


def align_to_pins(uv: np.ndarray, index: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Move a layout rigidly (no scaling) so its pinned vertices best fit their targets."""
    a = uv[index]
    ca, cb = a.mean(axis=0), target.mean(axis=0)
    if len(index) < 2:
        return uv + (cb - ca)
    u, _, vt = np.linalg.svd((a - ca).T @ (target - cb))
    rot = vt.T @ np.diag([1.0, np.sign(np.linalg.det(vt.T @ u.T))]) @ u.T
    return (uv - ca) @ rot.T + cb


def relax(vertices: np.ndarray, faces: np.ndarray, conn: Connectivity, start: np.ndarray, *,
          pins=None, barrier: float = 1e-3, max_iterations: int = 500, tolerance: float = 1e-4,
          progress=None, local=None, min_stretch=None) -> Relaxation:
    """Relax a one-to-one layout towards true edge lengths, keeping it one-to-one.

    See the module docstring for the method.

    Parameters
    ----------
    vertices : (n, 3) float64
    faces : (m, 3) int64
    conn : Connectivity
    start : (n, 2) float64
        A layout without folded triangles and with valid boundary loops.
    pins : tuple of ((k,) int, (k, 2) float), optional
        Vertices to hold and their flat positions (libigl's ``b, bc``).  They
        are approached step by step first; if reaching them would fold or
        overlap the pattern they stop short (``converged`` is then False).
    barrier : float
        Starting barrier weight ``mu`` (>= 0): 0.1 for a start far from the
        answer (a conformal or Tutte layout), 1e-3 for a near one (the greedy
        layout); 0 minimises the stress alone from the start.
    max_iterations : int
        > 0; pin travel and quasi-Newton iterations together.
    tolerance : float
        Stop when the stress falls by less than this fraction per iteration
        (averaged over two); a barrier stage ends at 30 times this.
    progress : callable, optional
        ``progress(iteration, max_iterations)`` after each iteration.
    local : (m, 3) complex128, optional
        :func:`patterns.measure.local_coordinates` of the mesh, if already at
        hand (computed otherwise).
    min_stretch : float in (0, 1), optional
        Guard against crushed triangles: every stage, the last included, adds
        ``sum_t w_t max(0, |J_t^-1|^2 - f)**2`` with ``f = 1 + 1 / min_stretch**2``
        (the value of a triangle squeezed to ``min_stretch`` one way and kept
        the other), which is zero wherever no triangle is squeezed that far.

    Returns
    -------
    Relaxation
    """
    n = len(vertices)
    e = conn.edges
    length = edge_lengths(vertices, e)
    uv = np.array(start, dtype=np.float64)
    floor = 1e-20 * len(length)  # RMS edge strain 1e-10: round-off level
    if pins is None and np.sum((edge_lengths(uv, e) / length - 1) ** 2) <= floor:
        uv.setflags(write=False)  # already exact (a developable part): nothing to relax
        return Relaxation(uv, 0, True)
    weight = 1.0 / length**2
    free = np.ones(n, dtype=bool)
    if pins is None:
        # The stress does not see translations: tie vertex 0 softly.  For the
        # preconditioner only; the energy itself has no anchor term.
        anchor = float(weight.mean())
        system = _laplacian(n, e, weight, anchor=anchor)
        iterations = 0
    else:
        pin_index, pin_target = pins
        free[pin_index] = False
        laplacian = _laplacian(n, e, weight)
        system = laplacian[free][:, free]
        uv, iterations = _travel_to_pins(faces, conn.loops, e, length, weight, laplacian, free, uv, pin_index,
                                         pin_target, max_iterations, progress)
        if not np.allclose(uv[pin_index], pin_target, rtol=0, atol=1e-9 * _size(uv)):
            uv.setflags(write=False)
            return Relaxation(uv, iterations, False)
        uv[pin_index] = pin_target
    # The preconditioner only shapes the steps (energy, gradients and line
    # search are double precision): the plain Laplacian is factorised in
    # single precision, a third faster to factorise and to solve with, with
    # the same iterations and result to 4 digits at 100k and 1M faces.  The
    # barrier-stiffened refactorisations below, whose weights span up to twelve
    # orders of magnitude, stay in double.
    lu = factorize(system, single=True)
    energy = _StressBarrier(vertices, faces, e, length, local=local, min_stretch=min_stretch)
    stiffened = []  # the _StiffLaplacian, made at the first refactorisation

    def refactor(u, mu):
        """The Laplacian with the barrier's curvature added to its weights, factorised."""
        stiff = energy.barrier_stiffness(u, mu)
        extra = np.zeros(len(e))
        for k in range(3):
            extra += np.bincount(conn.face_edges[:, k], stiff, len(e))
        if np.mean(extra > 1.0) < 0.1:
            # The barrier at most doubles the curvature of under a tenth of the
            # edges (a few squeezed triangles): not worth a factorisation.
            return lu
        if not stiffened:
            stiffened.append(_StiffLaplacian(e, free, anchor=anchor if pins is None else 0.0))
        return stiffened[0].factorize(weight * (1.0 + 0.5 * extra))

    uv, used, converged = _quasi_newton(energy, faces, conn.loops, uv, free, lu, refactor=refactor, barrier=barrier,
                                        max_iterations=max_iterations - iterations, tolerance=tolerance,
                                        floor=floor, progress=progress, offset=iterations,
                                        total=max_iterations)
    uv.setflags(write=False)
    return Relaxation(uv, iterations + used, converged)


class _StressBarrier:
    """Edge stress plus ``mu`` times a collapse barrier, and its gradient.

    ``E(u) = sum_e (|u_i - u_j| / l_e - 1)**2 + mu * sum_t w_t |J_t^-1|_F**2``
    with ``J_t`` the triangle's 2x2 Jacobian from its 3D frame to the plane and
    ``w_t`` its 3D area over the mean area, times 0.75 (the barrier term of a
    mesh then counts about as many terms as the stress, half as many as edges).
    ``|J^-1|_F**2 = |J|_F**2 / det(J)**2`` is 2 for a rigid motion and grows
    without bound as the triangle collapses.

    The two terms are evaluated apart (:meth:`parts`) so that a change of
    ``mu`` needs no new evaluation.  Coordinates are gathered column by column
    (several times faster than gathering ``(k, 2)`` rows) and gradients
    scattered by sparse products.
    """

    def __init__(self, vertices, faces, edges, length, *, local=None, min_stretch=None):
        n = len(vertices)
        # |J^-1|^2 = 1/s1^2 + 1/s2^2 of a triangle squeezed to min_stretch one way, kept the other.
        self.floor = 0.0 if not min_stretch else 1.0 + 1.0 / min_stretch**2
        self.faces, self.edges, self.length = faces, edges, length
        self._e0, self._e1 = np.ascontiguousarray(edges[:, 0]), np.ascontiguousarray(edges[:, 1])
        self._f0, self._f1, self._f2 = (np.ascontiguousarray(faces[:, k]) for k in range(3))
        z = local_coordinates(vertices, faces) if local is None else local
        r1, r2 = z[:, 1] - z[:, 0], z[:, 2] - z[:, 0]
        # R = [[r1.x, r2.x], [r1.y, r2.y]]; G = R^-1 R^-T (symmetric).
        det_r = r1.real * r2.imag - r2.real * r1.imag
        i11, i12, i21, i22 = r2.imag / det_r, -r2.real / det_r, -r1.imag / det_r, r1.real / det_r
        self.g11, self.g12, self.g22 = i11 * i11 + i12 * i12, i11 * i21 + i12 * i22, i21 * i21 + i22 * i22
        self.det_r2 = det_r * det_r
        area = 0.5 * np.abs(det_r)
        self.w = 0.75 * area / area.mean()
        ne, m = len(edges), len(faces)
        self._inv_length = 1.0 / length
        # Sparse scatter matrices: per-edge and per-triangle-column gradients to vertices.
        self.edge_scatter = sp.csr_matrix((np.r_[np.ones(ne), -np.ones(ne)],
                                           (np.r_[self._e1, self._e0], np.r_[np.arange(ne), np.arange(ne)])),
                                          shape=(n, ne))
        cols = np.arange(2 * m)
        self.face_scatter = sp.csr_matrix(
            (np.r_[np.ones(2 * m), -np.ones(2 * m)],
             (np.r_[self._f1, self._f2, self._f0, self._f0], np.r_[cols, cols])), shape=(n, 2 * m))

    def _jacobian(self, u):
        """Per-triangle ``(P columns a, b, c, d; det P; P G entries; |J|^2)`` of the flat map."""
        x, y = u[:, 0], u[:, 1]
        x0, y0 = x.take(self._f0), y.take(self._f0)
        a, b = x.take(self._f1) - x0, x.take(self._f2) - x0  # P = [[a, b], [c, d]]
        c, dd = y.take(self._f1) - y0, y.take(self._f2) - y0
        det_p = a * dd - b * c
        pg11, pg12 = a * self.g11 + b * self.g12, a * self.g12 + b * self.g22
        pg21, pg22 = c * self.g11 + dd * self.g12, c * self.g12 + dd * self.g22
        norm_j = a * pg11 + b * pg12 + c * pg21 + dd * pg22  # |J|^2 (times nothing: G carries R)
        return a, b, c, dd, det_p, (pg11, pg12, pg21, pg22), norm_j

    def barrier_stiffness(self, u, mu):
        """Per-triangle curvature scale of the barrier term, ``(m,)``: ``mu w 6 / sigma_min**4``."""
        *_, det_p, _, norm_j = self._jacobian(u)
        det2 = det_p * det_p / self.det_r2  # det(J)**2
        # Smallest singular value squared, in the cancellation-free form
        # det**2 / (largest one squared).
        smin2 = 2.0 * det2 / (norm_j + np.sqrt(np.maximum(norm_j * norm_j - 4.0 * det2, 0.0)))
        with np.errstate(divide="ignore", over="ignore"):
            return np.minimum(mu * self.w * 6.0 / (smin2 * smin2), 1e12)

    def stress(self, u):
        """``(S, gradient (n, 2))``: the summed squared edge strain."""
        x, y = u[:, 0], u[:, 1]
        dx = x.take(self._e1) - x.take(self._e0)
        dy = y.take(self._e1) - y.take(self._e0)
        dl = np.sqrt(dx * dx + dy * dy)
        r = dl * self._inv_length - 1.0
        k = 2.0 * r * self._inv_length / np.maximum(dl, 1e-300)
        return float(r @ r), self.edge_scatter @ np.column_stack([k * dx, k * dy])

    def barrier(self, u):
        """``(B, gradient (n, 2))`` of the barrier (``mu = 1``); ``(inf, None)`` if a triangle is folded."""
        return self._inverse_term(u, 0.0)

    def guard(self, u):
        """``(sum_t w_t max(0, |J_t^-1|^2 - floor)**2, gradient (n, 2))``; ``(inf, None)`` if folded.

        Zero on every triangle squeezed less than ``min_stretch`` allows.
        """
        return self._inverse_term(u, self.floor)

    def _inverse_term(self, u, floor):
        """The barrier (``floor == 0``) or the guard, with its gradient."""
        a, b, c, dd, det_p, (pg11, pg12, pg21, pg22), norm_j = self._jacobian(u)
        if not np.all(det_p > 0):
            return np.inf, None
        s = self.det_r2 / (det_p * det_p)
        if floor > 0:
            excess = np.maximum(norm_j * s - floor, 0.0)  # |J^-1|^2 beyond the floor
            value = float(self.w @ (excess * excess))
            ws = 2.0 * self.w * excess * s
        else:
            ws = self.w * s
            value = float(ws @ norm_j)
        k1 = 2.0 * ws
        k2 = k1 * norm_j / det_p
        # d/dP of |J|^2 det_r^2 / det_p^2 = 2 P G s - 2 |J|^2 s / det_p * cof(P),
        # cof(P) = [[dd, -c], [-b, a]].
        gx = np.concatenate([k1 * pg11 - k2 * dd, k1 * pg12 + k2 * c])
        gy = np.concatenate([k1 * pg21 + k2 * b, k1 * pg22 - k2 * a])
        return value, self.face_scatter @ np.column_stack([gx, gy])

    def parts(self, u, mu):
        """``(S, grad S, B, grad B)``; B is 0 (gradient None) when ``mu == 0``, inf when folded.

        ``S`` includes the guard against crushed triangles when ``min_stretch`` was given.
        """
        value, grad = self.stress(u)
        if self.floor:
            g_value, g_grad = self.guard(u)
            if g_grad is None:
                return np.inf, None, np.inf, None
            value, grad = value + g_value, grad + g_grad
        if mu == 0:
            return value, grad, 0.0, None
        b_value, b_grad = self.barrier(u)
        return value, grad, b_value, b_grad

    def __call__(self, u, mu):
        """``(E, gradient (n, 2))``; ``(inf, None)`` if ``mu > 0`` and a triangle is folded."""
        value, grad, b_value, b_grad = self.parts(u, mu)
        if mu == 0:
            return value, grad
        if b_grad is None:
            return np.inf, None
        return value + mu * b_value, grad + mu * b_grad


def _quasi_newton(energy, faces, loops, uv, free, lu, *, refactor, barrier, max_iterations, tolerance, floor,
                  progress, offset, total):
    """L-BFGS with a Laplacian ``H0`` and a flip-free, non-crossing line search.

    ``H0 = A^-1 / 2`` with ``A`` the stress Laplacian (plus the barrier's
    curvature while the barrier is on, refreshed every ``_REFRESH``
    iterations), scaled by the latest ``s.y / y.H0 y``.  ``H0`` is applied to
    each accepted gradient once and kept, so that the two-loop recursion needs
    no further solve.  The memory is dropped only when ``H0`` changes.
    Returns ``(uv, iterations, converged)``.
    """
    size = _size(uv)
    mu = float(barrier)
    everywhere = bool(free.all())

    def restrict(g):
        return g if everywhere else g[free]

    def evaluate(u):
        """``(E, grad E on the free vertices, S, grad S, B, grad B)``; E is inf when folded."""
        s_value, s_grad, b_value, b_grad = energy.parts(u, mu)
        if s_grad is None:  # folded (seen by the guard)
            return np.inf, None, s_value, s_grad, b_value, b_grad
        if mu == 0:
            return s_value, restrict(s_grad), s_value, s_grad, b_value, b_grad
        if b_grad is None:
            return np.inf, None, s_value, s_grad, b_value, b_grad
        return s_value + mu * b_value, restrict(s_grad + mu * b_grad), s_value, s_grad, b_value, b_grad

    value, grad, *terms = evaluate(uv)
    base = lu
    since_refresh = _REFRESH  # refresh at once if the barrier is on
    history = []  # (s, y, H0 y)
    recent = [value]
    iterations = 0
    converged = False
    hgrad = None
    while iterations < max_iterations:
        iterations += 1
        if mu > 0 and since_refresh >= _REFRESH:
            fresh, since_refresh = refactor(uv, mu), 0
            if fresh is not lu:
                lu, hgrad, history = fresh, None, []
        since_refresh += 1
        if hgrad is None:
            hgrad = 0.5 * lu.solve(grad)
        direction = np.zeros_like(uv)
        direction[free] = -_two_loop(grad, hgrad, history)
        slope = _dot(grad, restrict(direction))
        if not slope < 0:  # stale memory: fall back to the preconditioned gradient
            history = []
            direction[free] = -hgrad
            slope = _dot(grad, restrict(direction))
        step = min(1.0, 0.9 * float(flip_free_steps(faces, uv, direction, horizon=1.0 / 0.9).min()))
        # Steps below round-off of the layout's size make no progress.
        smallest = 1e-13 * size / max(float(np.abs(direction).max()), 1e-300)
        moved = False
        while step > smallest:
            cand = uv + step * direction
            new_value, new_grad, *new_terms = evaluate(cand)
            if new_value <= value + 1e-4 * step * slope and _boundary_crossings(cand, loops) is None:
                moved = True
                break
            step *= 0.5
        if moved:
            new_hgrad = 0.5 * lu.solve(new_grad)
            s, y = restrict(cand - uv), new_grad - grad
            if _dot(s, y) > 0:
                history.append((s, y, new_hgrad - hgrad))
                del history[:-_MEMORY]
            uv, value, grad, hgrad, terms = cand, new_value, new_grad, new_hgrad, new_terms
        if progress is not None:
            progress(offset + iterations, total)
        if not moved and history:
            history = []  # retry once from the plain preconditioned gradient
            continue
        last = mu == 0.0
        # Progress is judged over a window of iterations: single quasi-Newton
        # steps vary too much (a short step is often followed by a long one).
        recent.append(value)
        gain = recent[0] - value if len(recent) > _WINDOW else np.inf
        del recent[:-_WINDOW - 1]
        stalled = not moved or gain <= _WINDOW * tolerance * (1.0 if last else _STAGE_TOLERANCE) * value
        if last and (stalled or value <= floor):
            converged = True
            break
        if stalled:  # next stage: a tenth of the barrier, or none; the terms are at hand
            mu = mu * _DROP if mu > _WEAKEST * 1.5 else 0.0
            s_value, s_grad, b_value, b_grad = terms
            value = s_value + mu * b_value
            grad = restrict(s_grad + mu * b_grad) if mu > 0 else restrict(s_grad)
            fresh, since_refresh = (refactor(uv, mu) if mu > 0 else base), 0
            lu, history, hgrad, recent = fresh, [], None, [value]
    return uv, iterations, converged


def _dot(a: np.ndarray, b: np.ndarray) -> float:
    """Sum of the elementwise product of two arrays of one shape, without a temporary."""
    return float(np.vdot(a, b))


def _two_loop(grad, hgrad, history):
    """L-BFGS two-loop recursion; ``H0`` products come precomputed (``hgrad``, ``H0 y``)."""
    alphas = []
    for s, y, _ in reversed(history):
        alphas.append(_dot(s, grad) / _dot(y, s))
        grad = grad - alphas[-1] * y
    # H0 q = H0 g - sum a_i H0 y_i (H0 is linear).
    r = hgrad.copy()
    for (_, _, hy), a in zip(reversed(history), alphas):
        r -= a * hy
    if history:
        s, y, hy = history[-1]
        r *= _dot(s, y) / _dot(y, hy)
    for (s, y, _), a in zip(history, reversed(alphas)):
        b = _dot(y, r) / _dot(y, s)
        r += (a - b) * s
    return r


def _travel_to_pins(faces, loops, e, length, weight, laplacian, free, uv, pin_index, pin_target,
                    max_iterations, progress):
    """Move the pins onto their targets by stress-majorization steps, staying one-to-one.

    Each step aims at the minimiser of the stress's majorizer with the pins at
    their targets (one solve with the Laplacian's free block), cut vertex by
    vertex so nothing folds or crosses.  Returns ``(uv, iterations)``.
    """
    n = len(uv)
    lu = factorize(laplacian[free][:, free])
    coupling = laplacian[free][:, ~free]
    size = _size(uv)
    iterations = 0
    while iterations < max_iterations and not np.allclose(uv[pin_index], pin_target, rtol=0, atol=1e-9 * size):
        iterations += 1
        d = uv[e[:, 1]] - uv[e[:, 0]]
        dl = np.sqrt(d[:, 0] ** 2 + d[:, 1] ** 2)
        q = d * (weight * length / np.maximum(dl, 1e-300))[:, None]
        rhs = np.empty((n, 2))
        for k in range(2):
            rhs[:, k] = np.bincount(e[:, 1], q[:, k], n) - np.bincount(e[:, 0], q[:, k], n)
        target = np.empty((n, 2))
        target[~free] = pin_target
        target[free] = lu.solve(rhs[free] - coupling @ pin_target)
        moved = _safe_move(faces, loops, uv, target)
        if progress is not None:
            progress(iterations, max_iterations)
        if moved is uv:
            break
        uv = moved
    return np.array(uv), iterations


class _StiffLaplacian:
    """The weighted Laplacian's free block, refactorised for new edge weights.

    The same matrix as ``_laplacian(n, edges, weight, anchor=anchor)[free][:, free]``;
    the pattern never changes, so an :class:`~patterns.flatten.embed.LDL` keeps
    its ordering and elimination tree and each refactorisation is numeric only.
    Each :meth:`factorize` overwrites the previous factor.
    """

    def __init__(self, edges: np.ndarray, free: np.ndarray, *, anchor: float = 0.0):
        n, k = len(free), int(free.sum())
        index = np.cumsum(free) - 1
        self._inner = free[edges[:, 0]] & free[edges[:, 1]]
        a, b = index[edges[self._inner, 0]], index[edges[self._inner, 1]]
        node = np.arange(k)
        self._ldl = LDL(k, np.r_[np.minimum(a, b), node], np.r_[np.maximum(a, b), node])
        self._edges, self._free, self._n, self._anchor = edges, free, n, anchor

    def factorize(self, weight: np.ndarray) -> LDLFactor:
        """Factorise with edge weights ``weight`` ``(k,) float64``."""
        diagonal = _degrees(self._n, self._edges, weight, anchor=self._anchor)
        return self._ldl.factorize(np.r_[-weight[self._inner], diagonal[self._free]])


def _laplacian(n: int, edges: np.ndarray, weight: np.ndarray, *, anchor: float = 0.0) -> sp.csc_matrix:
    """The graph Laplacian ``D - W`` with edge weights ``weight`` (plus ``anchor`` at vertex 0), ``(n, n)`` CSC."""
    e0, e1 = edges[:, 0], edges[:, 1]
    diagonal = _degrees(n, edges, weight, anchor=anchor)
    node = np.arange(n)
    return sp.csc_matrix((np.r_[-weight, -weight, diagonal], (np.r_[e0, e1, node], np.r_[e1, e0, node])),
                         shape=(n, n))


def _degrees(n: int, edges: np.ndarray, weight: np.ndarray, *, anchor: float = 0.0) -> np.ndarray:
    """The Laplacian's diagonal ``(n,)``: each vertex's summed edge weight, plus ``anchor`` at vertex 0."""
    diagonal = np.bincount(edges[:, 0], weight, n) + np.bincount(edges[:, 1], weight, n)
    diagonal[0] += anchor
    return diagonal


def _size(uv: np.ndarray) -> float:
    return float(np.ptp(uv, axis=0).max()) or 1.0


def _safe_move(faces: np.ndarray, loops, uv: np.ndarray, target: np.ndarray, *, tries: int = 40) -> np.ndarray:
    """Move towards ``target`` as far as possible, vertex by vertex, staying one-to-one.

    Returns ``uv`` itself (the same object) when no move is possible.
    """
    step = target - uv
    n = len(uv)
    alpha = np.ones(n)
    per_face = np.minimum(0.9 * flip_free_steps(faces, uv, step, horizon=1.0 / 0.9), 1.0)
    np.minimum.at(alpha, faces.ravel(), np.repeat(per_face, 3))
    for attempt in range(2 * tries):
        cand = uv + alpha[:, None] * step
        bad = ~(signed_areas(faces, cand) > 0)
        crossing = None if bad.any() else _boundary_crossings(cand, loops)
        if not bad.any() and crossing is None:
            return cand
        if attempt >= tries:
            # Local cuts did not settle it: shrink the whole step instead (the
            # zero step is always safe, so this ends or returns uv).
            alpha *= 0.5
        elif bad.any():
            alpha[faces[bad].ravel()] *= 0.5
        elif len(crossing):
            alpha[crossing] *= 0.25
        else:
            alpha *= 0.5
    return uv


def _boundary_crossings(uv: np.ndarray, loops):
    """None when the flat loops form a valid polygon; else the vertices of the
    boundary segments that cross another one (possibly empty)."""
    rings = [uv[loop] for loop in loops]
    if shapely.is_valid(shapely.Polygon(rings[0], rings[1:])):
        return None
    _, pair, i, j = crossing_segments(uv, loops)
    return np.unique(np.concatenate([pair[i].ravel(), pair[j].ravel()]))


def check_pins(pins, n: int, name: str):
    """Validate ``pins = (index, positions)``; returns ``(int64 (k,), float64 (k, 2))``."""
    try:
        index, positions = pins
        index = np.asarray(index)
        positions = np.asarray(positions, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError(f"{name}: pins must be (vertex indices (k,), positions (k, 2))") from None
    if index.ndim != 1 or positions.shape != (len(index), 2) or len(index) == 0:
        raise InputError(f"{name}: pins must be (vertex indices (k,), positions (k, 2)) with k >= 1, "
                         f"got shapes {index.shape} and {positions.shape}")
    if not np.issubdtype(index.dtype, np.integer) or index.min() < 0 or index.max() >= n:
        raise InputError(f"{name}: pinned vertex indices must be integers in [0, {n})")
    if len(np.unique(index)) != len(index):
        raise InputError(f"{name}: a vertex is pinned twice")
    if not np.all(np.isfinite(positions)):
        raise InputError(f"{name}: pin positions must be finite")
    return index.astype(np.int64), positions
