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

from ..cut import cut_along, insert_line, pieces
from ..mesh import polyline_length, unique_edges
from ..model import Model, Seam, panel_from_mesh
from ..pattern import Flattening
from .curvature import gore_bound
from .darts import dart_lines, worst_strain
from .engine import flatten_mesh
from .seams import held_lengths

__all__ = ["flat_piece", "gored", "split_panel"]


def gored(model: Model, index: int, result: Flattening, limit: float, max_cuts: int, options: dict) -> Model:
    """The model with panel ``index`` split into the fewest gores that each flatten within ``limit``.

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
    options : dict
        Keywords of :func:`flatten_mesh` (``name`` included).

    Returns
    -------
    Model
        Unchanged if the panel is within the limit or no split with 1 to
        ``max_cuts`` cuts could be made; otherwise the split that meets the
        limit with the fewest cuts tried, or, if none does, the one that came
        closest.  The counts tried start at the gore bound
        (:func:`patterns.flattening.curvature.gore_bound`, rounded up) and go
        up until the limit is met, or down from there while it still is.
    """
    if worst_strain(result) <= limit:
        return model
    tried = {}  # cuts -> (worst piece's strain, split model), or None where the split could not be made

    def attempt(k: int):
        if k not in tried:
            tried[k] = None
            paths = _gore_paths(result, k, limit)
            split = None if paths is None else split_panel(model, index, paths)
            if split is not None:
                n_pieces = len(split.panels) - len(model.panels) + 1
                tried[k] = (max(worst_strain(flat_piece(split, p, options)) for p in range(index, index + n_pieces)),
                            split)
        return tried[k]

    def met(k: int) -> bool:
        return attempt(k) is not None and tried[k][0] <= limit

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
    passing = [c for c, v in done.items() if v[0] <= limit]
    if passing:
        return done[min(passing)][1]
    return min(done.values(), key=lambda v: v[0])[1] if done else model


def split_panel(model: Model, index: int, paths, *, inserts: bool = False) -> Model | None:
    """Cut panel ``index`` along ``paths`` (vertex paths joined by its edges, after :func:`insert_line`) into pieces.

    ``paths`` are given on the panel mesh with the lines already put in
    (``paths = (vertices, faces, [path, ...])``).  The pieces take the panel's
    place (named ``name-1``, ``name-2``, ...; panels after it move up), every
    cut becomes a seam between the two pieces it parts (appended after the
    model's seams, so seam ids stay), and the panel's seams move to the piece
    they lie on; each piece's :attr:`Panel.gore_of` is the panel's name.  With
    ``inserts``, the largest piece keeps the panel's name and comes first, the
    others are its inserts (``name-insert-1``, ..., :attr:`Panel.insert_into`
    the panel's name; ``gore_of`` None).  None if the cuts do not part the panel into one piece more
    than there are cuts meeting at one point (a cut that parts nothing).
    """
    vertices, faces, cuts = paths
    panel = model.panels[index]
    cut = cut_along(vertices, faces, cuts, name=panel.name)
    groups = pieces(cut.faces, len(cut.vertices), name=panel.name)
    if len(groups) < 2:
        return None
    labels = [f"{panel.name}-{j + 1}" for j in range(len(groups))]
    into, of = [None] * len(groups), [panel.name] * len(groups)
    if inserts:
        groups.sort(key=len, reverse=True)
        labels = [panel.name] + [f"{panel.name}-insert-{j}" for j in range(1, len(groups))]
        into, of = [None] + [panel.name] * (len(groups) - 1), [None] * len(groups)
    parts, local = [], np.full(len(cut.vertices), -1, dtype=np.int64)
    owner = np.full(len(cut.vertices), -1, dtype=np.int64)
    for j, group in enumerate(groups):
        f = cut.faces[group]
        used = np.unique(f)
        local[used] = np.arange(len(used))
        owner[used] = j
        parts.append(panel_from_mesh(labels[j], cut.vertices[used], np.searchsorted(used, f),
                                      name=f"{model.name}: panel {labels[j]}", insert_into=into[j],
                                      gore_of=of[j]))
    k = len(groups)
    renumber = np.array([p if p < index else p + k - 1 for p in range(len(model.panels))])
    seams = []
    for seam in model.seams:
        sides = []
        for side, p in enumerate(seam.panels):
            if p != index:
                sides.append((int(renumber[p]), np.asarray(seam.vertices[side])))
                continue
            piece, idx = _on_one_piece(cut.source, owner, np.asarray(seam.vertices[side]))
            sides.append((index + piece, local[idx]))
        seams.append(Seam(seam.id, (sides[0][0], sides[1][0]), seam.points, (sides[0][1], sides[1][1]),
                          seam.length, seam.cad_edge))
    for left, right in cut.sides:
        a, b = int(owner[left[0]]), int(owner[right[0]])
        points = cut.vertices[left]
        seams.append(Seam(len(seams), (index + a, index + b), points, (local[left], local[right]),
                          polyline_length(points)))
    panels = model.panels[:index] + tuple(parts) + model.panels[index + 1:]
    return Model(model.name, panels, tuple(seams), model.max_edge, model.bookkeeping)


def _on_one_piece(source, owner, chain):
    """The piece a seam chain (original vertex indices) lies on, and its vertices' copies there."""
    copies = [np.flatnonzero(source == i) for i in chain.tolist()]
    counts = np.bincount(np.concatenate([owner[c] for c in copies]))
    piece = int(np.argmax(counts))
    return piece, np.array([c[owner[c] == piece][0] for c in copies], dtype=np.int64)


def _gore_paths(result: Flattening, k: int, limit: float):
    """``k`` straight cuts from the dart lines' start points to their crown, put into the mesh, or None."""
    lines = dart_lines(result, k, limit, split=True)
    uv = result.uv
    starts = np.array([uv[line.start] for line in lines])
    normals = np.array([line.direction for line in lines])
    # The crown: the point nearest all the lines (least squares), at a vertex of the panel.
    projector = np.eye(2)[None] - normals[:, :, None] * normals[:, None, :]
    crown_point = np.linalg.lstsq(projector.sum(axis=0), np.einsum("kij,kj->i", projector, starts), rcond=None)[0]
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


def flat_piece(model: Model, p: int, options: dict) -> Flattening:
    """Panel ``p`` of ``model`` flattened with its seams held (``options``: keywords of :func:`flatten_mesh`)."""
    panel = model.panels[p]
    held = held_lengths(model, p, panel.vertices, {}, mesh_edges=unique_edges(panel.faces))
    return flatten_mesh(panel.vertices, panel.faces, lengths=held, **options)

