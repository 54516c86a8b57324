"""Fitting arcs and lines to a closed flat outline, within a tolerance.

Cutters charge by the entity and cut smoother arcs than hundreds of tiny
segments.  :func:`fit_arcs` replaces runs of outline points by one straight
segment or one circular arc each, greedily from a corner, as long as every
point of the run *and* the middle of every original segment stays within the
tolerance of it (so the fitted contour stays within the tolerance of the
polyline both ways, up to the sag of one original segment's middle).  The
result is the vertex list of a closed polyline with bulges (DXF's arc
segments: ``bulge = tan(sweep / 4)``, positive counter-clockwise), so a contour
stays ONE closed entity.
"""

from __future__ import annotations

import numpy as np

__all__ = ["arc_points", "fit_arcs"]


def _circle(a, b, c):
    """Centre and radius of the circle through three points, or None when they are collinear."""
    d = 2.0 * (a[0] * (b[1] - c[1]) + b[0] * (c[1] - a[1]) + c[0] * (a[1] - b[1]))
    scale = max(np.ptp([a, b, c], axis=0).max(), 1e-300)
    if abs(d) <= 1e-12 * scale * scale:
        return None
    aa, bb, cc = a @ a, b @ b, c @ c
    ux = (aa * (b[1] - c[1]) + bb * (c[1] - a[1]) + cc * (a[1] - b[1])) / d
    uy = (aa * (c[0] - b[0]) + bb * (a[0] - c[0]) + cc * (b[0] - a[0])) / d
    centre = np.array([ux, uy])
    return centre, float(np.linalg.norm(a - centre))


def _fit(pts, i, j, tol):
    """``(ok, bulge)`` for replacing ``pts[i..j]`` by one segment (bulge 0) or one arc."""
    run = pts[i:j + 1]
    probe = np.concatenate([run, 0.5 * (run[1:] + run[:-1])])
    a, b = run[0], run[-1]
    chord = b - a
    length = np.linalg.norm(chord)
    if length > 0:
        normal = np.array([-chord[1], chord[0]]) / length
        if np.max(np.abs((probe - a) @ normal)) <= tol:
            along = (probe - a) @ (chord / length)
            if along.min() >= -tol and along.max() <= length + tol:
                return True, 0.0
    if j - i < 2:
        return j - i == 1, 0.0
    fit = _circle(a, run[(j - i) // 2], b)
    if fit is None:
        return False, 0.0
    centre, radius = fit
    if np.max(np.abs(np.linalg.norm(probe - centre, axis=1) - radius)) > tol:
        return False, 0.0
    # The run must go round the centre one way, by less than half a turn.
    ang = np.unwrap(np.arctan2(run[:, 1] - centre[1], run[:, 0] - centre[0]))
    step = np.diff(ang)
    if not (np.all(step > 0) or np.all(step < 0)):
        return False, 0.0
    sweep = ang[-1] - ang[0]
    if abs(sweep) > np.pi:
        return False, 0.0
    return True, float(np.tan(sweep / 4.0))


def fit_arcs(loop: np.ndarray, tolerance: float = 0.01) -> np.ndarray:
    """Arcs and lines through a closed outline, within ``tolerance``.

    Parameters
    ----------
    loop : (n, 2) float64, mm
        Closed outline, not repeating its first point.
    tolerance : float
        Largest distance between the fitted contour and the outline's points
        and segment middles, mm (> 0).

    Returns
    -------
    (k, 3) float64
        Vertices ``(x, y, bulge)`` of a closed polyline; the bulge belongs to
        the segment from the vertex to the next one (0: straight).  Every
        vertex is a point of the outline (no point moves).
    """
    loop = np.asarray(loop, dtype=np.float64)
    n = len(loop)
    if n < 3:
        return np.column_stack([loop, np.zeros(n)])
    # Start at the sharpest corner, so that no arc has to run through the start.
    a = loop - np.roll(loop, 1, axis=0)
    b = np.roll(loop, -1, axis=0) - loop
    turn = np.abs(np.arctan2(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0], (a * b).sum(axis=1)))
    start = int(np.argmax(turn))
    pts = np.vstack([np.roll(loop, -start, axis=0), np.roll(loop, -start, axis=0)[:1]])
    out = []
    i = 0
    while i < n:
        good, bulge = i + 1, _fit(pts, i, i + 1, tolerance)[1]
        span = 2
        bad = None
        while i + span <= n:
            ok, bl = _fit(pts, i, i + span, tolerance)
            if not ok:
                bad = i + span
                break
            good, bulge = i + span, bl
            span *= 2
        hi = bad if bad is not None else n + 1
        hi = min(hi, n + 1)
        while hi - good > 1:
            mid = (good + hi) // 2
            if mid > n:
                hi = mid
                continue
            ok, bl = _fit(pts, i, mid, tolerance)
            if ok:
                good, bulge = mid, bl
            else:
                hi = mid
        out.append((pts[i, 0], pts[i, 1], bulge))
        i = good
    return np.array(out)


def arc_points(fitted: np.ndarray, *, step: float = 0.01) -> np.ndarray:
    """Points along a fitted closed contour, no farther than ``step`` mm apart on arcs (for checks)."""
    out = []
    k = len(fitted)
    for m in range(k):
        x0, y0, bulge = fitted[m]
        x1, y1, _ = fitted[(m + 1) % k]
        p0, p1 = np.array([x0, y0]), np.array([x1, y1])
        if bulge == 0.0:
            out.append(p0[None, :])
            continue
        sweep = 4.0 * np.arctan(bulge)
        chord = np.linalg.norm(p1 - p0)
        radius = chord / (2.0 * abs(np.sin(sweep / 2.0)))
        mid = 0.5 * (p0 + p1)
        normal = np.array([-(p1 - p0)[1], (p1 - p0)[0]]) / chord
        # The centre lies left of the chord for a counter-clockwise arc under half a turn.
        centre = mid + normal * np.sign(bulge) * np.sqrt(max(radius * radius - 0.25 * chord * chord, 0.0))
        a0 = np.arctan2(p0[1] - centre[1], p0[0] - centre[0])
        count = max(int(np.ceil(abs(sweep) * radius / step)), 2)
        t = a0 + np.linspace(0.0, sweep, count, endpoint=False)
        out.append(centre + radius * np.column_stack([np.cos(t), np.sin(t)]))
    return np.concatenate(out)
