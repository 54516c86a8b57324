"""Gores: split a panel into pieces along the dart lines, run on to the crown, instead of darts that stop short.

:func:`gored` is what :func:`patterns.flatten` does with ``max_strain`` and
``gores=True``: every freeform panel whose dartless flattening is above the
limit is cut, from the same evenly spaced outline points as darts
(:func:`patterns.flattening.darts.dart_lines`), straight to one crown point
(where the lines' inward normals meet best), into as few pieces as bring
every piece within the limit.  Each cut becomes a seam of the model, held
at its 3D length like every seam; a sphere therefore needs more gores than
darts (docs/garments.md: a gore whose edges are held at 3D length strains
twice as much at its centre as one whose lengths are balanced).
"""

from __future__ import annotations

import numpy as np
import shapely

from ..cut import insert_line
from ..mesh import unique_edges
from ..model import Model
from ..pattern import Flattening
from .curvature import gore_bound
from .darts import dart_lines, worst_strain
from .inserts import relieved
from .remedy import Flattener, Remedy
from .split import split_panel

__all__ = ["gore_paths", "gore_search", "gored"]


def gored(model: Model, index: int, result: Flattening, limit: float, max_cuts: int, flat: Flattener, *,
          max_slashes: int = 0) -> Model:
    """The model with panel ``index`` split into the fewest gores that each flatten within ``limit``.

    What :func:`gore_search` found (see there), or the model unchanged where
    the panel is within the limit or no split could be made.
    """
    if worst_strain(result) <= limit:
        return model
    found = gore_search(model, index, result, limit, max_cuts, flat, max_slashes=max_slashes)
    return model if found is None else found.model


def gore_search(model: Model, index: int, result: Flattening, limit: float, max_cuts: int, flat: Flattener, *,
                max_slashes: int = 0) -> Remedy | None:
    """Panel ``index`` split into the fewest gores within ``limit`` (the worst gore's strain, the model).

    Parameters
    ----------
    model : Model
    index : int
        The panel to split.
    result : Flattening
        Its dartless flattening (the lines are drawn on it).
    limit : float
        The largest principal strain allowed.
    max_cuts : int
        At most this many cuts (as many pieces round a crown inside the
        panel, one more to a crown on its outline).
    flat : callable
        ``flat(model, p) -> PanelFlat``: a gore flattened as :func:`patterns.flatten` flattens it
        (:data:`patterns.flattening.remedy.Flattener`).
    max_slashes : int
        A gore above the limit that is saddle-shaped (a seat's waist) is
        slashed and given inserts, at most this many slashes
        (:func:`patterns.flattening.inserts.relieved`); 0: none.

    Returns
    -------
    Remedy or None
        None if no split with 1 to ``max_cuts`` cuts could be made; otherwise
        the split that meets the limit with the fewest cuts tried, or, if none
        does, the one that came closest, and its worst gore's strain.  The counts tried start at the gore bound
        (:func:`patterns.flattening.curvature.gore_bound`, rounded up) and go
        up until the limit is met, or down from there while it still is.
    """
    tried = {}  # cuts -> Remedy (no darts), or None where the split could not be made

    def attempt(k: int):
        if k not in tried:
            tried[k] = None
            paths = gore_paths(result, k, limit)
            split = None if paths is None else split_panel(model, index, paths)
            if split is not None:
                n_pieces = len(split.panels) - len(model.panels) + 1
                found = relieved(split, index, n_pieces, limit, flat, max_slashes=max_slashes)
                tried[k] = Remedy(found.worst, found.model)
        return tried[k]

    def met(k: int) -> bool:
        return attempt(k) is not None and tried[k].worst <= limit

    # From the gore bound (what the curvature asks for, balanced gores): up until the limit is met,
    # or, if met there at once, down while it still is.
    k = int(np.clip(np.ceil(gore_bound(result, limit)), 1, max_cuts))
    if met(k):
        while k > 1 and met(k - 1):
            k -= 1
    else:
        while k < max_cuts and not met(k + 1):
            k += 1
    done = {c: v for c, v in tried.items() if v is not None}
    passing = [c for c, v in done.items() if v.worst <= limit]
    if passing:
        return done[min(passing)]
    return min(done.values(), key=lambda v: v.worst) if done else None


def gore_paths(result: Flattening, k: int, limit: float):
    """``k`` straight cuts from the dart lines' start points to their crown, put into the mesh, or None."""
    lines = dart_lines(result, k, limit, split=True)
    uv = result.uv
    starts = np.array([uv[line.start] for line in lines])
    normals = np.array([line.direction for line in lines])
    # The crown: the point nearest all the lines (least squares), at a vertex of the panel.
    projector = np.eye(2)[None] - normals[:, :, None] * normals[:, None, :]
    (a, b), (c, d) = projector.sum(axis=0)
    rhs = np.einsum("kij,kj->i", projector, starts)
    det = a * d - b * c  # the 2 x 2 normal equations solved in closed form: LAPACK's rounding follows the CPU
    crown_point = np.array([d * rhs[0] - b * rhs[1], a * rhs[1] - c * rhs[0]]) / det if abs(det) > 1e-12 * (
        a * d + b * b + c * c) else np.linalg.lstsq(projector.sum(axis=0), rhs, rcond=None)[0]
    loops = [np.asarray(loop) for loop in result.loops]
    polygon = shapely.Polygon(uv[loops[0]], [uv[loop] for loop in loops[1:]])
    if not shapely.contains_xy(polygon, *crown_point):
        boundary = np.concatenate(loops)
        crown = int(boundary[np.argmin(np.linalg.norm(uv[boundary] - crown_point, axis=1))])
    else:
        crown = int(np.argmin(np.linalg.norm(uv - crown_point, axis=1)))
    segments = shapely.linestrings([[uv[line.start], uv[crown]] for line in lines])
    if any(line.start == crown for line in lines) or not all(
            shapely.covers(polygon.buffer(1e-9 * float(np.ptp(uv))), s) for s in segments):
        return None
    v, f, p = result.vertices, result.faces, uv
    paths, taken = [], []
    for line in lines:
        inserted = insert_line(v, f, p, uv[line.start], uv[crown], keep_off=taken)
        v, f, p = inserted.vertices, inserted.faces, inserted.uv
        if inserted.path[0] != line.start or inserted.path[-1] != crown:
            return None
        paths.append(inserted.path)
        taken += [int(x) for x in inserted.path[:-1]]
    shared = np.unique(np.concatenate([path[1:-1] for path in paths]), return_counts=True)[1]
    if np.any(shared > 1) or any(np.isin(path[1:-1], [pp[0] for pp in paths]).any() for path in paths):
        return None  # two cuts run together before the crown
    edges = {tuple(e) for e in unique_edges(f).tolist()}
    if not all((min(a, b), max(a, b)) in edges for path in paths for a, b in zip(path[:-1].tolist(), path[1:].tolist())):
        return None  # a later line split an edge of an earlier one (they met before the crown)
    return v, f, paths
