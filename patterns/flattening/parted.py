"""Pieces with darts: a panel that darts alone cannot bring within the strain limit, parted into a few pieces.

A pattern maker whose dome asks for more darts than one panel can take adds
style seams: a bowl's cover in three pieces with four or five darts each, not
one panel with fourteen.  :func:`parted` is what :func:`patterns.flatten` does
with ``max_strain`` (darts: not ``gores=True``) on a panel that is not
saddle-shaped, before its darts:

* **When.**  Where the panel's gore bound asks for more darts than
  ``max_darts`` allows (darts need about 1.2 times the bound,
  :func:`patterns.flattening.curvature.gore_bound`: then no dart is tried on
  the whole panel), or where the darts tried on it fell short of the limit.
* **How.**  Cut as gores are (:func:`patterns.flattening.split.split_panel`,
  straight cuts from evenly spaced outline points to one crown), each cut a
  seam held at its 3D length; each piece flattened with its seams held and
  darted (:func:`patterns.flattening.darts.cut_darts`, at most ``max_darts``
  each: the pieces are sewn to each other, so their darts run towards the
  corner where the seams meet).
* **How many pieces.**  The fewest whose gore bound is at most
  :data:`_PIECE_BOUND` each, and never fewer than three, then one more
  (:data:`_COUNTS` counts at most): measured on the benchmark's domes, halves
  of a dome do not take darts well (the oblate dome: one half 15 % after 17
  tries; the ellipsoid: both halves 10 %), thirds and quarters do (the bowl,
  the oblate dome and the ellipsoid all meet 3 % in three pieces).
* **Saddles slashed.**  A piece above the limit that is saddle-shaped (a
  seat's waist beside its dome) is slashed and given inserts
  (:func:`patterns.flattening.inserts.relieved`, at most ``max_darts``
  slashes), not darted: a dart takes out material a saddle lacks.
* **Or gores.**  Where no count tried meets the limit, the caller cuts
  dartless gores (:func:`patterns.flattening.gores.gored`, at most
  ``max_gores``) and keeps whichever came closest.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..model import Model
from ..pattern import Flattening
from .curvature import gore_bound
from .gores import gore_paths
from .inserts import relieving
from .remedy import Flattener, Remedy
from .split import split_panel

__all__ = ["Parting", "darts_needed", "parted", "parting"]

_PIECE_BOUND = 4.0  # a piece's share of the gore bound at most this (about 5 darts a piece)
_COUNTS = 2  # piece counts tried: the first and one more
_DARTS_PER_BOUND = 1.2  # darts a panel needs per unit of gore bound (measured: the hemisphere, 11 against 9.07)


def darts_needed(result: Flattening, limit: float) -> float:
    """About how many darts the panel needs to come within ``limit``: 1.2 times its gore bound."""
    return _DARTS_PER_BOUND * gore_bound(result, limit)


def parted(model: Model, index: int, result: Flattening, limit: float, max_darts: int, max_pieces: int,
           flat: Flattener) -> Remedy | None:
    """Panel ``index`` parted into the fewest pieces tried that each come within ``limit`` with darts.

    Parameters
    ----------
    model : Model
    index : int
        The panel to part.
    result : Flattening
        Its dartless flattening (the cuts are drawn on it).
    limit : float
        The largest principal strain allowed.
    max_darts : int
        At most this many darts per piece.
    max_pieces : int
        At most this many cuts (``max_gores``).
    flat : callable
        ``flat(model, p) -> PanelFlat``: panel ``p`` of a model flattened as
        :func:`patterns.flatten` flattens it.

    Returns
    -------
    Remedy or None
        The worst piece's strain, the parted model and its pieces darted: the first count tried that meets the
        limit, or the one that came closest; None where no count could be cut.
    """
    found = parting(model, index, result, limit, max_darts, max_pieces, flat)
    return None if found is None else found.met or found.closest()


@dataclass(frozen=True, eq=False)
class Parting:
    """The piece counts :func:`parting` tried.

    Attributes
    ----------
    tried : tuple of (Remedy, Iterator[Remedy])
        Each count that missed the limit: where it stopped (its first piece above it) and the rest of its
        pieces, not yet done (:func:`~patterns.flattening.inserts.relieving`'s iterator).
    met : Remedy or None
        The first count that meets the limit; None where none does.
    """

    tried: tuple
    met: Remedy | None = None

    @cached_property
    def _finished(self) -> tuple:
        """Each count of ``tried`` with its other pieces done, once: the last each iterator yields is the whole."""
        return tuple(next(iter(deque(rest, maxlen=1)), last) for last, rest in self.tried)

    def closest(self) -> Remedy:
        """The count that came closest, every piece of every count done (on a tie, the fewer pieces): what
        :func:`parted` gives where no count meets the limit."""
        best = None
        for last in self._finished:
            if best is None or last.worst < best.worst:
                best = last
        return best


def parting(model: Model, index: int, result: Flattening, limit: float, max_darts: int, max_pieces: int,
            flat: Flattener) -> Parting | None:
    """:func:`parted`, with a count stopped at its first piece above the limit (it cannot meet it: every
    piece of a count must), so that a caller with another remedy still to try (gores) finishes the counts
    only if that one falls short too.  The pieces are the last first, as :func:`relieved` takes them.
    None where no count could be cut."""
    first = max(3, int(np.ceil(gore_bound(result, limit) / _PIECE_BOUND)))
    tried = []
    for k in range(first, min(first + _COUNTS, max_pieces + 1)):
        paths = gore_paths(result, k, limit)
        split = None if paths is None else split_panel(model, index, paths)
        if split is None:
            continue
        pieces = relieving(split, index, len(split.panels) - len(model.panels) + 1, limit, flat,
                           max_slashes=max_darts, max_darts=max_darts)
        done = None
        for done in pieces:
            if done.worst > limit:
                break
        else:
            return Parting(tuple(tried), done)  # every piece within the limit
        tried.append((done, pieces))
    return Parting(tuple(tried)) if tried else None
