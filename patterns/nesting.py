"""Nesting: placing a pattern's panels on a roll (or sheet) of material.

:func:`layout` places every panel by its true outline, bottom-left first,
largest panel first, with a gap between any two and the grain kept along the
roll if asked; overlaps are checked with shapely at every trial.  The roll runs
along +Y from y = 0, ``width`` wide (x from 0 to ``width``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from .errors import InputError, LayoutError
from .options import check_number
from .predicates import flat_polygon

__all__ = ["Layout", "LayoutError", "Placeable", "layout"]


class Placeable(Protocol):
    """What :func:`layout` needs of a pattern (:class:`patterns.Pattern` is one): its name, its flat
    panels, and a copy with the panels placed.  A protocol rather than an import, because
    ``Pattern.layout()`` calls this module."""

    name: str
    panels: tuple

    def placed(self, placements) -> Placeable: ...


@dataclass(frozen=True, eq=False)
class Layout:
    """Where everything went and what it cost.

    Attributes
    ----------
    pattern : patterns.Pattern
        The pattern laid out (``pattern.laid_out`` is True; each panel's
        ``placement`` says where it is).
    width : float
        The roll's width, mm.
    length : float
        Roll length used: the top of the highest panel, mm.
    area_used : float
        ``width * length``, mm^2.
    area_panels : float
        The panels' flat area, mm^2.
    """

    pattern: Placeable
    width: float
    length: float
    area_used: float
    area_panels: float

    @property
    def efficiency(self) -> float:
        """Share of the used material that ends up in panels (0..1)."""
        return self.area_panels / self.area_used if self.area_used > 0 else 0.0


def _orientations(allow_rotation: bool, respect_grain: bool) -> list[float]:
    if respect_grain:
        return [0.0, np.pi] if allow_rotation else [0.0]  # the grain stays along the roll
    return [0.0, 0.5 * np.pi, np.pi, 1.5 * np.pi] if allow_rotation else [0.0]


def layout(pattern, *, width: float, gap: float = 10.0, margin: float = 0.0, allow_rotation: bool = True,
           respect_grain: bool = True, step: float | None = None) -> Layout:
    """Nest the panels of a pattern on a roll ``width`` mm wide.

    Parameters
    ----------
    pattern : patterns.Pattern
    width : float
        Roll (or sheet) width, mm.
    gap : float
        Clearance between panels and from the roll's edges... between panels
        only: panels may touch the roll's edges.  mm, >= 0.
    margin : float
        Extra room around each panel's outline, mm (a seam allowance to be added
        when the DXF is written).
    allow_rotation : bool
        Turn panels by multiples of 90 degrees (180 only, when
        ``respect_grain``).
    respect_grain : bool
        Keep every panel's +Y (its grain line, see ``flatten(grain=...)``)
        along the roll.
    step : float, optional
        Horizontal positions tried, mm apart (default: width / 150).

    Returns
    -------
    Layout

    Raises
    ------
    InputError
        Bad options.
    LayoutError
        A panel is wider than the roll in every allowed orientation.
    """
    import shapely
    from shapely import affinity

    # What a Pattern is, by what layout uses of it (importing the class would make a cycle:
    # Pattern.layout() calls this function).
    if not (hasattr(pattern, "panels") and callable(getattr(pattern, "placed", None))):
        raise InputError(f"layout() takes a patterns.Pattern, got {type(pattern).__name__}")
    width = check_number(width, "width (mm)", low=0, low_open=True, name=pattern.name)
    gap = check_number(gap, "gap (mm)", low=0, name=pattern.name)
    margin = check_number(margin, "margin (mm)", low=0, name=pattern.name)
    step = width / 150.0 if step is None else check_number(step, "step (mm)", low=0, low_open=True,
                                                           name=pattern.name)
    shapes, outlines, base = [], [], []
    for flat in pattern.panels:
        uv = flat.flattening.uv
        outline = flat_polygon(uv, flat.loops, holes=False)
        turn = 0.0
        if not respect_grain:
            # Square the panel up first: its minimum rotated rectangle along the axes.
            box = np.asarray(shapely.minimum_rotated_rectangle(outline).exterior.coords)
            edge = box[1] - box[0]
            turn = -float(np.arctan2(edge[1], edge[0]))
        base.append(turn)
        outline = affinity.rotate(outline, turn, origin=(0.0, 0.0), use_radians=True)
        outlines.append(outline.buffer(margin, join_style="mitre") if margin else outline)
        # For the collision tests: half the gap around each (simplified within 0.25 mm,
        # so the buffer is 0.25 mm wider to stay clear).
        shapes.append(shapely.simplify(outline.buffer(margin + 0.5 * gap + 0.25, join_style="mitre"), 0.25))
    order = np.argsort([-s.area for s in shapes], kind="stable")
    placed = []  # placed (buffered) shapes
    placements = [None] * len(shapes)
    top = 0.0
    for i in order:
        best = None
        for angle in _orientations(allow_rotation, respect_grain):
            turned = affinity.rotate(shapes[i], angle, origin=(0.0, 0.0), use_radians=True)
            x0, y0, x1, y1 = affinity.rotate(outlines[i], angle, origin=(0.0, 0.0), use_radians=True).bounds
            w, h = x1 - x0, y1 - y0
            if w > width + 1e-9:
                continue
            union = shapely.union_all(placed) if placed else None
            if union is not None:
                shapely.prepare(union)
            for x in np.append(np.arange(0.0, width - w, step), width - w):
                dx = x - x0

                def free(y, dx=dx):
                    if union is None:
                        return True
                    return not union.intersects(affinity.translate(turned, dx, y - y0))

                lo, hi = 0.0, top + gap + 1.0
                if free(lo):
                    y = lo
                else:
                    for _ in range(30):
                        mid = 0.5 * (lo + hi)
                        if free(mid):
                            hi = mid
                        else:
                            lo = mid
                    y = hi
                key = (y + h, x)
                if best is None or key < best[0]:
                    best = (key, angle, dx, y - y0, turned)
        if best is None:
            raise LayoutError(f"{pattern.name}: panel {pattern.panels[i].name} is wider than the "
                              f"{width:g} mm roll in every allowed orientation")
        _, angle, dx, dy, turned = best
        shape = affinity.translate(turned, dx, dy)
        placed.append(shape)
        top = max(top, best[0][0])
        placements[i] = (angle + base[i], dx, dy)
    laid = pattern.placed(placements)
    # Length used: the top of the highest outline (without the half gap).
    length = max(float(np.max(flat.uv[:, 1])) for flat in laid.panels)
    low = min(float(np.min(flat.uv[:, 1])) for flat in laid.panels)
    length = length - min(low, 0.0)
    area_panels = float(sum(flat.area for flat in laid.panels))
    return Layout(laid, float(width), length, float(width) * length, area_panels)
