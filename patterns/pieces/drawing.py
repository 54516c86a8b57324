"""A drawing: the pieces one file holds, in the one frame every writer of that file uses.

:func:`drawing_of` lays out pieces that are not nested in rows of their
bounding boxes (moved only, never turned or scaled) and puts the whole
drawing in the first quadrant, :data:`MARGIN` from each axis, where a
cutter's work area and a page start.  A nest (:func:`patterns.layout`) is
moved the same way, roll or sheets and all.  Writers never move anything: the
DXF, the SVG and the JSON report of one drawing have every coordinate in
common.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from ..curves import Motion
from ..findings import Finding
from ..pattern import Pattern
from ..text import printable
from ..units import Unit
from .build import pieces_of
from .options import PieceOptions

__all__ = ["MARGIN", "Drawing", "SheetFigures", "arrange", "drawing_of", "place_nest", "row_offsets"]

MARGIN = 5.0
"""Every drawing starts this far (mm) from the X and Y axes, in the first quadrant."""


@dataclass(frozen=True)
class SheetFigures:
    """What a shop quotes one sheet (or the used length of a roll) from.

    Attributes
    ----------
    index : int
        0 for the first sheet.
    size : (float, float)
        ``(length, width)`` of the stock, mm.
    pieces : tuple of str
        The names of the pieces on it.
    usage : float
        The pieces' cut area over the stock's area (0..1).
    cut_length : float
        Every outline and hole the cutter cuts, mm (arcs as arcs).
    pierces : int
        Where the cutter pierces: one per closed cut contour (each outline and each hole).
    bends : int
        The bend lines of its blanks (a press brake's strokes; a rolled panel's rulings not counted).
    """

    index: int
    size: tuple
    pieces: tuple
    usage: float
    cut_length: float
    pierces: int
    bends: int

    def to_dict(self) -> dict:
        return {"index": self.index, "size_mm": [round(self.size[0], 3), round(self.size[1], 3)],
                "pieces": list(self.pieces), "usage": round(self.usage, 6), "cut_length_mm": round(self.cut_length, 3),
                "pierces": self.pierces, "bends": self.bends}


@dataclass(frozen=True, eq=False)
class Drawing:
    """What one file holds (mm, the file's own frame).

    Attributes
    ----------
    name : str
        The part's or the nest's name.
    pieces : tuple of Piece
    stock : tuple of (x0, y0, x1, y1)
        A nest's roll (its used length) or each of its sheets, mm; empty when not nested.
    note : str
        A nest's summary ("a 1500 mm roll: 3592.0 mm used, efficiency 74.2 %"), drawn beside the stock.
    report : dict or None
        The check report (``patterns.Report.to_dict``) of what the pieces were made from, in this frame:
        the JSON profile writes it with the pieces.
    """

    name: str
    pieces: tuple
    stock: tuple = ()
    note: str = ""
    report: Mapping | None = field(default=None)

    def __post_init__(self):
        # a name from a file name may hold control characters or bytes that are not UTF-8: made safe once, here,
        # for every writer (an SVG's title, a DXF's text, a CSV's cell, a terminal)
        object.__setattr__(self, "name", printable(self.name))
        object.__setattr__(self, "note", printable(self.note))

    def sheet_drawings(self) -> tuple:
        """A drawing per sheet of the stock (a roll's used length is one): the pieces on it, moved with it into
        a file's frame, named ``"<name> sheet <k>"``; empty when not nested."""
        out = []
        for figures, rect in zip(self.sheets(), self.stock):
            on = tuple(p for p in self.pieces if p.name in set(figures.pieces))
            pieces, stock = place_nest(on, (rect,))
            out.append(Drawing(f"{self.name} sheet {figures.index + 1}", pieces, stock,
                               f"sheet {figures.index + 1} of {len(self.stock)}", self.report))
        return tuple(out)

    def sheets(self) -> tuple:
        """A :class:`SheetFigures` per sheet of the stock (a roll's used length is one), each piece on the one
        that holds its middle; empty when not nested."""
        out = []
        for index, (x0, y0, x1, y1) in enumerate(self.stock):
            on = []
            for piece in self.pieces:
                px0, py0, px1, py1 = piece.bounds
                if x0 <= (px0 + px1) / 2 <= x1 and y0 <= (py0 + py1) / 2 <= y1:
                    on.append(piece)
            area = (x1 - x0) * (y1 - y0)
            out.append(SheetFigures(index, (float(y1 - y0), float(x1 - x0)), tuple(p.name for p in on),
                                    float(sum(p.area for p in on) / area) if area > 0 else 0.0,
                                    float(sum(p.outline.length + sum(h.length for h in p.holes) for p in on)),
                                    sum(1 + len(p.holes) for p in on),
                                    sum(1 for p in on for b in p.bends if b.direction)))
        return tuple(out)

    @property
    def bounds(self) -> tuple:
        """``(x0, y0, x1, y1)`` of every cut outline and the stock, mm."""
        boxes = [p.bounds for p in self.pieces] + [tuple(s) for s in self.stock]
        b = np.array(boxes, dtype=np.float64).reshape(-1, 4)
        return (float(b[:, 0].min()), float(b[:, 1].min()), float(b[:, 2].max()), float(b[:, 3].max()))


def row_offsets(boxes, *, gap: float | None = None) -> np.ndarray:
    """Where to move each box so that they lie in rows: ``(k, 2)`` mm translations.

    ``boxes`` ``(k, 4)``: ``(x0, y0, x1, y1)`` each, mm.  Rows run left to right, downwards, about
    1.6 times as wide as the boxes' total area's square root; ``gap`` (default 8 % of the largest box)
    between boxes and rows.
    """
    boxes = np.asarray(boxes, dtype=np.float64).reshape(-1, 4)
    sizes = boxes[:, 2:] - boxes[:, :2]
    if gap is None:
        gap = 0.08 * float(np.max(sizes))
    width = max(float(np.sqrt((sizes[:, 0] + gap) @ (sizes[:, 1] + gap)) * 1.6), float(sizes[:, 0].max()))
    offsets = np.zeros((len(boxes), 2))
    x = y = row = 0.0
    for i, (w, h) in enumerate(sizes):
        if x > 0 and x + w > width:
            x, y, row = 0.0, y - row - gap, 0.0
        offsets[i] = (x - boxes[i, 0], y - boxes[i, 3])
        x += w + gap
        row = max(row, h)
    return offsets


def _to_margin(pieces, stock, margin: float) -> tuple:
    """Pieces and stock moved together so that their extents start ``margin`` from both axes."""
    d = Drawing("", tuple(pieces), tuple(stock))
    x0, y0, _, _ = d.bounds
    shift = Motion(0.0, margin - x0, margin - y0)
    moved = tuple(p.moved(shift) for p in pieces)
    rects = tuple((x0_ + shift.dx, y0_ + shift.dy, x1_ + shift.dx, y1_ + shift.dy) for x0_, y0_, x1_, y1_ in stock)
    return moved, rects


def arrange(pieces, *, gap: float | None = None, margin: float = MARGIN, rows: bool = True) -> tuple:
    """Pieces laid in rows of their bounding boxes (``rows``; else where they lie), moved only, the drawing
    ``margin`` mm from both axes."""
    pieces = tuple(pieces)
    if not rows:
        return _to_margin(pieces, (), margin)[0]
    offsets = row_offsets([p.bounds for p in pieces], gap=gap)
    moved = [p.moved(Motion(0.0, float(dx), float(dy))) for p, (dx, dy) in zip(pieces, offsets)]
    return _to_margin(moved, (), margin)[0]


def place_nest(pieces, stock, *, margin: float = MARGIN) -> tuple:
    """``(pieces, stock)`` of a nest moved together into the drawing's frame."""
    return _to_margin(tuple(pieces), tuple(stock), margin)


def drawing_of(source, options: PieceOptions | None = None, *, findings: tuple[Finding, ...] = (),
               unit: Unit | str = Unit.MM, **keywords) -> Drawing:
    """The drawing of a pattern, a blank, pieces or a list of them: their pieces laid in rows (a pattern
    already laid out, :meth:`patterns.Pattern.placed`, keeps its layout).

    Parameters
    ----------
    source : patterns.Pattern, patterns.Blank, Piece, Drawing, or a sequence of them
        A :class:`Drawing` is returned as it is.
    options : PieceOptions, optional
        Keywords (any :class:`PieceOptions` field) go over it; ``gap`` is the space between pieces.
    findings : tuple of patterns.Finding
        A pattern's check findings, for its pieces.
    unit : patterns.Unit or str
        The unit the pieces' seam labels say (the file's: default mm); their labels are placed once, for it.
    """
    if isinstance(source, Drawing):
        return source
    opts = PieceOptions.of(options, keywords)
    pieces = pieces_of(source, opts, findings=findings, unit=unit)
    items = list(source) if isinstance(source, (list, tuple)) else [source]
    name = " + ".join(dict.fromkeys(str(getattr(item, "name", "")) for item in items)) or "pieces"
    laid_out = isinstance(source, Pattern) and source.laid_out
    return Drawing(name, arrange(pieces, gap=opts.gap, rows=not laid_out))

