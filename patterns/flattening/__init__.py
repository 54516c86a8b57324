"""Flattening: 3D triangle meshes to 1:1 flat patterns.

* :mod:`~patterns.flattening.engine`: :func:`flatten_mesh` (arrays in, a frozen
  :class:`Flattening` out) -- the growers (:mod:`~patterns.flattening.grow`),
  the relaxation (:mod:`~patterns.flattening.relax`,
  :mod:`~patterns.flattening.energy`), the starts
  (:mod:`~patterns.flattening.embed`) and numberings
  (:mod:`~patterns.flattening.numbering`);
* :mod:`~patterns.flattening.panels`: :func:`flatten` (a ``Model`` in, a
  ``Pattern`` out), with exact developments (:mod:`~patterns.flattening.develop`),
  held seams (:mod:`~patterns.flattening.seams`), darts
  (:mod:`~patterns.flattening.darts`) and grain (:mod:`~patterns.flattening.grain`).
"""

from ..pattern import Flattening
from .engine import flatten_mesh
from .panels import flatten
from .settings import METHODS, FlattenOptions

__all__ = ["METHODS", "FlattenOptions", "Flattening", "flatten", "flatten_mesh"]
