"""Fold-free relaxation of a flat layout: least distortion of the surface-to-plane map.

The relaxation minimises an area-weighted distortion energy of the map from
the surface to the plane (:mod:`patterns.flattening.energy`) -- by default
``"arap"``, the sum of squared principal strains weighted by 3D area, the
material's strain -- while every triangle keeps its orientation and the flat
boundary never crosses itself.  Chosen edges (the seams of a pattern) can be
held at target lengths.

Method
------
* **Energy.**  ``E + mu B + G + S``: the distortion ``E``; the collapse barrier
  ``B = sum_t W_t |J_t^-1|^2``, whose weight ``mu`` starts at ``barrier`` and
  is cut tenfold each time progress stalls, down to 0 in the last stage (it
  keeps triangles open while a far start -- the conformal layout of a head --
  moves towards the answer); the optional guard ``G`` against crushed
  triangles (``min_stretch``); the optional seam term ``S``, an augmented
  Lagrangian whose multipliers are updated each time the last stage
  converges, until every held edge is within ``length_tolerance`` of its
  target.
* **Steps.**  L-BFGS whose initial inverse Hessian is ``K^-1``, ``K`` the
  energy's curvature at an isometry: the cotangent Laplacian (the Hessian of
  ``sum_t W_t |J_t|^2``), with the seam term's stiffness added along the held
  edges.  While the barrier is strong, or for the symmetric Dirichlet energy
  where triangles are squeezed, each triangle's block is stiffened by its
  ``1 + 3 mu / sigma_min**4`` and the matrix refactorised numerically only
  (qdldl's ``L D L^T``, ordering and elimination tree kept; a scalar version
  of SLIM's proxy).  The L-BFGS memory is kept until the matrix changes.
* **Line search.**  Each step is capped at 0.9 of the first time any triangle
  would flip (exact quadratic roots, :func:`flip_free_steps`), then halved until
  the energy drops (Armijo) and the boundary loops are still a valid polygon
  (shapely).  A start without folds and with valid loops therefore ends
  without folds and without overlap, by the same degree argument as
  :mod:`patterns.audit`.  Nothing is ever rescaled.
* **Far, crushed starts.**  A start with 1 % of its area squeezed below a
  stretch of 1e-2 (the thin limbs of a conformal or Tutte layout: a hand's
  fingertips at 1e-6 of their size) is first carried near by at most 20
  reweighted local-global steps of SLIM's proxy (:mod:`.slim`), then relaxed
  from there without barrier stages, the L-BFGS ``H0`` being the energy's
  projected Newton Hessian (:mod:`.hessian`, refactorised every 4 iterations)
  instead of the stiffened Laplacian, which cannot describe triangles
  stretched 7:1 one way; ``"auto"`` then minimises the hybrid at
  once (ARAP's fold-free minimum crushed a triangle on every such mesh of the
  two corpora: the OptCuts hands, armadillo, dinosaur and torso, two BFF
  heads).  Gradient steps inflate such parts by a few per cent an iteration:
  300-400 iterations where the reweighted steps take 12-20, and the
  Laplacian-preconditioned tail after them 250-500 where this one takes 30-110.
  SLIM's proxy does not see the outline: where a reweighted step would run it
  into itself (libigl's camel, its legs pressed together), the steps are
  dropped and the start takes the barrier path below instead.
* **Pins** are reached first by stress-majorization steps cut vertex by vertex
  (:func:`_travel_to_pins`), then held while the rest relaxes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..mesh import Connectivity, edge_lengths
from .embed import LDL, LDLFactor, factorize
from .energy import BY_NAME, ENERGIES, Arap, EdgeLengths, Hybrid, InverseTerm, dot, frames
from .hessian import PairFactor, PairSystem, projected_hessian
from .moves import edge_index, flip_free_steps, layout_size, outline_valid, safe_move
from .slim import SLIM_STEPS, crushed_start, reweighted

_WINDOW = 2  # iterations over which progress is judged
_STAGE_TOLERANCE = 30.0  # a barrier stage ends at this many times the tolerance
_REFRESH = 5  # iterations between refactorisations while the matrix is stiffened
_REFRESH_NEWTON = 4  # iterations between projected Hessians after reweighted steps from a crushed start (lucy,
# hand_yaron, hand_1: 1, 2, 4, 8 measured; 4 the fastest, a factorisation costing about 4 L-BFGS iterations)
_IMMATERIAL = 1e-14  # the relaxation stops at an energy of this per triangle: RMS strain 1e-7, 0.1 um a metre
# (BFF's maze, nearly developable: 25 iterations to 5.3e-11 from 1.35e-9, then 0.3 % per 25 to the cap; an exact
# development never gets here: it is caught before any step, at RMS strain 1e-10)
_PROXIMAL = 1e-6  # the projected Hessian's diagonal is raised by this fraction of its mean (a rigid turn is free)
_MEMORY = 8  # L-BFGS pairs kept
_JUMP = 0.1  # a step that cuts the energy below this fraction refactorises the stiffened matrix at once
_DROP = 0.1  # the barrier weight is multiplied by this at each new stage
_WEAKEST = 1e-5  # the last barrier stage before the energy alone
_SEAM_RHO = 300.0  # seam penalty weight, relative to the held edge's triangle (30: slow rounds; 1000: stiffer steps)
_SEAM_ROUNDS = 20  # most multiplier updates
_CRUSHED = 1e-3  # "auto": ARAP's layout with a triangle squeezed below this stretch is redone with the hybrid
_PROBE = 10.0  # "auto" from a far start: the first ARAP run stops at this many times the tolerance

__all__ = ["ENERGIES", "Relaxation", "is_isometric", "relax"]


@dataclass(frozen=True, eq=False)
class Relaxation:
    """Result of :func:`relax`.

    Attributes
    ----------
    uv : (n, 2) float64
    iterations : int
    converged : bool
        The relative decrease of the energy fell below the tolerance, the pins
        (if any) were reached and the held edges (if any) came within their
        tolerance, before ``max_iterations``.
    length_error : float
        Largest ``|l_flat / l_target - 1|`` over the held edges (0 without any).
    energy : str
        The energy minimised: ``"arap"``, ``"hybrid"`` or ``"symmetric-dirichlet"``
        (what ``"auto"`` chose).
    """

    uv: np.ndarray
    iterations: int
    converged: bool
    length_error: float = 0.0
    energy: str = "arap"


def relax(vertices: np.ndarray, faces: np.ndarray, conn: Connectivity, start: np.ndarray, *,
          energy: str = "auto", pins=None, lengths=None, length_tolerance: float = 1e-4, barrier: float = 1e-3,
          max_iterations: int = 500, tolerance: float = 1e-4, progress=None, local=None,
          min_stretch=None) -> Relaxation:
    """Relax a one-to-one layout towards least distortion, keeping it one-to-one.

    See the module docstring for the method.

    Parameters
    ----------
    vertices : (n, 3) float64
    faces : (m, 3) int64
    conn : Connectivity
    start : (n, 2) float64
        A layout without folded triangles and with valid boundary loops.
    energy : {"auto", "arap", "hybrid", "symmetric-dirichlet"}
        The distortion minimised (:mod:`patterns.flattening.energy`).  ``"auto"``
        minimises ARAP, the squared principal strains; where its fold-free
        minimum presses a triangle flat (a stretch below 1e-3: the layout
        that least strains the material would fold there), it goes on from
        that layout with the hybrid energy, which holds triangles open (at
        once from a far start with crushed parts, see the module).
    pins : tuple of ((k,) int, (k, 2) float), optional
        Vertices to hold and their flat positions (libigl's ``b, bc``).  They
        are approached step by step first; if reaching them would fold or
        overlap the pattern they stop short (``converged`` is then False).
    lengths : tuple of ((k, 2) int, (k,) float[, (k,) int]), optional
        Edges (each an edge of the mesh) and the flat lengths to hold them at,
        in the mesh unit: the seams of a pattern.  With a third array, the
        edges of one group are held in total (a seam side's length), not one
        by one.
    length_tolerance : float
        The held lengths are done when every group's ``|l_flat / l_target - 1|``
        is below this (> 0).
    barrier : float
        Starting barrier weight ``mu`` (>= 0) of the ARAP energy: 0.1 for a
        start far from the answer (a conformal or Tutte layout), 0 for a near
        one (the greedy layout).  The other energies are barriers themselves.
    max_iterations : int
        > 0; pin travel and quasi-Newton iterations together.
    tolerance : float
        Stop when the energy falls by less than this fraction per iteration
        (averaged over two); a barrier stage ends at 30 times this.  The last
        stage also stops below 1e-14 per triangle (RMS strain 1e-7: 0.1 um in
        a metre).
    progress : callable, optional
        ``progress(iteration, max_iterations)`` after each iteration.
    local : (m, 3) complex128, optional
        :func:`patterns.measure.local_coordinates` of the mesh, if already at
        hand (computed otherwise).
    min_stretch : float in (0, 1), optional
        Guard against crushed triangles: every stage, the last included, adds
        ``sum_t W_t max(0, |J_t^-1|^2 - f)**2`` with ``f = 1 + 1 / min_stretch**2``
        (the value of a triangle squeezed to ``min_stretch`` one way and kept
        the other), which is zero wherever no triangle is squeezed that far.

    Returns
    -------
    Relaxation
    """
    n = len(vertices)
    uv = np.array(start, dtype=np.float64)
    fr = frames(vertices, faces, local=local)
    seam, seam_index = _seam_term(n, conn, fr, lengths)
    floor = 1e-20 * len(faces)  # RMS strain 1e-10: round-off level
    if pins is None and seam is None and _isometric(fr, uv, floor):
        uv.setflags(write=False)  # already exact (a developable part): nothing to relax or factorise
        return Relaxation(uv, 0, True, energy="arap" if energy == "auto" else energy)
    free = np.ones(n, dtype=bool)
    iterations = 0
    if pins is not None:
        pin_index, pin_target = pins
        free[pin_index] = False
        uv, iterations = _travel_to_pins(faces, conn.loops, conn.edges, edge_lengths(vertices, conn.edges), free, uv,
                                         pin_index, pin_target, max_iterations, progress)
        if not np.allclose(uv[pin_index], pin_target, rtol=0, atol=1e-9 * layout_size(uv)):
            uv.setflags(write=False)
            return Relaxation(uv, iterations, False, _length_error(seam, uv), "arap" if energy == "auto" else energy)
        uv[pin_index] = pin_target
    carried = barrier > 0 and pins is None and crushed_start(fr, uv)
    pair = None
    if carried:
        # A far start with crushed parts (the thin limbs of a conformal or Tutte layout): carried near by
        # reweighted steps first (:mod:`.slim`), then relaxed from there with no barrier stages.  "auto"
        # goes to the hybrid at once: ARAP's minimum crushed a triangle on every such mesh measured.
        steps = min(SLIM_STEPS, max_iterations - iterations)
        pair = PairSystem(fr, n)
        far = "hybrid" if energy == "auto" else energy
        moved = reweighted(fr, uv, conn.loops, energy=far, iterations=steps, system=pair)
        iterations += moved.used
        if moved.blocked:
            # The steps would run the outline into itself (a camel's legs pressed together): SLIM's proxy
            # does not see the outline, so the barrier path goes from the start instead.
            carried, pair = False, None
        else:
            uv, barrier, energy = moved.uv, 0.0, far
    guard = InverseTerm(fr, 1.0 + 1.0 / min_stretch**2) if min_stretch else None
    system = _System(conn, fr, free, seam, seam_index, pair=pair)
    chosen = "arap" if energy == "auto" else energy
    main = BY_NAME[chosen](fr)
    converged = False
    # "auto" from a far start: a first, looser ARAP run tells whether ARAP crushes
    # triangles (then the hybrid goes on from there) before it is run to the end.
    probe = energy == "auto" and barrier > 0
    mu = barrier
    while True:
        run = _Minimiser(_Objective(main, InverseTerm(fr), guard, seam), system, faces, conn.loops, free,
                         tolerance=tolerance * (_PROBE if probe else 1.0), floor=_IMMATERIAL * len(faces),
                         length_tolerance=length_tolerance, progress=progress, offset=iterations,
                         total=max_iterations, refresh=_REFRESH_NEWTON if carried else _REFRESH)
        uv, used, converged = run(uv, mu if chosen == "arap" else 0.0, max_iterations - iterations)
        iterations += used
        if energy != "auto" or chosen != "arap" or iterations >= max_iterations:
            break
        if _crushed(fr, uv):
            chosen, main, probe = "hybrid", Hybrid(fr), False
        elif probe:
            probe, mu = False, 0.0  # not crushed: ARAP to the full tolerance, from there
        else:
            break
    uv.setflags(write=False)
    return Relaxation(uv, iterations, converged, _length_error(seam, uv), chosen)


def _crushed(fr, uv) -> bool:
    """True when a triangle of ``uv`` is squeezed below ``_CRUSHED`` of its size in some direction."""
    return bool(fr.jacobian(uv).smallest_stretch_squared().min() < _CRUSHED**2)


def _isometric(fr, uv, floor) -> bool:
    """True when every triangle of ``uv`` is its 3D triangle moved rigidly, to round-off."""
    out = Arap(fr).terms(fr.jacobian(uv), grad=False)  # the value only
    return out[0] <= floor


def is_isometric(vertices: np.ndarray, faces: np.ndarray, uv: np.ndarray, *, local=None) -> bool:
    """True when the layout ``uv`` ``(n, 2)`` has no strain: ARAP energy at round-off level (RMS strain 1e-10).

    What :func:`relax` checks first; an exact development needs no relaxation.
    """
    return _isometric(frames(vertices, faces, local=local), uv, 1e-20 * len(faces))


def _seam_term(n, conn, fr, lengths):
    """The :class:`EdgeLengths` term of ``relax(lengths=...)`` and its edges' rows in ``conn.edges``, or None, None."""
    if lengths is None or not len(lengths[0]):
        return None, None
    edges, target = lengths[:2]
    groups = lengths[2] if len(lengths) > 2 else None
    edges = np.sort(np.asarray(edges, dtype=np.int64), axis=1)
    index = edge_index(conn.edges, edges)
    faces_of = conn.edge_faces[index]
    side = np.where(faces_of[:, 0] >= 0, faces_of[:, 0], faces_of[:, 1])
    group = np.arange(len(edges)) if groups is None else np.unique(np.asarray(groups), return_inverse=True)[1]
    weight = np.bincount(group, fr.weight[side])
    return EdgeLengths(n, edges, np.asarray(target, dtype=np.float64), group, weight, _SEAM_RHO), index


def _length_error(seam, uv) -> float:
    return 0.0 if seam is None else float(np.abs(seam.residual(uv)).max())


class _Objective:
    """The relaxation's energy in two parts, ``(E + G + S, B)``, so that a change of ``mu`` needs no evaluation.

    ``E`` the distortion, ``G`` the guard, ``S`` the seam term, ``B`` the
    barrier; the triangle terms' derivatives are summed before one scatter.
    """

    def __init__(self, main, barrier, guard, seam):
        self.main, self.barrier, self.guard, self.seam = main, barrier, guard, seam
        self.fr = main.fr

    def parts(self, u, mu):
        """``(F, grad F, B, grad B)`` with ``F = E + G + S``; ``B`` is 0 (gradient None) when ``mu == 0``.

        ``F`` is inf (gradient None) where a term that sees folds sees one, ``B`` likewise.
        """
        jac = self.fr.jacobian(u)
        out = self.main.terms(jac)
        if out is not None and self.guard is not None:
            extra = self.guard.terms(jac)
            out = None if extra is None else (out[0] + extra[0], tuple(x + y for x, y in zip(out[1], extra[1])))
        if out is None:
            return np.inf, None, np.inf, None
        value, grad = out[0], self.fr.gradient(*out[1])
        if self.seam is not None:
            s_value, s_grad = self.seam(u)
            value, grad = value + s_value, grad + s_grad
        if mu == 0:
            return value, grad, 0.0, None
        b_value, b_grad = self.barrier(u, jac)
        return value, grad, b_value, b_grad

    def value(self, u, mu):
        """``F + mu B`` at ``u`` as :meth:`parts` and the solver add it up, to the last bit, without a gradient
        (inf where folded): what a line search needs of a step it may not take."""
        jac = self.fr.jacobian(u)
        out = self.main.terms(jac, grad=False)
        if out is not None and self.guard is not None:
            extra = self.guard.terms(jac, grad=False)
            out = None if extra is None else (out[0] + extra[0], None)
        if out is None:
            return np.inf
        value = out[0]
        if self.seam is not None:
            value = value + self.seam(u, grad=False)[0]
        if mu == 0:
            return value
        b_value, _ = self.barrier(u, jac, grad=False)
        return np.inf if b_value == np.inf else value + mu * b_value


class _System:
    """The preconditioner ``K``: the energy's curvature as a weighted Laplacian, factorised.

    ``K = 2 L(s) + S`` on the free vertices (plus a small anchor at vertex 0
    when nothing is pinned: the energies do not see translations): ``2 L`` is
    the Hessian of ``sum_t W_t |J_t|^2``, ``L(s)`` the cotangent Laplacian
    with each triangle scaled by ``s_t`` (1 for ARAP at an isometry;
    ``1 + 3 / sigma_min**4`` for the symmetric Dirichlet energy, 4 at an
    isometry) and ``S`` the seam term's stiffness along the held edges.  The
    mesh comes in nested-dissection order; the plain matrix (``s = 1``) is
    factorised once (:func:`~patterns.flattening.embed.factorize`: qdldl, no
    BLAS beneath, the same bits on every CPU, up to ``EXACT_SIZE`` unknowns;
    SuperLU in float32 past it), stiffened ones refactorised numerically only
    by qdldl.
    """

    def __init__(self, conn, fr, free, seam, seam_index, *, pair: PairSystem | None = None):
        self.conn, self.fr, self.free, self.pair = conn, fr, free, pair
        self.extra = np.zeros(len(conn.edges))
        if seam is not None:
            np.add.at(self.extra, seam_index, seam.edge_weights())
        weight = self.weights(None)
        self.anchor = float(np.abs(weight).mean()) if free.all() else 0.0
        matrix = _laplacian(len(free), conn.edges, weight, anchor=self.anchor)
        self.plain = factorize(matrix if free.all() else matrix[free][:, free], single=True)
        self._stiff = None

    def weights(self, scale) -> np.ndarray:
        """Edge weights ``(e,)`` of ``K`` for triangle scales ``scale`` ``(m,)`` (None: all 1)."""
        coef = self.fr.dirichlet_weights(scale) * 2.0
        return np.bincount(self.conn.face_edges.ravel(), coef.ravel(), len(self.conn.edges)) + self.extra

    def hessian(self, u: np.ndarray, main) -> PairFactor:
        """The projected Hessian of ``main`` at ``u`` plus the seam stiffness, factorised (``pair`` given)."""
        values = self.pair.assemble(projected_hessian(self.fr, self.fr.jacobian(u), main.stretch,
                                                      columns=self.pair.columns, packed=True))
        if self.extra.any():
            values += self.pair.laplacian(self.conn.edges, self.extra)
        values[self.pair.diagonal] += _PROXIMAL * float(values[self.pair.diagonal].mean())
        values[self.pair.diagonal[[0, self.pair.n]]] += self.anchor
        return self.pair.factorize(values)

    def stiffened(self, stiffness: np.ndarray):
        """``K`` with triangle scales ``1 + stiffness``, factorised; the plain factor when that changes little."""
        if np.mean(stiffness > 1.0) < 0.1:
            # At most doubling the curvature of under a tenth of the triangles
            # (a few squeezed ones): not worth a factorisation.
            return self.plain
        if self._stiff is None:
            self._stiff = _StiffLaplacian(self.conn.edges, self.free, anchor=self.anchor)
        return self._stiff.factorize(self.weights(1.0 + stiffness))


class _Memory:
    """L-BFGS pairs with their preconditioned ``H0 y`` and ``s . y``, and the two-loop recursion."""

    def __init__(self):
        self.pairs = []

    def clear(self):
        self.pairs = []

    def add(self, s, y, hy):
        sy = dot(s, y)
        if sy > 0:
            self.pairs.append((s, y, hy, sy))
            del self.pairs[:-_MEMORY]

    def direction(self, grad, hgrad) -> np.ndarray:
        """``H grad`` by the two-loop recursion; ``H0`` products come precomputed (``hgrad``, ``H0 y``)."""
        alphas = []
        q = grad.copy()
        for s, y, _, sy in reversed(self.pairs):
            alphas.append(dot(s, q) / sy)
            q -= alphas[-1] * y
        r = hgrad.copy()  # H0 q = H0 g - sum a_i H0 y_i (H0 is linear)
        for (_, _, hy, _), a in zip(reversed(self.pairs), alphas):
            r -= a * hy
        if self.pairs:
            s, y, hy, sy = self.pairs[-1]
            yhy = dot(y, hy)
            if yhy > 0:  # H0's curvature along y: rounds to 0 where y is tiny (the spline bowl on an AMD EPYC)
                r *= sy / yhy
        for (s, y, _, sy), a in zip(self.pairs, reversed(alphas)):
            r += (a - dot(y, r) / sy) * s
        return r


class _Minimiser:
    """L-BFGS with the :class:`_System` as ``H0`` and a flip-free, non-crossing line search, in stages.

    Stages: the barrier weight ``mu`` is cut tenfold each time progress stalls,
    then dropped; in the last stage (``mu = 0``), each time progress stalls
    the seam multipliers are updated until the held lengths are reached.
    ``H0`` is applied to each accepted gradient once and kept, so that the
    two-loop recursion needs no further solve; the memory is dropped only when
    ``H0`` changes.
    """

    def __init__(self, objective, system, faces, loops, free, *, tolerance, floor, length_tolerance, progress,
                 offset, total, refresh=_REFRESH):
        self.objective, self.system, self.faces, self.loops, self.free = objective, system, faces, loops, free
        self.refresh = refresh  # iterations between refactorisations of the stiffened matrix
        self.tolerance, self.floor, self.length_tolerance = tolerance, floor, length_tolerance
        self.progress, self.offset, self.total = progress, offset, total
        self.everywhere = bool(free.all())
        self.sd = not isinstance(objective.main, Arap)  # a barrier itself: its matrix follows the squeeze
        self.newton = system.pair is not None  # H0 the projected Hessian (after reweighted steps)
        self.size = None  # the layout's size, for the smallest useful step (set at the start)
        self.outline_first = False  # a line search tests the outline before the value (see line_search)

    def restrict(self, g):
        return g if self.everywhere else g[self.free]

    def downhill(self, uv, d):
        """``-d`` on the free vertices, 0 on the pinned: a step ``(n, 2)`` for the layout ``uv``."""
        if self.everywhere:
            return -d
        out = np.zeros_like(uv)
        out[self.free] = -d
        return out

    def evaluate(self, u, mu):
        """``(value, gradient on the free vertices, parts)``; value inf where folded."""
        parts = self.objective.parts(u, mu)
        f_value, f_grad, b_value, b_grad = parts
        if f_grad is None or (mu > 0 and b_grad is None):
            return np.inf, None, parts
        if mu == 0:
            return f_value, self.restrict(f_grad), parts
        return f_value + mu * b_value, self.restrict(f_grad + mu * b_grad), parts

    def reweigh(self, parts, mu):
        """``(value, gradient)`` from :meth:`evaluate`'s parts with another barrier weight."""
        f_value, f_grad, b_value, b_grad = parts
        if mu == 0:
            return f_value, self.restrict(f_grad)
        return f_value + mu * b_value, self.restrict(f_grad + mu * b_grad)

    def factor(self, u, mu):
        """The preconditioner for the current stage at ``u``."""
        if self.newton:
            return self.system.hessian(u, self.objective.main)
        if self.sd:
            return self.system.stiffened(self.objective.barrier.stiffness(u))
        if mu > 0:
            return self.system.stiffened(mu * self.objective.barrier.stiffness(u))
        return self.system.plain

    def __call__(self, uv, barrier, max_iterations):
        """Run; returns ``(uv, iterations, converged)``."""
        mu = float(barrier)
        self.size = layout_size(uv)
        value, grad, parts = self.evaluate(uv, mu)
        # pending: the last step's (s, y, H0 grad before it), its pair completed by the next iteration's solve
        # (a run that stops after a step makes no solve for it)
        lu, hgrad, memory, pending = self.factor(uv, mu), None, _Memory(), None
        since_refresh, recent, rounds = 0, [value], 0
        stiff = self.sd or self.newton or mu > 0
        iterations = 0
        while iterations < max_iterations:
            iterations += 1
            if stiff and since_refresh >= self.refresh:
                fresh, since_refresh = self.factor(uv, mu), 0
                if fresh is not lu:
                    lu, hgrad, pending = fresh, None, None
                    memory.clear()
            since_refresh += 1
            if hgrad is None:
                hgrad = lu.solve(grad)
                if pending is not None:
                    memory.add(pending[0], pending[1], hgrad - pending[2])
                    pending = None
            moved, step = self.line_search(uv, value, grad, hgrad, memory, mu)
            if moved:
                cand, new_value, new_grad, new_parts = step
                pending = (self.restrict(cand - uv), new_grad - grad, hgrad)
                if stiff and new_value < _JUMP * value:
                    since_refresh = self.refresh  # a crushed triangle opened: matrix and pairs made far from here
                uv, value, grad, hgrad, parts = cand, new_value, new_grad, None, new_parts
            if self.progress is not None:
                self.progress(self.offset + iterations, self.total)
            if not moved and memory.pairs:
                memory.clear()  # retry once from the plain preconditioned gradient
                continue
            recent.append(value)
            gain = recent[0] - value if len(recent) > _WINDOW else np.inf
            del recent[:-_WINDOW - 1]
            last = mu == 0.0
            scale = max(abs(value), self.floor)
            stalled = not moved or gain <= _WINDOW * self.tolerance * (1.0 if last else _STAGE_TOLERANCE) * scale
            if not stalled and not (last and value <= self.floor):
                continue
            if last:
                seam = self.objective.seam
                if seam is None or rounds >= _SEAM_ROUNDS or seam.update(uv) <= self.length_tolerance:
                    return uv, iterations, seam is None or _length_error(seam, uv) <= self.length_tolerance
                rounds += 1
                value, grad, parts = self.evaluate(uv, mu)  # new multipliers: a new energy
            else:
                mu = mu * _DROP if mu > _WEAKEST * 1.5 else 0.0
                stiff = self.sd or self.newton or mu > 0
                value, grad = self.reweigh(parts, mu)  # the terms are at hand
            lu, hgrad, since_refresh, recent, pending = self.factor(uv, mu), None, 0, [value], None
            memory.clear()
        return uv, iterations, False

    def line_search(self, uv, value, grad, hgrad, memory, mu):
        """``(moved, (uv, value, grad, parts))`` along the L-BFGS direction, flip-free and non-crossing."""
        direction = self.downhill(uv, memory.direction(grad, hgrad))
        slope = dot(grad, self.restrict(direction))
        if not slope < 0:  # stale memory: fall back to the preconditioned gradient
            memory.clear()
            direction = self.downhill(uv, hgrad)
            slope = dot(grad, self.restrict(direction))
        step = min(1.0, 0.9 * float(flip_free_steps(uv, self.faces, direction, horizon=1.0 / 0.9,
                                                     corners=self.objective.fr.corners).min()))
        # Steps below round-off of the layout's size make no progress.
        smallest = 1e-13 * self.size / max(float(np.abs(direction).max()), 1e-300)
        first = True
        while step > smallest:
            cand = uv + step * direction
            # Most steps tried are not taken (a search that ends a stage halves some forty times to round-off):
            # on a darted piece whose legs press together, nine in ten run the outline into itself; elsewhere
            # the energy does not go down.  Both tests are pure, so their order does not change the step
            # taken: the one that failed last goes first; past the first step, the value alone (most of
            # those are not taken), the gradient for the step taken.
            full = None
            if self.outline_first:
                taken = outline_valid(cand, self.loops)
                if taken:
                    full = self.evaluate(cand, mu)
                    taken = full[0] <= value + 1e-4 * step * slope
                    self.outline_first = taken
            else:
                if first:
                    full = self.evaluate(cand, mu)
                taken = (full[0] if first else self.objective.value(cand, mu)) <= value + 1e-4 * step * slope
                if taken and not outline_valid(cand, self.loops):
                    taken, self.outline_first = False, True
            if taken:
                new_value, new_grad, parts = self.evaluate(cand, mu) if full is None else full
                return True, (cand, new_value, new_grad, parts)
            first = False
            step *= 0.5
        return False, None


def _travel_to_pins(faces, loops, e, length, free, uv, pin_index, pin_target, max_iterations, progress):
    """Move the pins onto their targets by stress-majorization steps, staying one-to-one.

    Each step aims at the minimiser of the edge stress's majorizer with the
    pins at their targets (one solve with the graph Laplacian's free block,
    weights ``1 / l**2``), cut vertex by vertex so nothing folds or crosses.
    Returns ``(uv, iterations)``.
    """
    n = len(uv)
    weight = 1.0 / length**2
    laplacian = _laplacian(n, e, weight)
    lu = factorize(laplacian[free][:, free])
    coupling = laplacian[free][:, ~free]
    size = layout_size(uv)
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
        target[pin_index] = pin_target
        # The pinned block in vertex order (``~free`` is sorted; ``pin_index`` need not be).
        target[free] = lu.solve(rhs[free] - coupling @ target[~free])
        moved = safe_move(faces, loops, uv, target)
        if progress is not None:
            progress(iterations, max_iterations)
        if moved is uv:
            break
        uv = moved
    return np.array(uv), iterations


class _StiffLaplacian:
    """The weighted Laplacian's free block, refactorised for new edge weights.

    The same matrix as ``_laplacian(n, edges, weight, anchor=anchor)[free][:, free]``;
    the pattern never changes, so an :class:`~patterns.flattening.embed.LDL` keeps
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
