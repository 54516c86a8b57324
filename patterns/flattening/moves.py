"""Moves that keep a flat layout one-to-one, and the checks of what a relaxation is asked to hold.

* :func:`flip_free_steps`: the largest step each triangle can take along a
  direction before it flips (exact quadratic roots);
* :func:`safe_move`: a layout moved towards a target vertex by vertex, as far
  as it stays one-to-one (no folded triangle, a valid boundary polygon);
* :func:`best_scale`, :func:`align_to_pins`: a starting layout's scale and its
  rigid fit to pins (never applied to a result);
* :func:`check_lengths`, :func:`check_pins`: ``lengths=`` and ``pins=``
  validated against the mesh, with messages naming the input's vertices.
"""

from __future__ import annotations

import numpy as np
import shapely

from ..errors import InputError
from ..measure import best_turn, signed_areas
from ..mesh import Connectivity, extent
from ..predicates import crossing_segments

__all__ = [
    "align_to_pins",
    "best_scale",
    "check_lengths",
    "check_pins",
    "crossing_vertices",
    "edge_index",
    "edge_rows",
    "flip_free_steps",
    "layout_size",
    "outline_valid",
    "safe_move",
]


def flip_free_steps(uv: np.ndarray, faces: np.ndarray, step: np.ndarray, *, horizon: float = np.inf,
                    corners: tuple | None = None) -> np.ndarray:
    """Largest ``t`` per triangle such that ``uv + s * step`` keeps it positive for all ``s < t``.

    The signed area along the step is the quadratic ``a2 t**2 + a1 t + a0``
    (``a0 > 0``); its smallest positive root is returned, ``inf`` if none.

    Parameters
    ----------
    uv, step : (n, 2) float64
    faces : (m, 3) int64
    horizon : float
        Only roots below this matter: triangles whose area stays positive up to
        ``horizon`` get ``inf`` without solving (much faster when most are safe).
    corners : tuple of three (m,) int64, optional
        ``faces``' columns, contiguous, if at hand (faster gathers).

    Returns
    -------
    (m,) float64
    """
    # Column gathers: several times faster than gathering (m, 3, 2) blocks.
    i, j, k = corners if corners is not None else (np.ascontiguousarray(faces[:, c]) for c in range(3))
    x, y = np.ascontiguousarray(uv[:, 0]), np.ascontiguousarray(uv[:, 1])
    dx, dy = np.ascontiguousarray(step[:, 0]), np.ascontiguousarray(step[:, 1])
    x0, y0, dx0, dy0 = x.take(i), y.take(i), dx.take(i), dy.take(i)
    e1x, e1y, e2x, e2y = x.take(j) - x0, y.take(j) - y0, x.take(k) - x0, y.take(k) - y0
    d1x, d1y, d2x, d2y = dx.take(j) - dx0, dy.take(j) - dy0, dx.take(k) - dx0, dy.take(k) - dy0
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
    turn = best_turn(a - ca, target - cb)  # no BLAS: the relaxation from this start follows its bits
    c, s = np.cos(turn), np.sin(turn)
    x, y = uv[:, 0] - ca[0], uv[:, 1] - ca[1]
    return np.column_stack([x * c - y * s + cb[0], x * s + y * c + cb[1]])


def edge_rows(table: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """Row of each ``edges`` pair (sorted ends) in the unique edge ``table`` (sorted ends), -1 where absent."""
    n = int(max(table.max(), edges.max())) + 1
    keys = table[:, 0] * n + table[:, 1]
    order = np.argsort(keys, kind="stable")
    want = edges[:, 0] * n + edges[:, 1]
    pos = np.minimum(np.searchsorted(keys, want, sorter=order), len(keys) - 1)
    return np.where(keys[order[pos]] == want, order[pos], -1)


def edge_index(table: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """:func:`edge_rows`, every pair required; InputError naming the first that is not an edge."""
    rows = edge_rows(table, edges)
    if np.any(rows < 0):
        bad = edges[np.flatnonzero(rows < 0)[0]]
        raise InputError(f"held length on ({int(bad[0])}, {int(bad[1])}), which is not an edge of the mesh")
    return rows


def layout_size(uv: np.ndarray) -> float:
    """The layout's larger extent, mm (1 for a point)."""
    return extent(uv) or 1.0


def safe_move(faces: np.ndarray, loops, uv: np.ndarray, target: np.ndarray, *, tries: int = 40) -> np.ndarray:
    """Move towards ``target`` as far as possible, vertex by vertex, staying one-to-one.

    Returns ``uv`` itself (the same object) when no move is possible.
    """
    step = target - uv
    n = len(uv)
    alpha = np.ones(n)
    per_face = np.minimum(0.9 * flip_free_steps(uv, faces, step, horizon=1.0 / 0.9), 1.0)
    np.minimum.at(alpha, faces.ravel(), np.repeat(per_face, 3))
    for attempt in range(2 * tries):
        cand = uv + alpha[:, None] * step
        bad = ~(signed_areas(cand, faces) > 0)
        crossing = None if bad.any() else crossing_vertices(cand, loops)
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


def outline_valid(uv: np.ndarray, loops) -> bool:
    """Whether the flat loops ``uv[loop]`` form a valid polygon (no loop crosses or touches itself or another).

    What a line search needs of :func:`crossing_vertices`, without finding the crossing segments: on
    libigl's camel, whose legs press together, those took half the relaxation's time.
    """
    rings = [uv[loop] for loop in loops]
    return bool(shapely.is_valid(shapely.Polygon(rings[0], rings[1:])))


def crossing_vertices(uv: np.ndarray, loops):
    """None when the flat loops form a valid polygon; else the vertices of the
    boundary segments that cross another one (possibly empty)."""
    if outline_valid(uv, loops):
        return None
    _, pair, i, j = crossing_segments(uv, loops)
    return np.unique(np.concatenate([pair[i].ravel(), pair[j].ravel()]))


def check_lengths(lengths, conn: Connectivity, name: str, *, numbering=None):
    """Validate ``lengths = (edges, targets[, groups])``; returns ``(int64 (k, 2), float64 (k,)[, int64 (k,)])``.

    Every pair must be an edge of the mesh and every target a positive finite length.
    ``numbering`` ``(n,) int64``, if given, renumbers the vertices (input vertex ``j`` is vertex
    ``numbering[j]`` of ``conn``); the edges come back renumbered, messages name the input's.
    """
    try:
        edges, targets, *rest = lengths
        edges = np.asarray(edges)
        targets = np.asarray(targets, dtype=np.float64)
        groups = np.asarray(rest[0]) if rest else None
    except (TypeError, ValueError):
        raise InputError(f"{name}: lengths must be (edges (k, 2), lengths (k,)[, groups (k,)])") from None
    if len(rest) > 1 or (groups is not None and (groups.shape != targets.shape
                                                 or not np.issubdtype(groups.dtype, np.integer))):
        raise InputError(f"{name}: lengths must be (edges (k, 2), lengths (k,)[, integer groups (k,)])")
    if edges.ndim != 2 or edges.shape[1:] != (2,) or targets.shape != (len(edges),):
        raise InputError(f"{name}: lengths must be (edges (k, 2), lengths (k,)), got shapes {edges.shape} and "
                         f"{targets.shape}")
    if len(edges) and (not np.issubdtype(edges.dtype, np.integer) or edges.min() < 0
                       or edges.max() >= conn.n_vertices):
        raise InputError(f"{name}: held edges must be vertex indices in [0, {conn.n_vertices})")
    if not np.all(np.isfinite(targets) & (targets > 0)):
        raise InputError(f"{name}: held lengths must be positive finite numbers")
    edges = edges.astype(np.int64)
    inner = edges if numbering is None else numbering[edges]
    index = edge_rows(conn.edges, np.sort(inner, axis=1))
    if np.any(index < 0):
        bad = edges[np.flatnonzero(index < 0)[0]]
        raise InputError(f"{name}: held length on ({int(bad[0])}, {int(bad[1])}), which is not an edge of the mesh")
    edges = inner
    return (edges, targets) if groups is None else (edges, targets, groups.astype(np.int64))


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
