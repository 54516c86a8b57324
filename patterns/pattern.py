"""The flat pattern: every panel laid flat at true scale, with its seams.

:func:`patterns.flatten` returns a :class:`Pattern`.  A :class:`FlatPanel` keeps
the 3D panel it came from; vertex ``i`` of the panel is at ``uv[i]`` in the
plane (the 3D <-> 2D map is the vertex index).  Millimetres throughout.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["FlatPanel", "FlatSeam", "Pattern"]


@dataclass(frozen=True, eq=False)
class FlatPanel:
    """One panel laid flat.

    Attributes
    ----------
    name : str
    panel : patterns.Panel
        The 3D panel (``panel.vertices[i]`` is laid at ``uv[i]``).
    flattening : patterns.Flattening
        The engine's result: ``uv``, overlap verdict, distortion, iterations.
    """

    name: str
    panel: object
    flattening: object

    @property
    def uv(self) -> np.ndarray:
        """(n, 2) float64, mm: flat position of each panel vertex."""
        return self.flattening.uv

    @property
    def vertices(self) -> np.ndarray:
        """(n, 3) float64, mm: the 3D vertices."""
        return self.panel.vertices

    @property
    def faces(self) -> np.ndarray:
        """(m, 3) int64: the triangles (counter-clockwise in the plane)."""
        return self.panel.faces

    @property
    def loops(self) -> tuple:
        """Outline loops (vertex indices), the outer one first."""
        return self.panel.loops

    def outline(self, loop: int = 0) -> np.ndarray:
        """(k, 2) float64, mm: flat points of one outline loop (not repeated at the end)."""
        return self.uv[self.loops[loop]]

    @property
    def area(self) -> float:
        """Flat area, mm^2."""
        p = self.uv[self.faces]
        a = p[:, 1] - p[:, 0]
        b = p[:, 2] - p[:, 0]
        return float(0.5 * np.sum(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]))


@dataclass(frozen=True, eq=False)
class FlatSeam:
    """A seam and its flat length on each side.

    Attributes
    ----------
    seam : patterns.Seam
    flat_lengths : (float, float)
        Length of the seam's polyline in the flat pattern on side 0 and side 1,
        mm.  The difference is what puckers when the pieces are sewn or welded.
    """

    seam: object
    flat_lengths: tuple

    @property
    def length(self) -> float:
        """The seam's exact 3D length, mm."""
        return self.seam.length

    @property
    def mismatch(self) -> float:
        """``flat_lengths[0] - flat_lengths[1]``, mm."""
        return float(self.flat_lengths[0] - self.flat_lengths[1])


@dataclass(frozen=True, eq=False)
class Pattern:
    """A model's panels laid flat, with its seams.

    Attributes
    ----------
    model : patterns.Model
    panels : tuple of FlatPanel
        In the model's panel order.
    seams : tuple of FlatSeam
        In the model's seam order.
    method : str
        The flattening method used.
    """

    model: object
    panels: tuple
    seams: tuple
    method: str

    @property
    def name(self) -> str:
        return self.model.name

    @property
    def one_to_one(self) -> bool:
        """True when no panel overlaps itself."""
        return all(p.flattening.one_to_one for p in self.panels)

    def __repr__(self) -> str:
        return f"Pattern({self.name!r}, {len(self.panels)} panels, {len(self.seams)} seams, method={self.method!r})"
