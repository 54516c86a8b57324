"""Fitting arcs and lines to a closed flat outline, within a tolerance.

Cutters charge by the entity and cut smoother arcs than hundreds of tiny
segments.  :func:`fit_arcs` replaces runs of outline points by one straight
segment or one circular arc each, as long as every point of the run stays
within the tolerance of it.  The tolerance is measured at the outline's
*points*: they lie on the CAD edge the outline samples, while its chords cut
inside a curve by their sagitta (``c² / 8R``: 0.049 mm for the 2.79 mm chords
of an R20 hole), so measuring at the chords refused every arc on a circle
meshed coarser than the tolerance.  A segment's middle still has to lie within
the tolerance of the fit, or within its sagitta on the arc plus half the
tolerance where that sagitta is larger -- but only where the segment samples
the arc (it turns by at most 30 degrees on it, and is at most twice as long as
its neighbours), so an arc never cuts a corner or bulges off a straight edge.
The runs are found greedily from the sharpest corner and then balanced: every
break between two pieces moves to the middle of the range in which both pieces
still fit, and neighbours that fit as one piece merge, all round the loop (so a
round hole is a few arcs of its radius, not arcs and a left-over straight
flat).  The result is the vertex list of a closed polyline with bulges (DXF's
arc segments: ``bulge = tan(sweep / 4)``, positive counter-clockwise), so a
contour stays ONE closed entity; its vertices are points of the outline.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["arc_points", "fit_arcs"]

_CORNER = np.radians(30.0)
"""A vertex turning by more than this is a corner: a break there never moves.  Likewise a segment
that turns by more than this on an arc is no sample of it (three points are always on a circle)."""


def _line(run: np.ndarray, tol: float) -> bool:
    """Whether every point of ``run`` lies within ``tol`` of the segment from its first to its last point."""
    a, b = run[0], run[-1]
    chord = b - a
    length = float(np.hypot(*chord))
    if length == 0.0:
        return False
    d = run - a
    along = (d[:, 0] * chord[0] + d[:, 1] * chord[1]) / length
    across = (d[:, 0] * chord[1] - d[:, 1] * chord[0]) / length
    return bool(np.abs(across).max() <= tol and along.min() >= -tol and along.max() <= length + tol)


def _arc(run: np.ndarray, tol: float, sampled: np.ndarray) -> float | None:
    """The bulge of the arc from ``run``'s first to its last point that every point lies within ``tol`` of.

    The centre lies on the chord's perpendicular bisector (the end points stay where they are); it
    is the least-squares one (algebraic, then refined on the true distances), so noise in any one
    point does not throw it off the way a circle through three of them would.  Each segment's
    middle must lie within ``tol`` of the arc too, or, where its sagitta ``s`` on the arc is over
    half the tolerance, within ``s + tol / 2`` (a chord cuts inside the curve its points sample by
    its sagitta; half the tolerance is left for the points' scatter).  That is only where the
    segment samples the arc: where it turns by at most :data:`_CORNER` on it (else it cuts a corner)
    and is at most twice as long as its neighbours (``sampled``: each segment's length, capped at
    twice its neighbours'; a lone long chord beside a curve is a straight edge, not a sample of a
    circle through its ends and a point or two beyond them).  None when no such arc fits,
    the run does not go round the centre one way, or it turns by more than half a turn.
    """
    a, b = run[0], run[-1]
    half = 0.5 * float(np.hypot(*(b - a)))
    if half == 0.0 or len(run) < 3:
        return None
    mid = 0.5 * (a + b)
    normal = np.array([a[1] - b[1], b[0] - a[0]]) / (2.0 * half)
    d = run[1:-1] - mid
    s = d[:, 0] * normal[0] + d[:, 1] * normal[1]
    ss = math.fsum(s * s)
    if ss == 0.0:
        return None
    # |p - mid - t n|^2 = half^2 + t^2  <=>  |p - mid|^2 - half^2 = 2 t (p - mid).n, in least squares:
    t = math.fsum(((d * d).sum(axis=1) - half * half) * s) / (2.0 * ss)
    res = np.hypot(d[:, 0] - t * normal[0], d[:, 1] - t * normal[1]) - np.hypot(half, t)
    worst = float(np.abs(res).max())
    if worst > 3.0 * tol:
        return None
    for _ in range(3 if worst > tol else 0):  # Gauss-Newton on the distances themselves
        radius = np.hypot(half, t)
        rel = d - t * normal
        dist = np.hypot(rel[:, 0], rel[:, 1])
        res = dist - radius
        jac = -(rel[:, 0] * normal[0] + rel[:, 1] * normal[1]) / dist - t / radius
        jj = math.fsum(jac * jac)
        if jj == 0.0:
            break
        step = -math.fsum(jac * res) / jj
        t += step
        if abs(step) <= 1e-12 * (abs(t) + half):
            break
    centre = mid + t * normal
    radius = float(np.hypot(half, t))
    if np.abs(np.hypot(run[:, 0] - centre[0], run[:, 1] - centre[1]) - radius).max() > tol:
        return None
    middle = 0.5 * (run[1:] + run[:-1]) - centre
    sag = radius - np.sqrt(np.maximum(radius * radius - 0.25 * sampled * sampled, 0.0))
    sag[sampled > 2.0 * radius * np.sin(0.5 * _CORNER) * (1.0 + 1e-9)] = 0.0
    if np.any(np.abs(np.hypot(middle[:, 0], middle[:, 1]) - radius) > np.maximum(tol, sag + 0.5 * tol)):
        return None
    # The run must go round the centre one way, by at most half a turn.
    ang = np.unwrap(np.arctan2(run[:, 1] - centre[1], run[:, 0] - centre[0]))
    step = np.diff(ang)
    if not (np.all(step > 0) or np.all(step < 0)):
        return None
    sweep = float(ang[-1] - ang[0])
    if abs(sweep) > np.pi:
        return None
    return float(np.tan(sweep / 4.0))


class _Runs:
    """The pieces of a closed outline: which runs ``i..j`` (indices round the loop, ``j - i < n``) fit."""

    def __init__(self, loop: np.ndarray, tol: float):
        self.loop, self.tol, self.n = loop, tol, len(loop)
        seg = np.roll(loop, -1, axis=0) - loop  # segment k: from point k to point k + 1
        length = np.hypot(seg[:, 0], seg[:, 1])
        self.sampled = np.minimum(length, 2.0 * np.minimum(np.roll(length, 1), np.roll(length, -1)))
        self._cache: dict[tuple[int, int], float | None] = {}

    def bulge(self, i: int, j: int) -> float | None:
        """0 for a line, the bulge of an arc, or None when ``loop[i..j]`` fits neither."""
        if j - i == 1:
            return 0.0
        if not 1 < j - i < self.n:
            return None
        key = (i % self.n, j - i)
        if key not in self._cache:
            idx = np.arange(i, j + 1) % self.n
            run = self.loop[idx]
            self._cache[key] = 0.0 if _line(run, self.tol) else _arc(run, self.tol, self.sampled[idx[:-1]])
        return self._cache[key]

    def fits(self, i: int, j: int) -> bool:
        return self.bulge(i, j) is not None

    def reach(self, i: int, limit: int, known: int | None = None) -> int:
        """The farthest ``j <= limit`` with ``i..j`` one piece, ``i..known`` being one (doubling, then bisecting)."""
        good = i + 1 if known is None else known
        bad, step = limit + 1, 1
        while good + step <= limit:
            if not self.fits(i, good + step):
                bad = good + step
                break
            good += step
            step *= 2
        while bad - good > 1:
            m = (good + bad) // 2
            good, bad = (m, bad) if self.fits(i, m) else (good, m)
        return good

    def reach_back(self, j: int, limit: int, known: int | None = None) -> int:
        """The nearest ``i >= limit`` with ``i..j`` one piece, ``known..j`` being one."""
        good = j - 1 if known is None else known
        bad, step = limit - 1, 1
        while good - step >= limit:
            if not self.fits(good - step, j):
                bad = good - step
                break
            good -= step
            step *= 2
        while good - bad > 1:
            m = (good + bad) // 2
            good, bad = (m, bad) if self.fits(m, j) else (good, m)
        return good


def fit_arcs(loop: np.ndarray, tolerance: float = 0.01) -> np.ndarray:
    """Arcs and lines through a closed outline, within ``tolerance`` of its points.

    Parameters
    ----------
    loop : (n, 2) float64, mm
        Closed outline, not repeating its first point.
    tolerance : float
        Largest distance between an outline point and the fitted contour, mm (> 0).

    Returns
    -------
    (k, 3) float64
        Vertices ``(x, y, bulge)`` of a closed polyline; the bulge belongs to
        the segment from the vertex to the next one (0: straight).  Every
        vertex is a point of the outline (no point moves), and every
        outline point lies within ``tolerance`` of the contour.  Between two
        points the contour follows the fitted arc, not the outline's chord:
        it stays within ``max(tolerance, s + tolerance / 2)`` of the chord,
        ``s`` the chord's sagitta on the arc.
    """
    loop = np.asarray(loop, dtype=np.float64)
    n = len(loop)
    if n < 3:
        return np.column_stack([loop, np.zeros(n)])
    a = loop - np.roll(loop, 1, axis=0)
    b = np.roll(loop, -1, axis=0) - loop
    turn = np.abs(np.arctan2(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0], (a * b).sum(axis=1)))
    corner = turn > _CORNER
    runs = _Runs(loop, tolerance)
    # Greedily from the sharpest corner, so that no arc has to run through the start ...
    start = int(np.argmax(turn))
    breaks = [start]
    while breaks[-1] < start + n:
        breaks.append(runs.reach(breaks[-1], start + n))
    breaks.pop()  # the last break is the start again, a turn later
    # ... then balance the pieces: each break to the middle (by length) of where it may go, both
    # of its pieces still fitting, and neighbours that fit as one piece merged, until nothing moves.
    # (Breaks are indices round the loop, increasing, less than one turn apart; the first may move
    # back past the start.)
    length = np.concatenate([[0.0], np.cumsum(np.hypot(b[:, 0], b[:, 1]))])

    def along(k: int) -> float:  # length round the loop to point k (any integer)
        q, r = divmod(k, n)
        return q * length[n] + length[r]

    for _ in range(4):  # a few passes: a left-over flat is gone after the first
        moved = False
        m = 0
        while m < len(breaks):
            k = len(breaks)
            prev = breaks[m - 1] - (n if m == 0 else 0)
            nxt = breaks[(m + 1) % k] + (n if m == k - 1 else 0)
            here = breaks[m]
            if corner[here % n]:
                m += 1
                continue
            if runs.fits(prev, nxt):
                del breaks[m]
                moved = True
                continue
            lo, hi = runs.reach_back(nxt, prev + 1, here), runs.reach(prev, nxt - 1, here)
            if lo < hi:
                middle = 0.5 * (along(lo) + along(hi))
                cand = min(range(lo, hi + 1), key=lambda x: (abs(along(x) - middle), x))
                if cand != here and runs.fits(prev, cand) and runs.fits(cand, nxt):
                    breaks[m] = cand
                    moved = True
            m += 1
        if not moved:
            break
    out = []
    for m, i in enumerate(breaks):
        j = breaks[m + 1] if m + 1 < len(breaks) else breaks[0] + n
        out.append((loop[i % n, 0], loop[i % n, 1], runs.bulge(i, j)))
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
        chord = math.hypot(*(p1 - p0))
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
