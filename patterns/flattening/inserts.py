"""Slashes and inserts: a saddle-shaped panel relieved by wedges cut from its outline and sewn back in.

On negative Gaussian curvature (a saddle, a seat's waist) the surface has
more material round a point than a flat disk: laid flat, its outline is
pressed short, and a dart would only take out material the flat piece lacks
already.  A pattern maker slashes such a piece from the outline inwards and
spreads it, filling each opening with an insert (a godet, a gusset).

:func:`slashed` is what :func:`patterns.flatten` does with ``max_strain`` on
a freeform panel whose angle defects are mostly negative and whose
flattening is above the limit.  The rule:

* **Where.**  ``k`` slashes evenly spaced along the outer outline by arc
  length, the first at the outline's most pressed stretch (flat edges
  shortest against 3D), each running straight on the dartless layout towards
  the *trough* (the centroid of the negative angle defects), ``depth`` of the
  way there.
* **How wide.**  Each slash leaves a wedge whose angle at its tip is the
  panel's total excess angle (the negative defects' sum) over ``k``, times
  ``spread``: the wedge is cut out of the panel as a piece of its own, the
  insert, and the two cuts become seams held at their 3D lengths like every
  seam.  Taking a wedge of exactly a cone's excess angle out of a cone
  leaves a flat piece; on a saddle the excess is spread, so the wedges are
  wider than their share (``spread`` 2 or 3, measured).
* **How many.**  First the gore bound of the negative curvature
  (:func:`patterns.flattening.curvature.gore_bound` on the negated defects),
  rounded up; then one more at a time, up to ``max_darts``; each try is the
  flattening of every piece, and the first count at which all are within
  the limit is kept, or else the try that came closest if it is better than
  no slash.

The saddle of :data:`patterns.samples.DOMES` (200 mm, ``z = (x² - y²)/400``)
at 3 %: 4.49 % without slashes; 4 slashes at depth 0.8 and spread 2, the main
piece 2.06 %, each insert 0.2 % (docs/garments.md).
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np

from ..cut import insert_line
from ..measure import angle_defects
from ..mesh import face_areas
from ..model import Model
from ..pattern import Flattening
from .curvature import crown_of, gore_bound
from .darts import cut_darts, worst_strain
from .remedy import Flattener, Remedy
from .split import flat_piece, split_panel

__all__ = ["is_saddle", "relieved", "relieving", "slash_search", "slashed"]

_TRIES = ((0.8, 2.0), (0.9, 3.0))  # (depth towards the trough, spread of the wedges), tried in turn at each count
_SLIVER = 1e-6  # a try whose cuts leave a triangle of less than this share of the median area is not taken


def is_saddle(vertices: np.ndarray, faces: np.ndarray, loops) -> bool:
    """Whether a mesh's curvature is mostly negative: its negative angle defects outweigh its positive ones.

    ``vertices`` ``(n, 3)`` float64 mm, ``faces`` ``(m, 3)`` int64, ``loops`` its boundary loops (vertex
    index arrays; their vertices have no defect of their own).
    """
    return _mostly_negative(angle_defects(vertices, faces, loops=loops))


def _mostly_negative(defects: np.ndarray) -> bool:
    return bool(np.maximum(-defects, 0.0).sum() > np.maximum(defects, 0.0).sum())


def slashed(model: Model, index: int, result: Flattening, limit: float, max_slashes: int, options: dict) -> Model:
    """The model with panel ``index`` slashed and its wedges made inserts, so that every piece is within ``limit``.

    Parameters
    ----------
    model : Model
    index : int
        The panel to slash.
    result : Flattening
        Its flattening without slashes (the slashes are drawn on it).
    limit : float
        The largest principal strain allowed.
    max_slashes : int
        At most this many slashes (and inserts).
    options : dict
        Keywords of :func:`flatten_mesh` (``name`` included).

    Returns
    -------
    Model
        Unchanged if the panel is within the limit, is not saddle-shaped
        (:func:`is_saddle`), or no slashes made it better; otherwise the
        panel (keeping its name and place) followed by its inserts
        (``name-insert-1``, ...), for the fewest slashes that bring every
        piece within the limit, or, if none does, the try that came closest.
    """
    found = slash_search(model, index, result, limit, max_slashes, options)
    return model if found is None else found.model


def slash_search(model: Model, index: int, result: Flattening, limit: float, max_slashes: int,
                 options: dict) -> Remedy | None:
    """What :func:`slashed` found (the worst piece's strain, the model), or None where it leaves the model
    unchanged (the panel within the limit or not saddle-shaped)."""
    before = worst_strain(result)
    if before <= limit:
        return None
    defects = angle_defects(result.vertices, result.faces, loops=result.loops)
    if not _mostly_negative(defects):
        return None
    first = int(np.clip(np.ceil(gore_bound(result, limit, defects=-defects)), 1, max_slashes))
    outline = _Outline(result, np.maximum(-defects, 0.0))
    best = Remedy(before, model)
    for k in range(first, max_slashes + 1):
        tried = _slashed(model, index, outline, k, limit, options)
        if tried.worst < best.worst:
            best = tried
        if tried.worst > limit:
            continue
        for fewer in range(k - 1, 0, -1):  # met at once: as few as meet
            tried = _slashed(model, index, outline, fewer, limit, options)
            if tried.worst > limit:
                break
            best = tried
        break
    return best


def _slashed(model, index, outline, k, limit, options) -> Remedy:
    """The first of :data:`_TRIES` that meets ``limit`` with ``k`` slashes, or the closest; the model as it was,
    at an infinite strain, if none could be cut."""
    best = Remedy(np.inf, model)
    for depth, spread in _TRIES:
        paths = outline.wedge_paths(k, depth, spread)
        split = None if paths is None else split_panel(model, index, paths, inserts=True)
        if split is None or len(split.panels) != len(model.panels) + k:
            continue
        worst = max(worst_strain(flat_piece(split, p, options)) for p in range(index, index + k + 1))
        if worst < best.worst:
            best = Remedy(worst, split)
        if worst <= limit:
            break
    return best


class _Outline:
    """What every try's slashes are laid out from, found once per panel: the outer outline's arc length on
    the layout, its most pressed point, the trough and the excess angle."""

    def __init__(self, result: Flattening, excess: np.ndarray):
        self.result, self.outer = result, np.asarray(result.loops[0])
        uv = result.uv
        self.trough, self.excess = crown_of(uv, excess), float(excess.sum())
        ring = np.r_[self.outer, self.outer[:1]]
        self.arc = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(uv[ring], axis=0), axis=1))]
        flat = np.diff(self.arc)
        real = np.linalg.norm(np.diff(result.vertices[ring], axis=0), axis=1)
        window = max(1, len(self.outer) // 20)  # the most pressed stretch, not the most pressed edge
        pressed = np.convolve(np.r_[flat[-window:], flat, flat[:window]] / np.r_[real[-window:], real, real[:window]],
                              np.ones(2 * window + 1) / (2 * window + 1), "valid")
        self.first = self.arc[int(np.argmin(pressed))]

    def wedge_paths(self, k: int, depth: float, spread: float):
        """``(vertices, faces, paths)``: the two cuts of each of ``k`` wedges put into the mesh, or None."""
        result, outer, arc, trough, first = self.result, self.outer, self.arc, self.trough, self.first
        uv, total = result.uv, arc[-1]
        angle = spread * self.excess / k
        v, f, p = result.vertices, result.faces, uv
        paths, taken = [], []
        for j in range(k):
            at = (first + j * total / k) % total
            start = uv[outer[int(np.argmin(np.abs(arc[:-1] - at)))]]
            tip = int(np.argmin(np.linalg.norm(p - (start + depth * (trough - start)), axis=1)))
            half = math.hypot(*(p[tip] - start)) * np.tan(angle / 2.0)  # no BLAS: its rounding follows the CPU
            if half >= total / (2 * k):
                return None  # the wedges would meet on the outline
            for side in (-1.0, 1.0):
                corner = outer[int(np.argmin(np.abs(arc[:-1] - (at + side * half) % total)))]
                inserted = insert_line(v, f, p, p[corner], p[tip], keep_off=taken)
                v, f, p = inserted.vertices, inserted.faces, inserted.uv
                if inserted.path[0] != corner or inserted.path[-1] != tip:
                    return None
                paths.append(inserted.path)
                taken += [int(x) for x in inserted.path[:-1]]
        areas = face_areas(v, f)
        if areas.min() < _SLIVER * float(np.median(areas)):
            return None  # two cuts ran through one point short of the tip
        return v, f, paths


def relieved(model: Model, first: int, count: int, limit: float, flat: Flattener, *, max_slashes: int,
             max_darts: int | None = None) -> Remedy:
    """Pieces just split from one panel, each brought towards ``limit``: slashed where saddle-shaped, else darted.

    Parameters
    ----------
    model : Model
        The model the pieces are in.
    first, count : int
        The pieces: panels ``first`` to ``first + count - 1``.
    limit : float
        The largest principal strain allowed.
    flat : callable
        ``flat(model, p) -> PanelFlat``: panel ``p`` flattened as
        :func:`patterns.flatten` flattens it.
    max_slashes : int
        A piece above the limit that is saddle-shaped (:func:`is_saddle`) is
        slashed and given inserts (:func:`slash_search`), at most this many.
    max_darts : int, optional
        Any other piece gets darts, at most this many
        (:func:`patterns.flattening.darts.cut_darts`); none if not given.

    Returns
    -------
    Remedy
        The worst strain of all the pieces (inserts included), the model with
        the inserts, and the pieces darted (where ``max_darts`` is given).
    """
    remedy = None
    for remedy in relieving(model, first, count, limit, flat, max_slashes=max_slashes, max_darts=max_darts):
        pass
    return Remedy(0.0, model, {}) if remedy is None else remedy


def relieving(model: Model, first: int, count: int, limit: float, flat: Flattener, *, max_slashes: int,
              max_darts: int | None = None) -> Iterator[Remedy]:
    """:func:`relieved` a piece at a time, so that a search can stop at the first piece above the limit.

    Parameters
    ----------
    model : Model
        The split model; not changed (a slash makes a new one).
    first, count : int
        Its pieces: panels ``first`` to ``first + count - 1``, relieved the last first (an insert moves the
        panels after its own, never those before).
    limit : float
        The area-weighted principal strain each piece must meet (a fraction: 0.03 is 3 %).
    flat : Flattener
        Flattens one panel of a model (the caller's options).
    max_slashes : int
        Slashes a saddle-shaped piece may get (0: none).
    max_darts : int or None
        Darts per piece; None: none cut.

    Yields
    ------
    Remedy
        After each piece, the remedy so far: ``worst`` the worst strain of the pieces done, the model (with any
        slash), each darted piece's darts.  Once ``worst`` is above ``limit`` the whole cannot meet it; the last
        one yielded is :func:`relieved`'s.
    """
    darted, worst = {}, 0.0
    for p in reversed(range(first, first + count)):  # an insert moves the pieces after its panel, not those before
        start = flat(model, p)
        piece = start.flattening
        panel = model.panels[p]
        if worst_strain(piece) > limit and max_slashes > 0 and is_saddle(panel.vertices, panel.faces, panel.loops):
            found = slash_search(model, p, piece, limit, max_slashes, start.options)
            if found is not None:
                worst, model = max(worst, found.worst), found.model
                yield Remedy(worst, model, dict(darted))
                continue
        if max_darts is not None:
            darted[panel.name] = cut_darts(piece, limit, max_darts, start.held, start.options)
            piece = darted[panel.name].flattening
        worst = max(worst, worst_strain(piece))
        yield Remedy(worst, model, dict(darted))

