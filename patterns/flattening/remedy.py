"""What the remedies for too much strain give back: frozen records, one meaning per name.

:func:`patterns.flatten` with ``max_strain`` plans, panel by panel (:mod:`.panels`), among the remedies a
pattern maker has -- darts (:mod:`.darts`), pieces with darts (:mod:`.parted`), gores (:mod:`.gores`),
slashes with inserts (:mod:`.inserts`) -- and keeps whichever meets the limit first, or came closest.  Each
remedy answers in one of these records, side by side here:

* :class:`PanelFlat` -- a panel flattened as :func:`patterns.flatten` flattens it (what a :data:`Flattener`
  gives): its flattening, its held seam lengths, the engine's keywords;
* :class:`Darted` -- a panel with its darts cut (:func:`.darts.cut_darts`);
* :class:`Remedy` -- a panel split (parted, gored, slashed): the worst piece's strain, the model with the
  pieces, and the pieces that were darted.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from ..model import Model
from ..pattern import DartSearch, Flattening

__all__ = ["Darted", "Flattener", "PanelFlat", "Remedy"]


@dataclass(frozen=True, eq=False)
class PanelFlat:
    """A panel flattened as :func:`patterns.flatten` flattens it.

    Attributes
    ----------
    flattening : Flattening
    held : tuple or None
        Its held seam lengths (``lengths`` of :func:`~patterns.flatten_mesh`: edges (k, 2) int64, mm (k,)
        float64[, groups]), or None (nothing held).
    options : dict
        The keywords of :func:`~patterns.flatten_mesh` it was flattened with (``name`` included): its darts
        and pieces are flattened with them too.
    """

    flattening: Flattening
    held: tuple | None
    options: dict


Flattener = Callable[[Model, int], PanelFlat]
"""``flat(model, p) -> PanelFlat``: flattens panel ``p`` of a model (a split panel's piece) as
:func:`patterns.flatten` flattens a panel."""


@dataclass(frozen=True, eq=False)
class Darted:
    """A panel with its darts cut (:func:`patterns.flattening.darts.cut_darts`).

    Attributes
    ----------
    flattening : Flattening
        The panel with its darts sewn (or as it was, where no dart helped).
    darts : tuple of patterns.Dart
    search : patterns.DartSearch or None
        What the search tried and found (None: no dart asked for).
    """

    flattening: Flattening
    darts: tuple
    search: DartSearch | None


@dataclass(frozen=True, eq=False)
class Remedy:
    """A panel split into pieces (parted, gored, slashed and given inserts).

    Attributes
    ----------
    worst : float
        The worst principal strain of all its pieces (inserts included).
    model : Model
        The model with the pieces in the panel's place.
    darted : dict
        ``{piece name: Darted}`` of the pieces darted (parted pieces); empty for gores and inserts.
    """

    worst: float
    model: Model
    darted: dict = field(default_factory=dict)
