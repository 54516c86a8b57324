"""Labels placed inside their panel, clear of the cut and seam lines and of each other.

Every text the DXF writers put on a panel (its name, its strain, a seam's
lengths, a bend's angle) asks for a place: it is tried at the places it
prefers (first the one it asks for), then at smaller sizes, and taken at the
first where its box lies inside the finished piece (the seam line's polygon),
a quarter of its height clear of the outline, and off every label already
placed.  A label that fits nowhere at a third of its size is left out rather
than drawn across a cut.  Boxes are measured with ezdxf's font metrics of the
standard style, 10 % wider for readers with wider fonts.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import lru_cache

import numpy as np
import shapely

from ..units import Unit
from .piece import Piece, SeamSide

__all__ = ["Label", "LabelPlacer", "piece_labels", "readable_angle", "seam_text", "text_box"]

SCALES = (1.0, 0.8, 0.64, 0.5, 0.4, 0.33)
"""The sizes a label is tried at, as fractions of the size it asks for."""


@lru_cache(maxsize=1)
def _font():
    from ezdxf.fonts import fonts

    return fonts.make_font("txt", 1.0)


def text_width(text: str, height: float) -> float:
    """Width of ``text`` at cap height ``height`` in the standard style, mm (ezdxf's metrics)."""
    return float(_font().text_width(text)) * height


def text_box(text: str, at, height: float, angle: float, *, widen: float = 1.1) -> shapely.Polygon:
    """The box a MIDDLE_CENTER-aligned TEXT covers: ``widen`` x its width, from a descender below the
    baseline to the cap height, turned by ``angle`` degrees about ``at``."""
    w = 0.5 * widen * text_width(text, height)
    lo, hi = -0.5 * height - 0.25 * height, 0.5 * height
    corners = np.array([[-w, lo], [w, lo], [w, hi], [-w, hi]])
    a = np.radians(angle)
    rot = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
    return shapely.Polygon(corners @ rot.T + np.asarray(at, dtype=np.float64))


@dataclass(frozen=True)
class Label:
    """A placed label: its text, centre (2,) mm, cap height mm and angle (degrees), and what it says:
    ``"title"`` (the piece's name and what it is), ``"seam"`` (a seam side's lengths) or ``"bend"``."""

    text: str
    at: np.ndarray
    height: float
    angle: float
    kind: str = "title"
    of: int = -1
    """A seam label's index in :attr:`Piece.seams`, a bend label's in :attr:`Piece.bends` (-1 for the title)."""


class LabelPlacer:
    """Places the labels of one panel, one after another, each clear of those before it.

    Parameters
    ----------
    piece : shapely.Polygon
        The finished piece (the seam line's polygon), mm.
    """

    def __init__(self, piece: shapely.Polygon):
        self.piece = piece
        self.boxes = []
        self.labels = []
        self.left_out = []

    def place(self, text: str, places, height: float, angle: float = 0.0) -> Label | None:
        """Put ``text`` at the first of ``places`` ((k, 2) mm, in order of preference) where it fits,
        at ``height`` or smaller; None (and noted in :attr:`left_out`) when it fits nowhere."""
        block = self.place_block([(text, 0.0, 1.0)], places, height, angle)
        return block[0] if block else None

    def place_block(self, lines, places, height: float, angle: float = 0.0) -> list:
        """Place lines of text together: ``lines`` are ``(text, offset, size)``, the offset of each line's
        middle across the block and its cap height, both in units of ``height``; the block is tried at
        ``places`` ((k, 2) mm) and shrunk as a whole.  Returns the placed :class:`Label` list, empty
        when the block fits nowhere (its texts then noted in :attr:`left_out`)."""
        places = np.asarray(places, dtype=np.float64).reshape(-1, 2)
        a = np.radians(angle)
        across = np.array([-np.sin(a), np.cos(a)])
        for scale in SCALES:
            h = height * scale
            inner = self.piece.buffer(-0.25 * h)
            if inner.is_empty:
                continue
            for at in places:
                boxes = [text_box(t, at + off * h * across, size * h, angle) for t, off, size in lines]
                if all(inner.contains(b) for b in boxes) and not any(
                        b.intersects(c) for b in boxes for c in self.boxes):
                    self.boxes.extend(boxes)
                    placed = [Label(t, at + off * h * across, size * h, angle) for t, off, size in lines]
                    self.labels.extend(placed)
                    return placed
        self.left_out.extend(t for t, _, _ in lines)
        return []

    def inside_places(self, near, step: float, limit: int = 300) -> np.ndarray:
        """Points inside the piece on a grid ``step`` apart, nearest to ``near`` first; ``near`` and the
        piece's pole of inaccessibility lead."""
        from shapely.ops import polylabel

        x0, y0, x1, y1 = self.piece.bounds
        step = max(step, max(x1 - x0, y1 - y0) / 150)  # a large piece: a coarser grid, some 20000 points at most
        xs, ys = np.arange(x0, x1 + step, step), np.arange(y0, y1 + step, step)
        grid = np.stack(np.meshgrid(xs, ys), axis=-1).reshape(-1, 2)
        grid = grid[shapely.contains_xy(self.piece, grid[:, 0], grid[:, 1])]
        grid = grid[np.argsort(np.linalg.norm(grid - near, axis=1))][:limit]
        pole = np.array(polylabel(self.piece, tolerance=max(step / 4, 1e-3)).coords[0])
        return np.vstack([np.asarray(near, dtype=np.float64).reshape(1, 2), pole.reshape(1, 2), grid])


def along(points: np.ndarray, inward_offset: float, *, fractions=(0.5, 0.4, 0.6, 0.3, 0.7, 0.2, 0.8)):
    """Places along a polyline ((k, 2) mm), at ``fractions`` of its length, moved ``inward_offset`` to its left.

    Returns ``[(place (2,), tangent (2,))]``."""
    points = np.asarray(points, dtype=np.float64)
    seg = np.linalg.norm(np.diff(points, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    out = []
    for f in fractions:
        t = f * s[-1]
        j = int(np.clip(np.searchsorted(s, t, side="right") - 1, 0, len(seg) - 1))
        u = (t - s[j]) / max(seg[j], 1e-300)
        p = points[j] + u * (points[j + 1] - points[j])
        tangent = (points[j + 1] - points[j]) / max(seg[j], 1e-300)
        out.append((p + inward_offset * np.array([-tangent[1], tangent[0]]), tangent))
    return out


def readable_angle(direction) -> float:
    """The angle (degrees, in (-90, 90]) of a text along ``direction`` (2,), so that it reads left to right."""
    angle = float(np.degrees(np.arctan2(direction[1], direction[0])))
    if angle > 90:
        angle -= 180
    elif angle <= -90:
        angle += 180
    return angle


def seam_text(side: SeamSide, unit: Unit = Unit.MM) -> str:
    """The annotation written next to a seam: id, 3D length and this side's flat length, in the drawing's unit.

    Two decimals in mm, four in the larger units (0.01 mm or finer either way).
    """
    digits = 2 if unit is Unit.MM else 4
    return (f"S{side.seam} 3D {side.length_3d / unit.mm:.{digits}f} FLAT {side.length_flat / unit.mm:.{digits}f} "
            f"{unit.label}")


def piece_labels(piece: Piece, unit: Unit = Unit.MM, *, block=None) -> list:
    """Every label of a piece, each placed clear of the others inside the finished piece.

    Parameters
    ----------
    piece : Piece
    unit : patterns.Unit
        The drawing's unit (the seam labels say it).
    block : list of (str, float, float), optional
        The title block, as :meth:`LabelPlacer.place_block` takes it; default the piece's name
        (1.2 text heights) and the first line of its title (0.7).

    Returns
    -------
    list of Label
        The title block (kind ``"title"``), then one label per seam side (``"seam"``, 0.6 text heights,
        along the seam and 1.6 label heights inside it, its middle first), then one per bend line
        (``"bend"``, half a text height, centred on the line).
    """
    placer = LabelPlacer(piece.finished)
    th = piece.text_height
    if block is None:
        block = [(piece.name, 0.8, 1.2)] + [(line, -0.9, 0.7) for line in piece.title[:1]]
    out = list(placer.place_block(block, placer.inside_places(piece.label_at, th), th))
    for k, side in enumerate(piece.seams):
        text = seam_text(side, unit)
        for place, tangent in along(side.points, 1.6 * 0.6 * th):
            label = placer.place(text, [place], 0.6 * th, readable_angle(tangent))
            if label is not None:
                out.append(replace(label, kind="seam", of=k))
                break
    for k, bend in enumerate(piece.bends):
        a, b = bend.line
        length = float(np.linalg.norm(b - a))
        direction = (b - a) / max(length, 1e-12)
        places = [b - direction * f * length for f in (0.1, 0.3, 0.5, 0.7, 0.9)]
        label = placer.place(bend.label, places, 0.5 * th, readable_angle(direction))
        if label is not None:
            out.append(replace(label, kind="bend", of=k))
    return out
