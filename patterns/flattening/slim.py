"""Reweighted local-global steps (SLIM's proxy) that carry a far start towards least distortion.

A conformal or Tutte layout of a mesh with long thin parts (fingers, legs,
a tail) shrinks them by orders of magnitude: a hand's fingertips come out
at 1e-6 of their size.  Gradient steps, even preconditioned by a scalar
reweighting of the Laplacian, then inflate them by a few per cent an
iteration (measured: 300-400 of the relaxation's 400-500 iterations on the
OptCuts hands, armadillo and dinosaur).  The scalable locally injective
mappings method (Rabinovich, Poranne, Panozzo, Sorkine-Hornung 2017)
takes each triangle's principal directions into its step: with ``J = U S V^T``
and the closest rotation ``R = U V^T``, it solves

    min over uv of  sum_t W_t |A_t (J_t - R_t)|^2,   A_t = U diag(a1, a2) U^T,

``a_i^2 = f'(s_i) / (2 (s_i - 1))`` for the per-stretch energy
``f(s) = s^2 + s^-2`` (the symmetric Dirichlet energy), whose minimiser moves a
crushed triangle's stretch by a constant factor a step.  Each term is
``W_t (A_t^2) (x) (C_t C_t^T)``, a 2 x 2 matrix times the triangle's cotangent
stiffness, so the system couples ``u`` and ``v``: ``2 n`` unknowns, one
factorisation a step (qdldl, the ordering kept).  The step to that minimiser
is capped before any triangle flips and halved until the energy drops and
the outline stays a valid polygon, so the layout stays one-to-one.

:func:`reweighted` is run by :func:`patterns.flattening.relax.relax` on a far
start whose triangles are crushed (``CRUSHED_START``); the relaxation goes on
from its layout.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .energy import BY_NAME, Frames
from .hessian import PAIRS, PairSystem
from .moves import flip_free_steps, layout_size, outline_valid

__all__ = ["CRUSHED_START", "SLIM_STEPS", "Carried", "crushed_start", "reweighted"]

CRUSHED_START = 1e-2
"""A start is carried by :func:`reweighted` first when 1 % of its area (3D) is squeezed below this stretch.

(1e-3 at first; the five OptCuts starts between 1e-3 and 1e-2 -- chinese lion, evil, foot,
gargoyle, vase -- all ended in the hybrid by the other path too, and carried they took 0.5-0.9
of its time at a lower energy.  The lowest start measured whose ARAP minimum crushes nothing,
the BFF spot head, is at 1.5e-2.  libigl's camel (``camel_b``, 5.5e-3) is carried too, but its
legs press together: the first reweighted step runs its outline into itself, and the relaxation
then goes the barrier path from the start instead, see :attr:`Carried.blocked`.)"""

SLIM_STEPS = 20
"""Reweighted steps :func:`patterns.flattening.relax.relax` takes at most from a crushed start (SLIM's usual count)."""
_TOLERANCE = 1e-3  # stop when the energy falls by less than this fraction in a step


def crushed_start(fr: Frames, uv: np.ndarray) -> bool:
    """Whether 1 % of a layout's area is squeezed below :data:`CRUSHED_START` (the 1st percentile stretch)."""
    s2 = fr.jacobian(uv).smallest_stretch_squared()
    order = np.argsort(s2)
    share = np.cumsum(fr.weight[order]) / fr.weight.sum()
    return bool(s2[order][np.searchsorted(share, 0.01)] < CRUSHED_START**2)


def _stiffness(fr: Frames, c: np.ndarray) -> np.ndarray:
    """``W C C^T``, ``(m, 3, 3)``: each triangle's cotangent stiffness times its weight (``C`` its
    :func:`.hessian.corner_columns`)."""
    return fr.weight[:, None, None] * np.einsum("mij,mkj->mik", c, c)


def _proxy(jac, stretch: tuple[float, float]):
    """``(A^2, A^2 R)``, each ``(m, 2, 2)``, of every triangle, in closed form.

    ``J z = alpha z + beta conj(z)``: ``s1, s2 = |alpha| +- |beta|``, ``R`` the
    rotation by ``arg alpha``, ``U`` by ``(arg alpha + arg beta) / 2``.  Per
    stretch ``a^2 = f'(s) / (2 (s - 1)) = p + q (s + 1)(s^2 + 1) / s^3`` of the
    energy's ``f = p (s - 1)^2 + q (s^2 + s^-2 - 2)`` (``stretch = (p, q)``),
    continuous through ``s = 1``.
    """
    ar, ai, br, bi = jac.conformal_parts()
    na, nb = np.hypot(ar, ai), np.hypot(br, bi)
    s = np.stack([na + nb, na - nb], axis=1)  # (m, 2), positive on a one-to-one layout
    p, q = stretch
    a2 = p + q * (s + 1.0) * (s * s + 1.0) / s ** 3
    mean, half = 0.5 * (a2[:, 0] + a2[:, 1]), 0.5 * (a2[:, 0] - a2[:, 1])
    # cos, sin of 2 arg U = arg alpha + arg beta: alpha beta / |alpha beta| (any angle where beta = 0: half is 0).
    norm = np.maximum(na * nb, 1e-300)
    c2, s2 = (ar * br - ai * bi) / norm, (ar * bi + ai * br) / norm
    weight = np.empty((len(s), 2, 2))
    weight[:, 0, 0], weight[:, 1, 1] = mean + half * c2, mean - half * c2
    weight[:, 0, 1] = weight[:, 1, 0] = half * s2
    cr, sr = ar / np.maximum(na, 1e-300), ai / np.maximum(na, 1e-300)  # R: rotation by arg alpha
    target = np.empty_like(weight)
    target[:, :, 0] = weight[:, :, 0] * cr[:, None] + weight[:, :, 1] * sr[:, None]
    target[:, :, 1] = -weight[:, :, 0] * sr[:, None] + weight[:, :, 1] * cr[:, None]
    return weight, target


class Carried(NamedTuple):
    """What :func:`reweighted` returns."""

    uv: np.ndarray
    """(n, 2) float64: one-to-one, its energy no higher than the start's."""
    used: int
    """Steps taken."""
    blocked: bool
    """A step that lowered the energy would have run the outline into itself (SLIM's proxy knows
    nothing of the outline): stopped there, the layout as it was before that step."""


def reweighted(fr: Frames, uv: np.ndarray, loops, *, energy: str = "symmetric-dirichlet",
               iterations: int = SLIM_STEPS, system: PairSystem | None = None) -> Carried:
    """Carry a one-to-one layout towards least distortion by SLIM's reweighted steps.

    Parameters
    ----------
    fr : Frames
        The mesh's frames (:func:`patterns.flattening.energy.frames`).
    uv : (n, 2) float64
        A one-to-one layout (every triangle positive, the loops a valid polygon); not changed.
    loops : sequence of (k,) int64
        The boundary loops.
    energy : {"symmetric-dirichlet", "hybrid", "arap"}
        The distortion (:mod:`patterns.flattening.energy`) whose proxy is solved and which each step lowers.
    iterations : int
        Steps at most; fewer when a step lowers the energy by less than 0.1 %.
    system : PairSystem, optional
        The mesh's :class:`~patterns.flattening.hessian.PairSystem`, if at hand (built otherwise).

    Returns
    -------
    Carried
        ``(uv, used, blocked)``.
    """
    n = len(uv)
    system = PairSystem(fr, n) if system is None else system
    c = system.columns
    stiff = _stiffness(fr, c)
    energy = BY_NAME[energy](fr)
    uv = np.array(uv, dtype=np.float64)
    jac = fr.jacobian(uv)
    value = energy.terms(jac, grad=False)[0]
    size = layout_size(uv)
    used = 0
    for used in range(1, iterations + 1):
        weight, target = _proxy(jac, energy.stretch)
        # Entry ((k, c), (l, c')) of W A^2 (x) C C^T, packed (hessian.PAIRS: unknown k * 3 + c).
        values = system.assemble(weight[:, PAIRS[:, 0] // 3, PAIRS[:, 1] // 3] * stiff[:, PAIRS[:, 0] % 3, PAIRS[:, 1] % 3])
        proximal = 1e-9 * float(values[system.diagonal].mean())  # holds the translation; biases nothing else
        values[system.diagonal] += proximal
        # Right-hand side: each triangle's W (A^2 R) C^T, scattered to its corners.
        local = fr.weight[:, None, None] * np.einsum("mkj,mcj->mkc", target, c)  # (m, 2, 3)
        rhs = np.bincount(system.local.ravel(), weights=local.reshape(len(local), 6).ravel(), minlength=2 * n)
        rhs += proximal * np.concatenate([uv[:, 0], uv[:, 1]])
        x = system.factorize(values).solve(rhs)
        direction = np.column_stack([x[:n], x[n:]]) - uv
        step = min(1.0, 0.9 * float(flip_free_steps(uv, fr.faces, direction, horizon=1.0 / 0.9,
                                                     corners=fr.corners).min()))
        smallest = 1e-13 * size / max(float(np.abs(direction).max()), 1e-300)
        while step > smallest:
            cand = uv + step * direction
            cand_jac = fr.jacobian(cand)
            terms = energy.terms(cand_jac, grad=False)  # values only
            if terms is not None and terms[0] < value:
                if not outline_valid(cand, loops):
                    return Carried(uv, used, True)  # the step would run the outline into itself
                break
            step *= 0.5
        else:
            return Carried(uv, used, False)
        gain = (value - terms[0]) / value
        uv, value, jac = cand, terms[0], cand_jac
        if gain < _TOLERANCE:
            break
    return Carried(uv, used, False)
