"""Labels placed inside their panel, clear of the cut and seam lines and of each other.

Every text the DXF writers put on a panel (its name, its strain, a seam's
lengths, a bend's angle) asks for a place: it is tried at the places it
prefers (first the one it asks for), then at smaller sizes, and taken at the
first where its box lies inside the finished piece (the seam line's polygon,
clear of its holes), a quarter of its height clear of the outline, and off
every label already placed.  No label is drawn below
:data:`LEAST_TEXT_HEIGHT` (2 mm; or the piece's text height, when a smaller
one was asked for): one that fits nowhere at that height is left out rather
than shrunk or drawn across a cut, and :func:`label_findings` says so (a
``label-left-out`` note on the piece).  Boxes are measured with ezdxf's font
metrics of the standard style, 10 % wider for readers with wider fonts.

A piece's labels are placed once, when :func:`~patterns.pieces.pieces_of` makes
it (:func:`place_labels`), for the unit its seam labels say (the drawing's: mm
unless a machine DXF in another unit is made), and kept on the piece
(``Piece.labels``), moved with it by the layout and the nester; the notes, the
DXF, SVG and JSON writers and the worker all read those (:func:`piece_labels`).
Only a writer in another unit than the one the piece was labelled for places
them anew.  ASTM's title block (the standard's annotation lines) is its own: it
alone is placed by that writer, clear of the piece's other labels.
"""

from __future__ import annotations

from dataclasses import replace
from functools import lru_cache

import numpy as np
import shapely

from ..findings import Code, Finding, Severity
from ..units import Unit
from .piece import BendLine, Label, Labels, Piece, SeamSide

__all__ = ["LEAST_TEXT_HEIGHT", "Label", "LabelPlacer", "Labels", "label_findings", "labels_of", "least_height",
           "piece_labels", "place_labels", "readable_angle", "seam_text", "text_box", "with_labels"]

SCALES = (1.0, 0.8, 0.64, 0.5, 0.4, 0.33)
"""The sizes a label is tried at, as fractions of the size it asks for (never below the least height)."""

LEAST_TEXT_HEIGHT = 2.0
"""The least height of any label, mm: the low end of the default text height (3 % of a piece's size, 2-12 mm).
A label that does not fit at it is left out, with a finding; never drawn smaller."""


def least_height(text_height: float) -> float:
    """The least label height on a piece whose text height is ``text_height`` mm: :data:`LEAST_TEXT_HEIGHT`,
    or ``text_height`` itself when it is smaller (only ever when asked for explicitly)."""
    return min(LEAST_TEXT_HEIGHT, float(text_height))


def _heights(height: float, floor: float) -> list:
    """The heights a label that asks for ``height`` is tried at: :data:`SCALES` of it while above ``floor``,
    then ``floor`` itself (only ``floor`` when it asks for less)."""
    out = [height * s for s in SCALES if height * s > floor * (1 + 1e-9)]
    return out if len(out) == len(SCALES) else out + [floor]


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


class LabelPlacer:
    """Places the labels of one panel, one after another, each clear of those before it.

    Parameters
    ----------
    piece : shapely.Polygon
        The finished piece (the seam line's polygon, its holes with it), mm.
    least : float
        No label is placed smaller than this, mm (default :data:`LEAST_TEXT_HEIGHT`).
    """

    def __init__(self, piece: shapely.Polygon, least: float = LEAST_TEXT_HEIGHT):
        self.piece = piece
        self.least = float(least)
        self.boxes = []
        self.labels = []
        self.left_out = []
        """The labels that fit nowhere: each as it asked to be drawn, at its first place and the least height."""
        self._prepared = None

    def _inside(self, box: shapely.Polygon, margin: float) -> bool:
        """``box`` lies inside the piece at least ``margin`` mm from its edges and holes: the box grown by the
        margin inside the piece (the same as the box inside the piece shrunk by it, but the piece is never
        buffered: that took 4 s a size on a plate with 5,000 holes)."""
        if self._prepared is None:
            self._prepared = shapely.from_wkb(shapely.to_wkb(self.piece))  # a copy of our own to prepare
            shapely.prepare(self._prepared)
        return bool(self._prepared.contains(box.buffer(margin)))

    def place(self, text: str, places, height: float, angle=0.0, *, kind: str = "title", of: int = -1,
              shift: float = 0.0, note: bool = True) -> Label | None:
        """Put ``text`` at the first of ``places`` ((k, 2) mm, in order of preference) where it fits,
        at ``height`` or smaller down to the least height; None (and noted in :attr:`left_out`) when it fits
        nowhere (``note``).  ``angle`` (degrees) may be a sequence of angles, tried in turn, each at every size."""
        block = self.place_block([(text, 0.0, 1.0)], places, height, angle, kind=kind, of=of, shift=shift, note=note)
        return block[0] if block else None

    def place_block(self, lines, places, height: float, angle=0.0, *, kind: str = "title", of: int = -1,
                    shift: float = 0.0, note: bool = True) -> list:
        """Place lines of text together: ``lines`` are ``(text, offset, size)``, the offset of each line's
        middle across the block and its cap height, both in units of ``height``; the block is tried at
        ``places`` ((k, 2) mm), shrunk as a whole down to where its smallest line is at the least height,
        at each of ``angle`` in turn (degrees: one or a sequence).  ``shift`` moves each line along itself
        by that many half widths (1: the line starts at its place).  Returns the placed :class:`Label`
        list, empty when the block fits nowhere (its lines then noted in :attr:`left_out`, if ``note``)."""
        places = np.asarray(places, dtype=np.float64).reshape(-1, 2)
        angles = [float(a) for a in np.atleast_1d(angle)]
        floor = self.least / min(size for _, _, size in lines)
        for a in angles:  # level (the first angle) at every size down to the least, then turned
            r = np.radians(a)
            along_dir, across = np.array([np.cos(r), np.sin(r)]), np.array([-np.sin(r), np.cos(r)])
            for h in _heights(height, floor):
                for at in places:
                    centres = [at + off * h * across + shift * 0.55 * text_width(t, size * h) * along_dir
                               for t, off, size in lines]  # shift: half the box's (10 % widened) width
                    boxes = [text_box(t, c, size * h, a) for (t, _, size), c in zip(lines, centres)]
                    if all(self._inside(b, 0.25 * h) for b in boxes) and not any(
                            b.intersects(c) for b in boxes for c in self.boxes):
                        self.boxes.extend(boxes)
                        placed = [Label(t, c, size * h, a, kind, of) for (t, _, size), c in zip(lines, centres)]
                        self.labels.extend(placed)
                        return placed
        if not note:
            return []
        first = places[0] if len(places) else np.zeros(2)
        self.left_out.extend(Label(t, first, max(size * floor, self.least), angles[0], kind, of)
                             for t, _, size in lines)
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


def bend_details(bend: BendLine, unit: Unit = Unit.MM) -> str:
    """The second line of a blank's bend label: its allowance (the developed width of its zone) and its
    length, in the drawing's unit (``BA 4.20 L 30.00 MM``), as the bend sheet gives them; empty for a ruling.

    Two decimals in mm, four in the larger units, as :func:`seam_text`.
    """
    if not bend.direction or bend.allowance is None:
        return ""
    digits = 2 if unit is Unit.MM else 4
    length = float(np.linalg.norm(np.subtract(*bend.line)))
    return f"BA {bend.allowance / unit.mm:.{digits}f} L {length / unit.mm:.{digits}f} {unit.label}"


def _long_axis(polygon: shapely.Polygon) -> float:
    """The readable angle (degrees) of the longer side of the polygon's smallest turned rectangle."""
    ring = np.asarray(shapely.minimum_rotated_rectangle(polygon).exterior.coords)
    if len(ring) < 4:
        return 0.0
    sides = np.diff(ring[:3], axis=0)
    return readable_angle(max(sides, key=lambda d: float(np.hypot(*d))))


def _placer(piece: Piece, unit: Unit, block) -> LabelPlacer:
    """Every label of a piece placed (:func:`piece_labels`), with those that fit nowhere: the title block
    first, or last when that leaves fewer labels out (a title as wide as a narrow piece bars the labels of
    its long seams)."""
    first = _place_all(piece, unit, block, title_first=True)
    if not first.left_out:
        return first
    last = _place_all(piece, unit, block, title_first=False)
    return last if len(last.left_out) < len(first.left_out) else first


def _title(placer: LabelPlacer, piece: Piece, block, angles) -> None:
    """The title block; where it fits nowhere, its first line (the piece's name) alone, the rest left out."""
    places = placer.inside_places(piece.label_at, piece.text_height)
    if placer.place_block(block, places, piece.text_height, angles, note=len(block) == 1) or len(block) == 1:
        return
    text, _, size = block[0]
    placer.place_block([(text, 0.0, size)], places, piece.text_height, angles)
    placer.left_out.extend(Label(t, places[0], max(size_ * piece.text_height, placer.least), 0.0)
                           for t, _, size_ in block[1:])


def _place_all(piece: Piece, unit: Unit, block, *, title_first: bool) -> LabelPlacer:
    placer = LabelPlacer(piece.finished, least_height(piece.text_height))
    th = piece.text_height
    if block is None:
        block = [(piece.name, 0.8, 1.2)] + [(line, -0.9, 0.7) for line in piece.title[:1]]
    turned = _long_axis(piece.finished)
    angles = (0.0,) if abs(turned) < 1e-6 else (0.0, turned)  # a narrow piece: along its length when need be
    if title_first:
        _title(placer, piece, block, angles)
    for k, side in enumerate(piece.seams):
        text = seam_text(side, unit)
        h = max(0.6 * th, placer.least)
        tries = along(side.points, 1.6 * h)
        if not any(placer.place(text, [place], h, readable_angle(tangent), kind="seam", of=k, note=False)
                   for place, tangent in tries):
            placer.left_out.append(Label(text, tries[0][0], h, readable_angle(tries[0][1]), "seam", k))
    for k, bend in enumerate(piece.bends):
        a, b = bend.line
        length = float(np.linalg.norm(b - a))
        direction = (b - a) / max(length, 1e-12)
        h = max(0.5 * th, placer.least)
        places = [b - direction * f * length for f in (0.1, 0.3, 0.5, 0.7, 0.9)]
        details = bend_details(bend, unit)
        # the label and its allowance and length, one line either side of the bend line; else the label alone
        if details and placer.place_block([(bend.label, 0.7, 1.0), (details, -0.7, 1.0)], places, h,
                                          readable_angle(direction), kind="bend", of=k, note=False):
            continue
        if placer.place(bend.label, places, h, readable_angle(direction), kind="bend", of=k, note=False):
            if details:
                placer.left_out.append(Label(details, 0.5 * (a + b), h, readable_angle(direction), "bend", k))
            continue
        # too long for its line (a narrow blank): across it, beside its middle, on either side
        normal = np.array([-direction[1], direction[0]])
        for side in (normal, -normal):
            angle = readable_angle(side)
            shift = 1.0 if np.array([np.cos(np.radians(angle)), np.sin(np.radians(angle))]) @ side > 0 else -1.0
            beside = [p + side * 0.5 * h for p in places[2:0:-1] + places[3:4]]
            if details and placer.place_block([(bend.label, 0.7, 1.0), (details, -0.7, 1.0)], beside, h, angle,
                                              kind="bend", of=k, shift=shift, note=False):
                break
            if placer.place(bend.label, beside, h, angle, kind="bend", of=k, shift=shift, note=False):
                if details:
                    placer.left_out.append(Label(details, 0.5 * (a + b), h, readable_angle(direction), "bend", k))
                break
        else:
            placer.left_out.append(Label(bend.label, 0.5 * (a + b), h, readable_angle(direction), "bend", k))
    if not title_first:
        _title(placer, piece, block, angles)
        placer.labels.sort(key=lambda label: label.kind != "title")  # the title block first, as always
    return placer


def place_labels(piece: Piece, unit: Unit = Unit.MM) -> Labels:
    """Every label of a piece placed clear of the others inside the finished piece (mm), none below the least
    height (:func:`least_height`), and those that fit nowhere: what ``Piece.labels`` keeps.

    The title block (the piece's name at 1.2 text heights and the first line of its title at 0.7; level, or
    along a narrow piece's length where it fits only so), then one label per seam side (``"seam"``, 0.6 text
    heights, along the seam and 1.6 label heights inside it, its middle first, its lengths in ``unit``), then
    one per bend line (``"bend"``, half a text height, centred on the line, or across it beside its middle
    when the line is too short; a blank's bends numbered in the bending order).
    """
    placer = _placer(piece, Unit(unit), None)
    return Labels(tuple(placer.labels), tuple(placer.left_out), placer.least, Unit(unit).value)


def labels_of(piece: Piece, unit: Unit | str | None = None) -> Labels:
    """The piece's labels for ``unit``: those it keeps (``Piece.labels``) when they are for that unit (or
    ``unit`` is None), else placed now (a piece made without, or a writer in another unit)."""
    kept = piece.labels
    if kept is not None and (unit is None or kept.unit == Unit(unit).value):
        return kept
    return place_labels(piece, Unit.MM if unit is None else Unit(unit))


def with_labels(piece: Piece, unit: Unit | str = Unit.MM) -> Piece:
    """The piece with its labels for ``unit`` placed and kept (itself when it has them)."""
    if piece.labels is not None and piece.labels.unit == Unit(unit).value:
        return piece
    return replace(piece, labels=place_labels(piece, Unit(unit)))


def piece_labels(piece: Piece, unit: Unit | str | None = None, *, block=None) -> list:
    """Every label of a piece as a writer in ``unit`` draws it (places in mm): those the piece keeps
    (:func:`labels_of`; ``unit`` None: in the unit it was labelled for).

    Parameters
    ----------
    piece : Piece
    unit : patterns.Unit or str, optional
        The drawing's unit (the seam labels say it).
    block : list of (str, float, float), optional
        Another title block (ASTM's annotation lines), as :meth:`LabelPlacer.place_block` takes it: placed
        clear of the piece's other labels, instead of its own title.

    Returns
    -------
    list of Label
        The title block (kind ``"title"``), then the seam labels (``"seam"``), then the bend labels
        (``"bend"``); those that fit nowhere are left out (:func:`label_findings`).
    """
    kept = labels_of(piece, unit)
    if block is None:
        return list(kept.placed)
    placer = LabelPlacer(piece.finished, kept.least)
    others = [label for label in kept.placed if label.kind != "title"]
    placer.boxes = [text_box(label.text, label.at, label.height, label.angle) for label in others]
    turned = _long_axis(piece.finished)
    _title(placer, piece, block, (0.0,) if abs(turned) < 1e-6 else (0.0, turned))
    return placer.labels + others
def label_findings(piece: Piece) -> tuple:
    """One ``label-left-out`` note per label of ``piece`` that fits nowhere on it at the least text height
    (the writers leave it out): which label, on which piece, and where it was wanted."""
    kept = labels_of(piece)
    what = f"panel {piece.name}" if piece.source.kind == "panel" else piece.name
    out = []
    for label in kept.left_out:
        out.append(Finding(Code.LABEL_LEFT_OUT, Severity.NOTE, (piece.name,), label.at[None, :], (), None,
                           f"{what}: {label.kind} label {label.text!r} does not fit on the piece at the least text "
                           f"height ({kept.least:g} mm): left out"))
    return tuple(out)
