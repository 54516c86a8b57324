"""Fold-free relaxation of a flat layout towards true edge lengths.

The relaxation minimises the edge-length stress

    E(u) = sum over edges of (|u_i - u_j| / l_ij - 1)**2,

the sum of squared edge strains, by stress majorization (SMACOF): each
iteration aims every edge at its true 3D length along its current direction and
solves one sparse linear system whose matrix (the graph Laplacian weighted by
``1 / l**2``) never changes, so it is factorised once.

The layout stays one-to-one at every iterate.  The step towards the solution is
cut, vertex by vertex, so that (1) no triangle's orientation flips (the largest
flip-free fraction of each triangle's step is solved for exactly) and (2) the
flat boundary loops stay a valid polygon (crossing boundary segments, found with
a shapely STRtree, have their vertices' steps cut).  A start without folds and
with valid loops therefore ends without folds and without overlap, by the same
degree argument as :mod:`patterns.check`.  Nothing is ever rescaled.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import shapely

from ..errors import InputError
from ..measure import signed_areas
from ..mesh import Connectivity
from .embed import factorize

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
          pins=None, max_iterations: int = 50, tolerance: float = 1e-4, progress=None) -> Relaxation:
    """Relax a one-to-one layout towards true edge lengths, keeping it one-to-one.

    Parameters
    ----------
    vertices : (n, 3) float64
    faces : (m, 3) int64
    conn : Connectivity
    start : (n, 2) float64
        A layout without folded triangles and with valid boundary loops.
    pins : tuple of ((k,) int, (k, 2) float), optional
        Vertices to hold and their flat positions (libigl's ``b, bc``).  They
        are approached step by step; if reaching them would fold or overlap the
        pattern they stop short (``converged`` is then False).
    max_iterations : int
        > 0.
    tolerance : float
        Stop when an iteration lowers the stress by less than this fraction.
    progress : callable, optional
        ``progress(iteration, max_iterations)`` after each iteration.

    Returns
    -------
    Relaxation
    """
    n = len(vertices)
    e = conn.edges
    length = np.linalg.norm(vertices[e[:, 1]] - vertices[e[:, 0]], axis=1)
    uv = np.array(start, dtype=np.float64)
    floor = 1e-20 * len(length)  # RMS edge strain 1e-10: round-off level
    if pins is None and np.sum((np.linalg.norm(uv[e[:, 1]] - uv[e[:, 0]], axis=1) / length - 1) ** 2) <= floor:
        uv.setflags(write=False)  # already exact (a developable part): nothing to relax
        return Relaxation(uv, 0, True)
    weight = 1.0 / length**2
    adjacency = sp.coo_matrix((np.r_[weight, weight], (np.r_[e[:, 0], e[:, 1]], np.r_[e[:, 1], e[:, 0]])),
                              shape=(n, n)).tocsr()
    laplacian = (sp.diags(np.asarray(adjacency.sum(axis=1)).ravel()) - adjacency).tocsr()

    free = np.ones(n, dtype=bool)
    if pins is None:
        # The stress does not see translations: hold vertex 0 softly where it
        # starts.  The stress forces sum to zero, so at a fixed point the
        # anchor carries no force and does not bias the result.
        pin_index = np.zeros(0, dtype=np.int64)
        pin_target = np.zeros((0, 2))
        anchor = float(weight.mean())
        system = laplacian + sp.coo_matrix(([anchor], ([0], [0])), shape=(n, n))
        anchor_at = uv[0].copy()
    else:
        pin_index, pin_target = pins
        free[pin_index] = False
        anchor = 0.0
        system = laplacian[free][:, free]
        coupling = laplacian[free][:, ~free]
    lu = factorize(system)

    def majorize(u):
        """The majorizer's minimiser from ``u``, and the stress at ``u``."""
        d = u[e[:, 1]] - u[e[:, 0]]
        dl = np.sqrt(d[:, 0] ** 2 + d[:, 1] ** 2)
        q = d * (weight * length / np.maximum(dl, 1e-300))[:, None]
        rhs = np.empty((n, 2))
        for k in range(2):
            rhs[:, k] = np.bincount(e[:, 1], q[:, k], n) - np.bincount(e[:, 0], q[:, k], n)
        target = np.empty((n, 2))
        if anchor:
            rhs[0] += anchor * anchor_at
            target[:] = lu.solve(rhs)
        else:
            target[~free] = pin_target
            target[free] = lu.solve(rhs[free] - coupling @ pin_target)
        return target, float(np.sum((dl / length - 1.0) ** 2))

    def pins_reached(u):
        return np.allclose(u[pin_index], pin_target, rtol=0, atol=1e-9 * _size(u))

    target, energy = majorize(uv)
    best, best_energy = uv, energy
    converged = False
    iterations = 0
    for iterations in range(1, max_iterations + 1):
        moved = _safe_move(faces, conn.loops, uv, target)
        stuck = moved is uv
        target, new_energy = majorize(moved)
        # Converged: the stress changed by less than the tolerance (either way:
        # round-off moves it both ways), or the edge strain is at round-off
        # level already (RMS below 1e-10: an exactly developable part, where the
        # round-off of a million-face layout reaches 1e-11).
        small = abs(energy - new_energy) <= tolerance * energy or new_energy <= floor
        uv, energy = moved, new_energy
        # Cut steps are not guaranteed to lower the stress: keep the best
        # iterate (while the pins are still travelling, the latest).
        if energy <= best_energy or len(pin_index):
            best, best_energy = uv, energy
        if progress is not None:
            progress(iterations, max_iterations)
        if stuck or (small and pins_reached(uv)):
            converged = not stuck or energy == 0.0
            break
    uv = best
    converged = converged and pins_reached(uv)
    uv.setflags(write=False)
    return Relaxation(uv, iterations, converged)


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
    starts = np.concatenate(loops)
    ends = np.concatenate([np.roll(loop, -1) for loop in loops])
    lines = shapely.linestrings(np.stack([uv[starts], uv[ends]], axis=1))
    i, j = shapely.STRtree(lines).query(lines, predicate="intersects")
    keep = i < j
    i, j = i[keep], j[keep]
    pair = np.stack([starts, ends], axis=1)
    adjacent = (pair[i][:, :, None] == pair[j][:, None, :]).any(axis=(1, 2))
    i, j = i[~adjacent], j[~adjacent]
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
