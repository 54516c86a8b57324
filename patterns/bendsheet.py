"""The bend sheet: a blank's bends in the order a press brake bends them, one row each.

The order (the *sequence*) is **outside-in**: the bend whose outer flange is
shallowest goes first.  A bend line cuts the blank in two; its *outer flange*
is the side that reaches the blank's edge soonest, and its depth is how far
that side's farthest edge lies from the bend line, measured square to it.  A
flange bent from the edge of another flange (a return, a hem) is shallower
than the flange it sits on, so it is bent first, while the part is still flat
enough to lie on the die; the bends next to the big middle face come last.
Bends whose outer flanges are equally deep (counted in steps of :data:`TIE` mm) go
shortest bend line first (the short sides of a box before its long ones);
bends equal in both keep the order of the blank's bends.

Everything here takes plain geometry (a shapely polygon and bend lines), so
that a :class:`patterns.Blank` and a drawn piece (moved, nested) give the same
order: the rule depends on lengths only, never on where the blank lies.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import shapely
from shapely.ops import split

__all__ = ["COLUMNS", "TIE", "BendRow", "bend_rows", "flange_depths", "numbered", "sequence"]

TIE = 0.01
"""mm: two outer flanges (or two bend lines) closer in length than this are equal for the sequence: lengths are
counted in its steps, so that the order is total and a near tie is not decided by round-off (the same part on
another machine, or sampled otherwise, numbers its bends the same)."""

COLUMNS = ("part", "sequence", "direction", "angle_deg", "inside_radius_mm", "bend_length_mm", "k_factor",
           "allowance_mm", "flange_mm", "x1_mm", "y1_mm", "x2_mm", "y2_mm")
"""The bend sheet's columns, in order (lengths in mm; ``k_factor`` empty when a bend table gave the bend)."""


def flange_depths(polygon: shapely.Polygon, line: np.ndarray) -> tuple:
    """How far the blank reaches on each side of a bend line, mm.

    Parameters
    ----------
    polygon : shapely.Polygon
        The blank (outline and holes), mm.
    line : (2, 2) float64
        The bend line, end to end, mm.

    Returns
    -------
    tuple of float
        ``(left, right)``: the farthest distance, square to the line, of the blank's material joined to the
        line on its left (counter-clockwise normal) and on its right.  The blank is split along the bend line
        (extended 1 µm past its ends, so that a line drawn edge to edge cuts it); when the line does not cut
        it in two, every outline point on each side counts.
    """
    a, b = np.asarray(line, dtype=np.float64).reshape(2, 2)
    length = float(np.linalg.norm(b - a))
    d = (b - a) / max(length, 1e-12)
    n = np.array([-d[1], d[0]])
    cutter = shapely.LineString([a - 1e-3 * d, b + 1e-3 * d])
    segment = shapely.LineString([a, b])
    try:
        parts = [p for p in split(polygon, cutter).geoms if p.distance(segment) < 1e-6]
    except shapely.errors.GEOSException:  # a blank whose flanges overlap is no valid polygon: no split
        parts = []
    depth = [0.0, 0.0]
    if len(parts) >= 2:
        for part in parts:
            s = (np.asarray(part.exterior.coords) - a) @ n
            side = 0 if (np.asarray(part.representative_point().coords)[0] - a) @ n > 0 else 1
            depth[side] = max(depth[side], float(np.abs(s).max()))
    else:
        s = (np.asarray(polygon.exterior.coords) - a) @ n
        depth = [max(float(s.max()), 0.0), max(float(-s.min()), 0.0)]
    return depth[0], depth[1]


def sequence(polygon: shapely.Polygon, lines) -> tuple:
    """The press-brake order of a blank's bends (see the module's rule).

    Parameters
    ----------
    polygon : shapely.Polygon
        The blank, mm.
    lines : sequence of (2, 2) float64
        Its bend lines, mm.

    Returns
    -------
    tuple of int
        The bends' indices, first bent first.
    """
    return _order([min(flange_depths(polygon, line)) for line in lines], lines)


def numbered(polygon: shapely.Polygon, bends) -> tuple:
    """The bends, each with its ``sequence`` (1 for the first to bend) and its outer ``flange`` depth, mm:
    the one place a blank's bends are ordered (:class:`patterns.Blank` numbers its bends when it is made;
    its pieces, the drawings, the report and the bend sheet read the numbers).

    Parameters
    ----------
    polygon : shapely.Polygon
        The blank, mm.
    bends : sequence
        Its bends: frozen dataclasses with ``line`` ((2, 2) float64, mm), ``sequence`` and ``flange``.
    """
    bends = list(bends)
    outer = [min(flange_depths(polygon, b.line)) for b in bends]
    rank = {i: k for k, i in enumerate(_order(outer, [b.line for b in bends]), start=1)}
    return tuple(replace(b, sequence=rank[i], flange=outer[i]) for i, b in enumerate(bends))


def _order(outer: list, lines) -> tuple:
    """:func:`sequence` from each bend's outer flange depth, mm, already measured."""
    length = [float(np.linalg.norm(np.subtract(*np.asarray(line).reshape(2, 2)))) for line in lines]
    # depths and lengths counted in steps of TIE: a total order (a comparison "within TIE" is not transitive,
    # and the report and the drawing, measured on differently sampled outlines, could then number a near tie
    # apart)
    return tuple(sorted(range(len(outer)), key=lambda i: (round(outer[i] / TIE), round(length[i] / TIE), i)))


@dataclass(frozen=True)
class BendRow:
    """One row of a bend sheet (lengths in the unit the sheet was made in, mm unless a writer said otherwise).

    Attributes
    ----------
    part : str
        The blank's (or its drawn piece's) name.
    sequence : int
        1 for the first bend to make.
    direction : str
        ``"up"`` or ``"down"``, seen from the side of the blank drawn.
    angle_deg : float
        How far the sheet turns in the bend.
    inside_radius_mm : float
    bend_length_mm : float
        The bend line's length.
    k_factor : float or None
        None when a bend table gave the bend's allowance.
    allowance_mm : float
        The developed width of the bend zone.
    flange_mm : float
        Depth of the bend's outer flange (what the sequence sorts by).
    x1_mm, y1_mm, x2_mm, y2_mm : float
        The bend line's ends, in the drawing's (or the blank's) coordinates.
    """

    part: str
    sequence: int
    direction: str
    angle_deg: float
    inside_radius_mm: float
    bend_length_mm: float
    k_factor: float | None
    allowance_mm: float
    flange_mm: float
    x1_mm: float
    y1_mm: float
    x2_mm: float
    y2_mm: float

    def to_dict(self) -> dict:
        """``{column: value}`` in :data:`COLUMNS` order."""
        return {c: getattr(self, c) for c in COLUMNS}


def bend_rows(part: str, bends, *, scale: float = 1.0) -> tuple:
    """The bend sheet of one blank: a :class:`BendRow` per bend, in sequence.

    Parameters
    ----------
    part : str
    bends : sequence
        Its bends, numbered (:func:`numbered`): each with ``sequence``, ``flange``, ``line`` ((2, 2) float64,
        mm), ``direction``, ``angle``, ``inside_radius``, ``k_factor`` and ``allowance`` (a
        :class:`patterns.blank.Bend` or a drawn piece's bend line).
    scale : float
        Lengths are multiplied by it (``1 / 25.4`` for inches).

    Returns
    -------
    tuple of BendRow
    """
    rows = []
    for b in sorted(bends, key=lambda b: b.sequence):
        (x1, y1), (x2, y2) = np.asarray(b.line, dtype=np.float64) * scale
        rows.append(BendRow(part, b.sequence, b.direction, float(b.angle), float(b.inside_radius) * scale,
                            float(np.linalg.norm(np.subtract(*b.line))) * scale, b.k_factor,
                            float(b.allowance) * scale, float(b.flange) * scale,
                            float(x1), float(y1), float(x2), float(y2)))
    return tuple(rows)
