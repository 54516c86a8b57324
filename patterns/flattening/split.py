"""Splitting a panel into pieces along cut paths: :func:`split_panel`, and a piece flattened with its seams held.

Gores (:mod:`patterns.flattening.gores`), slashes with inserts
(:mod:`patterns.flattening.inserts`) and pieces with darts
(:mod:`patterns.flattening.parted`) all part a panel this way: the cuts become
seams of the model held at their 3D lengths, and a seam of the panel that a
cut starts inside is parted with it, one seam a piece.
"""

from __future__ import annotations

import numpy as np

from ..cut import components, cut_along
from ..mesh import polyline_length, unique_edges
from ..model import Model, Seam, panel_from_mesh
from ..pattern import Flattening
from .engine import flatten_mesh
from .seams import held_lengths

__all__ = ["flat_piece", "split_panel"]


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
    the panel's name; their ``gore_of`` None, the panel's kept).  None if the cuts do not part the panel into one piece more
    than there are cuts meeting at one point (a cut that parts nothing).
    """
    vertices, faces, cuts = paths
    panel = model.panels[index]
    cut = cut_along(vertices, faces, cuts, name=panel.name)
    groups = components(cut.faces, len(cut.vertices), name=panel.name)
    if len(groups) < 2:
        return None
    labels = [f"{panel.name}-{j + 1}" for j in range(len(groups))]
    into, of = [None] * len(groups), [panel.name] * len(groups)
    if inserts:
        groups.sort(key=len, reverse=True)
        labels = [panel.name] + [f"{panel.name}-insert-{j}" for j in range(1, len(groups))]
        into, of = [None] + [panel.name] * (len(groups) - 1), [panel.gore_of] + [None] * (len(groups) - 1)
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
    copies_of = _copies(cut.source)
    seams, later = [], []
    for seam in model.seams:
        runs = _runs(seam, index, copies_of, owner)
        for r, (lo, hi, pieces_at) in enumerate(runs):
            sides = tuple(int(renumber[p]) if p != index else index + pieces_at[side][0]
                          for side, p in enumerate(seam.panels))
            idx = tuple(np.asarray(seam.vertices[side])[lo:hi + 1] if p != index else local[pieces_at[side][1]]
                        for side, p in enumerate(seam.panels))
            points = seam.points[lo:hi + 1]
            share = polyline_length(points) / seam.polyline_length if len(runs) > 1 else 1.0
            part = (sides, points, idx, seam.length * share, seam.cad_edge)
            (seams if r == 0 else later).append(part if r else Seam(seam.id, *part))
    for part in later:  # a seam the cuts part: its first run keeps its id, the others come after the model's seams
        seams.append(Seam(len(seams), *part))
    for left, right in cut.sides:
        a, b = int(owner[left[0]]), int(owner[right[0]])
        points = cut.vertices[left]
        seams.append(Seam(len(seams), (index + a, index + b), points, (local[left], local[right]),
                          polyline_length(points)))
    panels = model.panels[:index] + tuple(parts) + model.panels[index + 1:]
    return Model(model.name, panels, tuple(seams), model.max_edge, model.bookkeeping)


def _copies(source: np.ndarray):
    """``copies(chain) -> [cut vertices of each original vertex of chain]`` (ascending), from one sort of ``source``."""
    order = np.argsort(source, kind="stable")
    ranked = source[order]

    def copies(chain) -> list:
        chain = np.asarray(chain)
        lows, highs = np.searchsorted(ranked, chain, "left"), np.searchsorted(ranked, chain, "right")
        return [order[a:b] for a, b in zip(lows.tolist(), highs.tolist())]

    return copies


def _runs(seam, index, copies_of, owner) -> list:
    """A seam cut into the runs that lie on one piece each: ``[(first, last, pieces_at), ...]``.

    ``first`` and ``last`` index the seam's points (a run shares its last point
    with the next run's first: a cut ends on the seam there); ``pieces_at[side]``
    is, for a side on panel ``index``, ``(piece, copies)``: the piece the run
    lies on and its points' vertex indices in the cut mesh (None for a side on
    another panel).  One run for a seam the cuts do not part.
    """
    on = [side for side, p in enumerate(seam.panels) if p == index]
    n = len(seam.points)
    copies = {side: copies_of(seam.vertices[side]) for side in on}
    held = {side: [set(owner[c].tolist()) for c in copies[side]] for side in on}
    runs, first = [], 0
    while first < n - 1:
        last, chosen = n - 1, {}
        for side in on:
            sets = held[side]
            # The piece that keeps the seam longest from here (an edge lies on one piece: its two ends share it).
            reach = {q: next((j - 1 for j in range(first + 1, n) if q not in sets[j]), n - 1) for q in sets[first]}
            q = max(sorted(reach), key=lambda q: reach[q])
            chosen[side], last = q, min(last, max(reach[q], first + 1))
        pieces_at = [None, None]
        for side in on:
            q = chosen[side]
            pieces_at[side] = (q, np.array([c[owner[c] == q][0] for c in copies[side][first:last + 1]], dtype=np.int64))
        runs.append((first, last, pieces_at))
        first = last
    return runs


def flat_piece(model: Model, p: int, options: dict) -> Flattening:
    """Panel ``p`` of ``model`` flattened with its seams held (``options``: keywords of :func:`flatten_mesh`)."""
    panel = model.panels[p]
    held = held_lengths(model, p, panel.vertices, {}, mesh_edges=unique_edges(panel.faces))
    return flatten_mesh(panel.vertices, panel.faces, lengths=held, **options)
