"""Darts: cut a flattening open where its strain is above a limit.

:func:`cut_darts` is what :func:`patterns.flatten` does with ``max_strain``.
A pattern maker relieves a dome with a few long darts, evenly spaced, all
reaching towards its crown, not with many short cuts to wherever the strain
peaks; this module decides the darts of a panel together:

* **Where they start.**  On the stretches of the outline that the flat
  layout draws longer than they are in 3D (a dome's rim is too short for
  the flattened dome: the material there has to go), or on the whole outer
  outline if none is; evenly spaced by arc length along each stretch, the
  count shared out by the stretches' excess length.  A dart starts at an
  outline vertex, so no seam edge is split.
* **Which way.**  Straight on the flat layout (a dart is drawn straight),
  along the outline's inward normal; the straight line is put into the
  mesh (:func:`patterns.cut.insert_line`), so the legs do not zigzag along
  triangle edges.
* **How many and how long.**  The fewest darts (up to ``max_darts``) that
  bring the worst triangle within the limit when as long as they can be
  (tips kept apart and off the far outline), then all shortened together,
  by bisection, to the shortest that still meets it.  Each try is one
  flattening with the panel's seams held.
* **Sewn.**  The two legs of each dart are held, in total, at one length
  (the mean of the lengths they take when free): they close on each other;
  the seams the darts do not cut keep their held lengths.  A try whose held
  lengths the relaxation could not reach (it stalled: a flap pinned between
  a dart and a seam) is not taken.

Measured (``benchmarks/darts.py``, docs/garments.md): a hemisphere R 150 mm
(one build123d face, 4,924 triangles) at 3 %: 11 darts, worst triangle
2.77 %, 2,191 mm of darts against the gore bound of 2,135 mm, legs equal to
0.002 mm, in 8.7 s.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely

from ..cut import cut_along, insert_line
from ..measure import triangle_strains
from ..mesh import edge_lengths, polyline_length, unique_edges
from ..pattern import Dart, Flattening
from .engine import flatten_mesh
from .seams import seam_edges

__all__ = ["DartLine", "cut_darts", "dart_lines"]

_TIP_GAP = 4.0  # tips at least this many mean flat edge lengths apart, and from the far outline
_BISECTIONS = 4  # halvings of the common dart length once a count meets the limit
_HELD = 1e-3  # a try whose held lengths end further off than this share (a stalled relaxation) is not taken
_STRETCHED = 0.5  # an outline vertex is on a stretch when its flat edges exceed 3D by this share of the limit


@dataclass(frozen=True, eq=False)
class DartLine:
    """A candidate dart, drawn on the dartless layout.

    Attributes
    ----------
    start : int
        The outline vertex it starts from.
    direction : (2,) float64
        Unit direction in the layout: the outline's inward normal there.
    reach : float
        Distance along ``direction`` to the far side of the outline, mm.
    """

    start: int
    direction: np.ndarray
    reach: float


def cut_darts(result: Flattening, limit: float, max_darts: int, held, options: dict):
    """Cut darts into a flattening until its worst triangle strain is within ``limit``.

    Parameters
    ----------
    result : Flattening
        The panel flattened without darts.
    limit : float
        The largest principal strain allowed (0.03 = 3 %).
    max_darts : int
        At most this many darts.
    held : tuple or None
        The panel's held seam lengths (``lengths`` of :func:`flatten_mesh`),
        kept on every cut mesh.
    options : dict
        The keywords of :func:`flatten_mesh`.

    Returns
    -------
    (Flattening, tuple of Dart)
        The result unchanged and no dart when it is within the limit already
        or no dart helps; otherwise the darted flattening (the mesh with the
        dart lines put in and cut) and its darts.  Where no count up to
        ``max_darts`` meets the limit, the darts that came closest.
    """
    if max_darts < 1 or worst_strain(result) <= limit:
        return result, ()
    h = float(np.mean(edge_lengths(result.uv, unique_edges(result.faces))))
    best = (worst_strain(result), result, ())  # the try that came closest, legs not yet sewn
    for k in range(1, max_darts + 1):
        lines = dart_lines(result, k, limit)
        longest = _longest_reach(result, lines, _TIP_GAP * h)
        tried = None if longest is None else _attempt(result, lines, longest, held, options)
        if tried is None:
            continue
        if tried[0] > limit:
            best = min(best, tried, key=lambda t: t[0])
            continue
        for _, flat, darts in _shortest(result, lines, longest, tried, limit, held, options):
            sewn = _sewn(flat, darts, held, options)  # shortest darts first: the first whose sewn legs keep it
            if _kept(sewn) and worst_strain(sewn) <= limit:
                return sewn, darts
    _, flat, darts = best
    if not darts:
        return result, ()
    sewn = _sewn(flat, darts, held, options)
    return (sewn, darts) if _kept(sewn) else (flat, darts)


def dart_lines(result: Flattening, k: int, limit: float, *, split: bool = False) -> list:
    """``k`` dart lines on a dartless layout: start vertices spread over the stretched outline, inward normals.

    Along a stretch that does not close on itself, darts sit in the middle of
    ``k`` equal parts; with ``split`` (gores) they part it into ``k + 1``
    equal parts, their ends at the stretch's ends.

    Returns
    -------
    list of DartLine
        Each with its start vertex, unit direction (flat) and reach: the
        distance along the direction to the outline on the far side.
    """
    uv, vertices = result.uv, result.vertices
    loops = [np.asarray(loop) for loop in result.loops]
    polygon = _polygon(result)
    runs = _stretches(vertices, uv, loops, limit)
    share = _shares(np.array([excess for _, excess in runs]), k)
    lines = []
    for (run, _), count in zip(runs, share):
        if not count:
            continue
        closed = run[0] == run[-1]
        arc = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(uv[run], axis=0), axis=1))]
        if closed:
            at = np.arange(count) * arc[-1] / count
        elif split:
            at = (np.arange(count) + 1.0) * arc[-1] / (count + 1)
        else:
            at = (np.arange(count) + 0.5) * arc[-1] / count
        for s in at:
            i = int(np.argmin(np.abs(arc - s)))
            vertex = int(run[i])
            before, after = run[max(i - 2, 0)], run[min(i + 2, len(run) - 1)]
            if closed and i in (0, len(run) - 1):
                before, after = run[-3], run[2]
            tangent = uv[after] - uv[before]
            inward = np.array([-tangent[1], tangent[0]]) / max(np.linalg.norm(tangent), 1e-300)
            lines.append(DartLine(vertex, inward, _reach(polygon, uv[vertex], inward)))
    return lines


def _polygon(result: Flattening):
    uv = result.uv
    return shapely.Polygon(uv[result.loops[0]], [uv[loop] for loop in result.loops[1:]])


def _stretches(vertices, uv, loops, limit) -> list:
    """Runs of outline vertices whose flat edges are longer than in 3D: ``[(vertices, excess mm)]``.

    A run covering a whole loop is returned closed (first vertex repeated at
    the end).  No stretch at all: the outer loop, closed.
    """
    runs = []
    for loop in loops:
        nxt = np.roll(loop, -1)
        flat = np.linalg.norm(uv[nxt] - uv[loop], axis=1)
        real = np.linalg.norm(vertices[nxt] - vertices[loop], axis=1)
        over = flat > real * (1.0 + _STRETCHED * limit)  # edge i runs loop[i] -> loop[i + 1]
        if over.all():
            runs.append((np.r_[loop, loop[:1]], float((flat - real).sum())))
            continue
        if not over.any():
            continue
        first = int(np.flatnonzero(~over)[0])  # walk from an edge that is not stretched
        order = (np.arange(len(loop)) + first) % len(loop)
        run = []
        for i in order:
            if over[i]:
                run.append(i)
            elif run:
                runs.append(_run(loop, run, flat, real))
                run = []
        if run:
            runs.append(_run(loop, run, flat, real))
    if not runs:
        loop = loops[0]
        nxt = np.roll(loop, -1)
        runs.append((np.r_[loop, loop[:1]], float(np.linalg.norm(uv[nxt] - uv[loop], axis=1).sum())))
    return runs


def _run(loop, edges, flat, real):
    """One stretch: the vertices of consecutive stretched edges and their excess length."""
    idx = np.asarray(edges)
    return np.r_[loop[idx], loop[(idx[-1] + 1) % len(loop)]], float((flat[idx] - real[idx]).sum())


def _shares(excess: np.ndarray, k: int) -> np.ndarray:
    """``k`` darts shared out over runs by their excess length (largest remainders)."""
    weights = np.maximum(excess, 0.0)
    weights = weights / weights.sum() if weights.sum() > 0 else np.full(len(excess), 1.0 / len(excess))
    exact = weights * k
    count = np.floor(exact).astype(np.int64)
    for i in np.argsort(-(exact - count))[: k - count.sum()]:
        count[i] += 1
    return count


def _reach(polygon, point, direction) -> float:
    """Distance from ``point`` along ``direction`` to where the straight line first leaves ``polygon``."""
    size = float(np.ptp(np.asarray(polygon.exterior.coords), axis=0).max())
    ray = shapely.LineString([point + 1e-9 * size * direction, point + 2.0 * size * direction])
    hits = ray.intersection(polygon.boundary)
    points = shapely.get_coordinates(hits)
    if not len(points):
        return 0.0
    return float(np.linalg.norm(points - point, axis=1).min())


def _tips(result, lines, fraction) -> np.ndarray:
    return np.array([result.uv[line.start] + fraction * line.reach * line.direction for line in lines])


def _valid(result, lines, fraction, gap) -> bool:
    """The dart lines at ``fraction`` of their reach stay apart: no crossing, tips ``gap`` apart and off the outline."""
    tips = _tips(result, lines, fraction)
    if any(fraction * line.reach < gap or (1 - fraction) * line.reach < gap for line in lines):
        return False
    segments = shapely.linestrings([[result.uv[line.start], tip] for line, tip in zip(lines, tips)])
    buffered = shapely.buffer(segments, 0.5 * gap)
    for i in range(len(lines)):
        for j in range(i + 1, len(lines)):
            if shapely.intersects(buffered[i], segments[j]):
                return False
    return True


def _longest_reach(result, lines, gap) -> float | None:
    """The largest share of their reach the lines can run to (bisection on :func:`_valid`), or None."""
    if not lines:
        return None
    lo, hi = 2.0 * gap / max(min(line.reach for line in lines), 1e-300), 1.0
    if lo >= hi or not _valid(result, lines, lo, gap):
        return None
    for _ in range(20):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if _valid(result, lines, mid, gap) else (lo, mid)
    return lo


def _attempt(result, lines, fraction, held, options):
    """Cut the lines at ``fraction`` of their reach and flatten: ``(worst strain, Flattening, darts)`` or None."""
    v, f, uv = result.vertices, result.faces, result.uv
    paths = []
    for line, tip in zip(lines, _tips(result, lines, fraction)):
        inserted = insert_line(v, f, uv, uv[line.start], tip)
        v, f, uv, path = inserted.vertices, inserted.faces, inserted.uv, inserted.path
        if len(path) < 2 or path[0] != line.start:
            return None
        paths.append(path)
    cut = cut_along(v, f, paths, name=options["name"])
    cut_held = None if held is None else (seam_edges(cut.vertices, unique_edges(cut.faces), held[0]), *held[1:])
    flat = flatten_mesh(cut.vertices, cut.faces, lengths=cut_held, **options)
    if not _kept(flat):
        return None  # the seams could not be held with these darts (a flap pinned between dart and seam)
    darts = tuple(Dart(tuple(np.asarray(side, dtype=np.int64) for side in sides), polyline_length(v[path]))
                  for sides, path in zip(cut.sides, paths))
    return worst_strain(flat), flat, darts


def _shortest(result, lines, longest, found, limit, held, options) -> list:
    """Shorten all darts together (bisection on their share of the reach) while the limit holds.

    Returns every try that met the limit, the shortest darts first.
    """
    passing = [(longest, found)]
    lo, hi = 0.0, longest
    for _ in range(_BISECTIONS):
        mid = 0.5 * (lo + hi)
        tried = _attempt(result, lines, mid, held, options)
        if tried is not None and tried[0] <= limit:
            passing.append((mid, tried))
            hi = mid
        else:
            lo = mid
    return [tried for _, tried in sorted(passing, key=lambda item: item[0])]


def _sewn(flat: Flattening, darts: tuple, held, options) -> Flattening:
    """Flatten again with each dart's legs held, in total, at one length: the mean of their free lengths."""
    edges, targets, groups = [], [], []
    if held is not None:
        pairs = seam_edges(flat.vertices, unique_edges(flat.faces), held[0])
        groups_in = held[2] if len(held) > 2 else np.arange(len(pairs))
        edges.append(pairs)
        targets.append(np.asarray(held[1], dtype=np.float64))
        groups.append(np.asarray(groups_in, dtype=np.int64))
    next_group = int(groups[0].max()) + 1 if groups else 0
    for dart in darts:
        length = float(np.mean(dart.leg_lengths(flat.uv)))
        for leg in dart.legs:
            steps = np.linalg.norm(np.diff(flat.vertices[leg], axis=0), axis=1)
            edges.append(np.column_stack([leg[:-1], leg[1:]]))
            targets.append(steps * length / steps.sum())  # shares of the leg's total, held in total
            groups.append(np.full(len(steps), next_group))
            next_group += 1
    return flatten_mesh(flat.vertices, flat.faces,
                        lengths=(np.concatenate(edges), np.concatenate(targets), np.concatenate(groups)), **options)


def _kept(result: Flattening) -> bool:
    """The held lengths (seams, dart legs) came within :data:`_HELD` of their targets."""
    return not result.length_error > _HELD


def worst_strain(result: Flattening) -> float:
    """The largest principal strain of any triangle of a flattening (the limit's measure)."""
    return float(triangle_strains(result.vertices, result.faces, result.uv).magnitude.max())
