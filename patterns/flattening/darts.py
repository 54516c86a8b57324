"""Darts: cut a flattening open where its strain is above a limit.

:func:`cut_darts` is what :func:`patterns.flatten` does with ``max_strain``:
greedy darts, one at a time, each from the outline to the most strained
point along mesh edges, kept only when they lower the strain.
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import csgraph

from ..cut import cut_along
from ..measure import strain_rms, triangle_strains
from ..mesh import edge_graph, unique_edges, unique_ints
from ..pattern import Flattening
from .engine import flatten_mesh
from .seams import seam_edges

__all__ = ["cut_darts", "strained_depths"]

_DART_SLACK = 1.05  # a dart is kept if the strain RMS after it is at most this times the lowest so far
_DART_REFUSALS = 4  # consecutive refused darts before the loop gives up


def cut_darts(result: Flattening, limit: float, max_darts: int, held, options: dict):
    """Cut darts into a flattening until its triangle strain is within ``limit``.

    Greedy: each round finds the vertices next to a triangle above the limit,
    takes the one deepest inside (farthest from the outline along the mesh),
    cuts along the shortest path of edges from the outline to it, and flattens
    again (``options``: those of :func:`flatten_mesh`; ``held``: the seam
    lengths, remapped onto each cut mesh).  A dart is kept only if the
    strain RMS after it (the relaxation's objective, which a cut can only
    lower at the optimum) is at most ``_DART_SLACK`` times the lowest so far;
    otherwise the cut is undone and the next deepest vertex is tried (after
    ``_DART_REFUSALS`` refusals in a row the loop stops).  Without that, one
    cut whose flaps overlap when laid flat (LSCM then overlaps, and the
    relaxation starts from Tutte's layout) sent every later round to
    50-300 % strain on a hemisphere.  The worst triangle strain is not the
    test: it moves about from cut to cut, and darts that raise it for a round
    are often what brings it down later.  Returns ``(flattening, darts)``.
    """
    darts = []
    lowest = strain_rms(result.vertices, result.faces, result.uv)
    refused = set()  # target vertices whose dart made things worse (indices survive later cuts)
    in_a_row = 0
    depths = strained_depths(result, limit)  # recomputed only when a dart is kept
    while depths is not None and len(darts) < max_darts and in_a_row < _DART_REFUSALS:
        strained, dist, pred = depths
        # The vertex to cut to: among the vertices next to a triangle above the
        # limit, the one deepest inside (farthest from the outline along the
        # mesh), so that one dart relieves the whole strained run.
        open_to = strained.copy()
        open_to[list(refused)] = False
        candidates = np.flatnonzero(open_to)
        if not len(candidates):
            break  # every strained triangle lies on the outline (or was tried): nothing left to cut
        target = int(candidates[np.argmax(dist[candidates])])
        path = [target]
        while pred[path[-1]] >= 0:
            path.append(int(pred[path[-1]]))
        path = np.asarray(path[::-1], dtype=np.int64)  # from the outline inwards
        cut = cut_along(result.vertices, result.faces, path, name=options["name"])
        cut_held = None if held is None else (seam_edges(cut.vertices, unique_edges(cut.faces), held[0]), *held[1:])
        after = flatten_mesh(cut.vertices, cut.faces, lengths=cut_held, **options)
        rms = strain_rms(after.vertices, after.faces, after.uv)
        if rms <= _DART_SLACK * lowest:
            darts.append(path)
            result, lowest, in_a_row, held = after, min(lowest, rms), 0, cut_held
            depths = strained_depths(result, limit)
        else:
            refused.add(target)
            in_a_row += 1
    return result, tuple(np.asarray(d) for d in darts)


def strained_depths(result: Flattening, limit: float):
    """Where a dart could go: ``(strained (n,) bool, dist (n,), pred (n,))``, or None if nothing is above ``limit``.

    ``strained`` marks the inner vertices next to a triangle above the limit
    and reachable from the outline; ``dist`` and ``pred`` are the shortest
    paths along mesh edges (3D lengths) from the outline.
    """
    v, f = result.vertices, result.faces
    above = np.flatnonzero(triangle_strains(v, f, result.uv).magnitude > limit)
    if not len(above):
        return None
    n = len(v)
    graph = edge_graph(v, unique_edges(f))
    boundary = unique_ints(np.concatenate(result.loops))
    dist, pred, _ = csgraph.dijkstra(graph, indices=boundary, min_only=True, return_predecessors=True)
    strained = np.zeros(n, dtype=bool)
    strained[f[above].ravel()] = True
    strained[boundary] = False
    return strained & np.isfinite(dist), dist, pred
