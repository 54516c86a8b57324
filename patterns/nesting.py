"""Nesting: pieces placed on a roll or on sheets, by sparrow (``spyrrow``).

:func:`layout` takes pieces (:mod:`patterns.pieces`: a pattern's panels, a
blank, or any mix of them) and hands their true cut outlines (the seam
allowance included) to sparrow, the
state-of-the-art heuristic for irregular strip packing (J. Gardeyn and T.
Wauters; ``spyrrow`` is its Python binding), with the gap as the least distance
between two pieces and the grain as the orientations allowed; then checks the
result with shapely on the placed outlines before anything uses it (no overlap,
every gap kept, everything on the roll or sheet).

The roll runs along +Y from y = 0, ``width`` wide (x from 0 to ``width``); a
piece's +Y (its grain line) runs along the roll when the grain is kept.  Pieces
may touch the roll's and the sheets' edges (give a narrower width to keep a
border).  Sheets
lie one after another along the roll's direction, :data:`SHEET_SPACING` apart in
the drawing.

Sparrow fills only its strip: small pieces go into the holes of big ones before
it runs (:func:`patterns.placement.into_holes`).  Sheets may be of several sizes
(the stock on hand, :mod:`patterns.stock`), each sheet of the size that wastes
least.  Sparrow takes simple polygons only (each outline is simplified within 0.05 mm, outwards, so that the
gap still holds on the true outline).  Its search runs for a time budget, so the
marker it stops at depends on how fast the machine ran; every marker found is
kept (:func:`cache_folder`), so that the same pieces and options give the same
marker again -- the promise a cutting room needs -- and a rerun is instant.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import subprocess
import sys
import time
from dataclasses import dataclass, field, replace
from importlib.metadata import version
from pathlib import Path

import numpy as np
import shapely
from shapely import affinity

from .curves import Motion
from .errors import InputError, LayoutError, PatternsError
from .files import atomic_output, child_python
from .options import Options, check_number, label, option
from .pieces import Drawing, Piece, PieceOptions, pieces_of
from .pieces.drawing import place_nest
from .pieces.labels import with_labels
from .placement import FILL, SHEET_SPACING, SNAP, fill_sheets, into_holes, onto_stock, strip_width, with_guests  # noqa: F401 - SNAP: the nest's tolerance, said here too
from .stock import check_sheet, parse_sheet, sheet_sizes

__all__ = ["ROTATIONS", "SHEET_SPACING", "Layout", "LayoutError", "NestOptions", "Sheet", "cache_folder", "layout"]

ROTATIONS = ("grain", "quarter", "free", "none")
"""How pieces may turn: ``grain`` 0 or 180 degrees (the grain stays along the roll), ``quarter``
any multiple of 90, ``free`` any angle, ``none`` not at all."""

_ANGLES = {"grain": [0.0, 180.0], "quarter": [0.0, 90.0, 180.0, 270.0], "free": None, "none": [0.0]}
"""The turns sparrow may make, degrees (None: any)."""

_TRIED = np.arange(0.0, 180.0, 1.0)
"""The turns tried, degrees, when checking that a freely turning piece fits (its extents repeat every 180)."""

SIMPLIFY = 0.05
"""Outlines are offered to sparrow simplified within this, mm (outwards: the gap holds on the true one)."""

MAX_PIECES = 2000
"""The most pieces one nest takes (copies and mirror images counted).  Sparrow's set-up before its timed search
grows with the pieces (measured on the cup's panels, 10 s budget: 1,000 pieces 15 s in all, 2,000 pieces 22 s,
4,000 pieces 38 s and 0.9 GB); 2,000 keeps the whole nest within a minute of the budget."""

SETUP_GRACE = 20.0
"""Seconds sparrow's process may run past its search budget before it is stopped (its start and set-up), plus
:data:`SETUP_PER_PIECE` a piece."""

SETUP_PER_PIECE = 0.1
"""Seconds of set-up allowed a piece past the budget: a stop for a sparrow that hangs, never for one that works
(measured: about 6 ms a piece of the cup on an idle machine, and 2000 pieces needed 51 s on a loaded one, where
0.02 s a piece refused them after 61 s)."""


def _quantities(value, option_name):
    if value is None:
        return None
    try:
        items = dict(value).items()
    except (TypeError, ValueError):
        raise InputError(f"{option_name} must map panel names to counts, e.g. {{'sleeve': 2}}") from None
    return {str(k): check_number(n, f"{option_name}[{k!r}]", low=1, high=MAX_PIECES, integer=True) for k, n in items}


def _parse_quantity(text: str):
    name, sep, count = text.rpartition("=")
    if not sep or not name:
        raise ValueError(f"expected NAME=COUNT, got {text!r}")
    return name, int(count)


@dataclass(frozen=True, repr=False)
class NestOptions(Options):
    """Where and how the pieces are nested (:func:`layout`; ``--roll-width`` or ``--sheet`` on the command line)."""

    width: float | None = option(None, "nest the pieces on a roll this wide, mm", low=0, low_open=True, optional=True,
                                 unit="mm", flag="--roll-width")
    sheet: tuple | None = option(None, "nest the pieces on sheets LENGTH x WIDTH mm, filled one after another "
                                       "(command line: 2500x1250); or on the stock on hand, several sizes, each "
                                       "with how many there are (2500x1250,1200x800:2; API: [(2500, 1250), "
                                       "(1200, 800, 2)]), the last sheet the smallest size that takes every piece left",
                                 check=check_sheet, parse=parse_sheet, optional=True,
                                 metavar="LxW[,LxW:N]")
    gap: float = option(10.0, "least distance between two pieces, mm", low=0, unit="mm", flag="--nest-gap")
    margin: float = option(0.0, "room kept around each piece's cut outline besides the gap, mm (a kerf, a "
                                "cutter's clearance)", low=0, high=1000, unit="mm")
    rotations: str = option("grain", "how pieces may turn: grain (0 or 180 degrees: the grain along the roll), "
                                     "quarter (multiples of 90), free, none", choices=ROTATIONS)
    copies: int = option(1, "pieces of every panel or blank (a part cut this many times; 2000 pieces a nest at "
                            "most)", integer=True, low=1, high=MAX_PIECES, metavar="N")
    mirror: bool = option(False, "each piece also as its mirror image (left and right)")
    quantities: dict | None = option(None, "pieces of named panels or blanks, over copies: NAME=N, repeatable (API: "
                                           "a mapping of names to counts)", check=_quantities, parse=_parse_quantity,
                                     repeat=True, flag="--quantity", metavar="NAME=N")
    time_limit: int = option(10, "seconds the nest takes (sparrow's search, on a roll or all the sheets, plus its "
                                 "set-up); longer may save a little material",
                             integer=True, low=1, high=86400, flag="--nest-time", metavar="S")
    seed: int = option(0, "the search's seed", integer=True, low=0, high=2**32 - 1, flag="--nest-seed",
                       metavar="N")
    cache: bool = option(True, "keep each marker sparrow finds and give the same one again for the same pieces "
                               "and options (sparrow's search is bound by time, so a rerun on a busier machine "
                               "could stop at another); --no-nest-cache searches anew", flag="--no-nest-cache",
                               off="search anew: neither reuse a kept marker nor keep the new one")

    def __post_init__(self):
        super().__post_init__()
        if self.width is not None and self.sheet is not None:
            raise InputError(f"nest on a roll ({label('width')}) or on sheets ({label('sheet')}), not both")
        room = self.gap + 2 * self.margin  # a gap wider than the stock: refused before sparrow sees it
        narrow = min(self.sheet_sizes, key=lambda s: min(s.length, s.width), default=None)
        if self.width is not None and room >= self.width or narrow is not None and room >= min(narrow.length,
                                                                                               narrow.width):
            stock = f"{self.width:g} mm roll" if narrow is None else f"{narrow.length:g} x {narrow.width:g} mm sheet"
            raise InputError(f"{label('gap')} {self.gap:g} mm (and {label('margin')} {self.margin:g} mm each side) is as wide as the "
                             f"{stock}: no two pieces could lie side by side")

    @property
    def sheet_sizes(self) -> tuple:
        """The sheets' sizes as :class:`~patterns.stock.SheetSize` records, in the order given; () on a roll."""
        return sheet_sizes(self.sheet)

    @property
    def active(self) -> bool:
        """True when a roll or a sheet is given (else nothing is nested)."""
        return self.width is not None or self.sheet is not None


@dataclass(frozen=True)
class Sheet:
    """One sheet of a nest on sheets: its pieces and how much of it they use."""

    index: int
    pieces: tuple
    """The names of the pieces on it."""
    area_pieces: float
    """mm^2."""
    area: float
    """The sheet's area, mm^2."""
    size: tuple = ()
    """``(length, width)``, mm."""

    @property
    def usage(self) -> float:
        return self.area_pieces / self.area if self.area > 0 else 0.0


@dataclass(frozen=True, eq=False)
class Layout:
    """Where everything went and what it cost (mm; the roll's corner at the origin, x across it).

    Attributes
    ----------
    name : str
        What was nested.
    pieces : tuple of patterns.pieces.Piece
        Every piece as placed, copies included (each piece's ``placement`` says how it was moved;
        copies are named ``face0 #2``, ``face0 mirrored``).
    stock : tuple of (x0, y0, x1, y1)
        The roll (to the length used) or each sheet, mm.
    width : float
        The roll's (or sheets') width, mm.
    length : float
        Roll length used (the end of the furthest piece), or the sheets' total length, mm.
    area_used : float
        ``width * length``, mm^2 (a nest on sheets: the sheets' area).
    area_panels : float
        The area the pieces take: their cut outlines with the margin, holes counted in (nothing else is
        cut there), mm^2.
    sheets : tuple of Sheet
        Sheet by sheet, for a nest on sheets; empty on a roll.
    seconds : float
        The nest's time: sparrow's searches (or the kept markers read), and checking the result.
    cached : bool
        Every marker came from the marker cache (``NestOptions.cache``): sparrow did not search.
    sources : tuple
        The patterns and blanks nested (their check report follows the pieces into the drawing).
    """

    name: str
    pieces: tuple
    stock: tuple
    width: float
    length: float
    area_used: float
    area_panels: float
    sheets: tuple = ()
    seconds: float = 0.0
    options: NestOptions = field(default_factory=NestOptions)
    sources: tuple = ()
    cached: bool = False

    @property
    def efficiency(self) -> float:
        """Share of the used material that ends up in pieces (0..1)."""
        return self.area_panels / self.area_used if self.area_used > 0 else 0.0

    def __repr__(self) -> str:
        return f"Layout({self.name!r}, {len(self.pieces)} pieces, {self})"

    def to_dict(self) -> dict:
        """What was nested and what it cost, JSON-ready: each piece's name and placement, the stock, the sheets."""
        return {"name": self.name, "width_mm": self.width, "length_mm": round(self.length, 3),
                "area_used_mm2": round(self.area_used, 3), "area_pieces_mm2": round(self.area_panels, 3),
                "efficiency": round(self.efficiency, 6), "seconds": round(self.seconds, 3), "cached": self.cached,
                "stock": [list(map(float, r)) for r in self.stock],
                "sheets": [{"index": s.index, "size_mm": list(s.size), "pieces": list(s.pieces),
                            "usage": round(s.usage, 6)} for s in self.sheets],
                "pieces": [{"name": p.name, "angle_deg": round(float(np.degrees(p.placement.angle)), 6),
                            "dx_mm": round(float(p.placement.dx), 6), "dy_mm": round(float(p.placement.dy), 6),
                            "mirrored": bool(p.placement.mirrored)} for p in self.pieces]}

    def drawing(self) -> Drawing:
        """The nest as a drawing: pieces and stock moved together into the first quadrant (the frame every
        file of it uses), with its summary as the note."""
        pieces, stock = place_nest(self.pieces, self.stock)
        return Drawing(self.name, pieces, stock, str(self))

    def __str__(self) -> str:
        if self.sheets:
            sizes = {s.size: sum(t.size == s.size for t in self.sheets) for s in self.sheets}
            if len(sizes) == 1:
                what = f"{len(self.sheets)} sheet{'s' if len(self.sheets) != 1 else ''} of {self.sheets[0].size[0]:g} x "
                what += f"{self.sheets[0].size[1]:g} mm"
            else:
                what = f"{len(self.sheets)} sheets (" + ", ".join(f"{n} of {a:g} x {b:g} mm"
                                                                   for (a, b), n in sizes.items()) + ")"
            return what + ", usage " + ", ".join(f"{s.usage:.1%}" for s in self.sheets) + \
                f" ({self.efficiency:.1%} in all)"
        return f"a {self.width:g} mm roll: {self.length:.1f} mm used, efficiency {self.efficiency:.1%}"


def _with_copies(pieces: tuple, counts: list, mirror: bool) -> tuple:
    """The pieces, then each one's extra copies (``face0 #2``) and, with ``mirror``, its mirror images (each
    titled with its own name: its labels placed once, here)."""
    extra = []
    for piece, n in zip(pieces, counts):
        unit = "mm" if piece.labels is None else piece.labels.unit
        extra += [with_labels(piece.copy(f"{piece.name} #{k + 1}", k), unit) for k in range(1, n)]
        if mirror:
            extra += [with_labels(piece.copy(f"{piece.name} mirrored" if k == 0 else
                                             f"{piece.name} #{k + 1} mirrored", n + k, mirrored=True), unit)
                      for k in range(n)]
    return tuple(pieces) + tuple(extra)


def layout(source, options: NestOptions | None = None, *, pieces: PieceOptions | None = None,
           unit: str = "mm", **keywords) -> Layout:
    """Nest pieces on a roll or on sheets (sparrow), checked with shapely.

    Parameters
    ----------
    source : patterns.Pattern, patterns.Blank, patterns.pieces.Piece, or a list of them
        What to nest: a pattern's panels, a blank, or any mix (a marker of several parts).
    options : NestOptions, optional
        The options as a record; keywords go over it: ``width`` (a roll, mm)
        or ``sheet`` (``(length, width)`` mm), ``gap`` (least distance between
        pieces, default 10 mm), ``margin`` (room around each cut outline),
        ``rotations`` (``"grain"``: 0 or 180 degrees, the default;
        ``"quarter"``, ``"free"``, ``"none"``), ``copies``, ``mirror``,
        ``quantities`` (``{piece name: count}``), ``time_limit`` (seconds,
        default 10), ``seed``.
    pieces : patterns.pieces.PieceOptions, optional
        What goes onto each piece (the seam allowance is part of its outline); keywords (``seam_allowance``,
        ...) go over it.
    unit : str
        The unit the pieces' seam labels say (the file's: default mm); their labels are placed once, for it,
        and move with them.

    Returns
    -------
    Layout

    Raises
    ------
    InputError
        Bad options, or no roll and no sheet.
    LayoutError
        A piece that fits the roll or sheet in no allowed orientation, or a
        result that fails the shapely check (never returned).
    """
    deadline = time.monotonic() + 0  # set below, once the options are known
    nest_fields = set(NestOptions.__dataclass_fields__)
    items = list(source) if isinstance(source, (list, tuple)) else [source]
    name = " + ".join(dict.fromkeys(str(getattr(item, "name", type(item).__name__)) for item in items))
    opts = NestOptions.of(options, {k: v for k, v in keywords.items() if k in nest_fields}, name=name)
    if not opts.active:
        raise InputError(f"{name}: give a roll width or a sheet to nest on")
    deadline += opts.time_limit
    base = pieces_of(source, pieces, unit=unit, **{k: v for k, v in keywords.items() if k not in nest_fields})
    names = [p.name for p in base]
    counts = [opts.copies] * len(names)
    for piece_name, n in (opts.quantities or {}).items():
        if piece_name not in names:
            raise InputError(f"{name}: quantities name piece {piece_name!r}; the pieces are {', '.join(names)}")
        counts[names.index(piece_name)] = n
    check_piece_count(name, counts, opts)
    sizes = opts.sheet_sizes
    every = _with_copies(base, counts, opts.mirror)
    shapes = [_outline(piece, opts.margin) for piece in every]
    fitting = {}
    for piece, shape in zip(every, shapes):  # a copy fits as its original does: each outline checked once
        if (key := shapely.to_wkb(shape)) not in fitting:
            fitting[key] = _check_fits(name, piece.name, shape, opts.width, sizes, opts.rotations)
    fits = [fitting[shapely.to_wkb(shape)] for shape in shapes]  # per piece, per sheet size: it fits
    across = opts.width if opts.width is not None else max(s.width for s in sizes)
    start = time.perf_counter()
    searched = []  # per marker: True if sparrow searched, False if it came from the cache
    guests = into_holes(every, shapes, opts)  # small pieces in the holes of big ones, before sparrow
    hosts = [i for i in range(len(every)) if i not in guests]
    try:
        placements, sheets, stock = _placed([shapes[i] for i in hosts], [every[i] for i in hosts],
                                            [fits[i] for i in hosts], across, opts, name, deadline, searched=searched)
        placements, sheets = with_guests(placements, sheets, stock, hosts, guests, every)
        laid, placed = _laid(every, placements, stock, opts.margin)
        _verify(name, laid, placed, across, opts, stock)
    except LayoutError:
        if not opts.cache:
            raise
        # a kept marker that fails the check (edited, or from a broken run): searched anew, and kept again
        placements, sheets, stock = _placed([shapes[i] for i in hosts], [every[i] for i in hosts],
                                            [fits[i] for i in hosts], across, opts, name, deadline, refresh=True,
                                            searched=searched)
        placements, sheets = with_guests(placements, sheets, stock, hosts, guests, every)
        laid, placed = _laid(every, placements, stock, opts.margin)
        _verify(name, laid, placed, across, opts, stock)
    seconds = time.perf_counter() - start
    area_pieces = float(sum(p.area for p in placed))
    if sheets:
        length = float(sum(s.size[0] for s in sheets))
        used = float(sum(s.area for s in sheets))
        across = max(s.size[1] for s in sheets)
        rects = tuple(stock)
    else:
        length = max(float(np.max(np.asarray(p.exterior.coords)[:, 1])) for p in placed)
        used = across * length
        rects = ((0.0, 0.0, across, length),)
    sources = tuple(item for item in items if not isinstance(item, Piece))
    return Layout(name, laid, rects, float(across), float(length), float(used), area_pieces, tuple(sheets), seconds,
                  opts, sources, cached=bool(searched) and not any(searched))


def check_piece_count(name: str, counts, opts: NestOptions) -> int:
    """The number of pieces a nest of ``counts`` (per piece, copies included) takes, mirror images counted;
    InputError past :data:`MAX_PIECES` (before any work: the command line checks it once the part is read)."""
    total = int(sum(counts)) * (2 if opts.mirror else 1)
    if total > MAX_PIECES:
        raise InputError(f"{name}: {total} pieces to nest, over the limit of {MAX_PIECES} in one nest (sparrow's "
                         f"set-up alone grows with them); nest fewer copies at a time")
    return total


def _left(deadline: float) -> int:
    """Whole seconds left to ``deadline`` (time.monotonic), at least 1 (sparrow's least budget)."""
    return max(1, int(deadline - time.monotonic()))


def _placed(shapes, pieces, fits, across, opts, name, deadline, *, refresh=False, searched=None):
    """``(placements, sheets, stock)``: sparrow's placements on the roll, or sheet after sheet
    (:func:`patterns.placement.fill_sheets`); ``searched`` gets a bool per marker (True: sparrow searched; False:
    a kept one)."""
    if opts.sheet is None:
        placements = _solve(shapes, list(range(len(shapes))), across, opts, name, seconds=_left(deadline),
                            refresh=refresh, searched=searched)
        return placements, (), [(0.0, 0.0, across, None)]
    trial = replace(opts, time_limit=max(1, opts.time_limit // 5))  # another key: the short searches of one sheet

    def solve(which, size, seconds, short=False):
        return _solve(shapes, which, size.width, trial if short else opts, name, seconds=seconds, refresh=refresh,
                      searched=searched, along=size.length)

    placements, sheets, stock = fill_sheets(shapes, fits, opts.sheet_sizes, solve, deadline, name=name)
    return placements, [Sheet(k, tuple(pieces[i].name for i in on), area, size.area, (size.length, size.width))
                        for k, (on, area, size) in enumerate(sheets)], stock


def _outline(piece: Piece, margin: float):
    """The piece's cut outline as placed (holes not offered as room), grown by the margin."""
    outline = piece.outline.polygon
    return outline.buffer(margin, join_style="mitre") if margin else outline


def _material(piece: Piece, margin: float):
    """The piece's material as placed: its cut outline less its holes, grown by the margin."""
    shape = shapely.Polygon(piece.outline.points(), [h.points() for h in piece.holes])
    return shape.buffer(margin, join_style="mitre") if margin else shape


def _item_points(shape) -> np.ndarray:
    """The outline offered to sparrow: grown and simplified within SIMPLIFY, in its frame (x along the
    strip = the piece's +Y, y across = its -X)."""
    simple = shapely.simplify(shape.buffer(SIMPLIFY, join_style="mitre"), SIMPLIFY)  # a polygon: kept valid
    pts = np.asarray(simple.exterior.coords)[:-1]
    return np.column_stack([pts[:, 1], -pts[:, 0]])


def _extents(shape, rotations: str) -> np.ndarray:
    """``(k, 2)`` float64, mm: the piece's width across the strip and length along it, turned by each of
    the turns allowed (for free turns, every degree)."""
    angles = _TRIED if _ANGLES[rotations] is None else _ANGLES[rotations]
    boxes = np.array([affinity.rotate(shape, a).bounds for a in angles])
    return boxes[:, 2:] - boxes[:, :2]


def _check_fits(name, piece, shape, width, sizes, rotations) -> tuple:
    """Per sheet size, whether the piece fits on it in an allowed orientation (``()`` on a roll of ``width``);
    LayoutError where it fits on no roll or sheet."""
    extents = _extents(shape, rotations)
    least = float(extents[:, 0].min())
    if width is not None:
        if least > width + 1e-9:
            raise LayoutError(f"{name}: piece {piece} is {least:.1f} mm wide, wider than the {width:g} mm roll in every "
                              f"allowed orientation (rotations={rotations!r})")
        return ()
    fits = tuple(bool(np.any((extents[:, 0] <= s.width + 1e-9) & (extents[:, 1] <= s.length + 1e-9))) for s in sizes)
    if not any(fits):
        widest = max(s.width for s in sizes)
        what = (f"a {sizes[0].length:g} x {sizes[0].width:g} mm sheet" if len(sizes) == 1
                else "any of the sheets (" + ", ".join(f"{s.length:g} x {s.width:g}" for s in sizes) + " mm)")
        if least > widest + 1e-9:
            than = f"the {what[2:]}" if len(sizes) == 1 else f"every sheet ({', '.join(str(s) for s in sizes)})"
            raise LayoutError(f"{name}: piece {piece} is {least:.1f} mm wide, wider than {than} in every allowed "
                              f"orientation (rotations={rotations!r})")
        raise LayoutError(f"{name}: piece {piece} does not fit on {what} in any allowed orientation "
                          f"(rotations={rotations!r})")
    return fits


def _tolerance(across: float) -> float:
    """How far (mm) a placed outline may stray past the stock's edges, or under the gap: a millionth of the
    roll's width (sparrow computes in single precision)."""
    return 1e-6 * max(float(across), 1.0)


def _solve(shapes, which, across, opts, name, *, seconds: int | None = None, refresh: bool = False,
           searched: list | None = None, along: float | None = None) -> dict:
    """Sparrow on the pieces ``which``: ``{piece: (angle rad, dx, dy)}`` on a roll ``across`` wide, searching
    ``seconds`` (at most ``opts.time_limit``, the marker's key); ``refresh`` searches anew over a kept marker;
    ``searched`` (a list) gets True if sparrow searched, False if the marker was a kept one."""
    points = [_item_points(shapes[i]) for i in which]
    across = strip_width([shapes[i] for i in which], across, along)
    # sparrow keeps every item the separation away from the strip's edges too, and each item it sees is
    # the outline grown by SIMPLIFY: a strip wider by both on either side, and everything moved back by
    # them, lets the true outlines touch the roll's edges (as a cutter may) -- a piece as wide as the roll
    # fits.
    # And sparrow (single precision) needs a hair to spare: the strip is wider by _verify's tolerance,
    # half of it either side.
    edge, slack = float(opts.gap) + SIMPLIFY, _tolerance(across)
    task = {"items": [np.round(p, 9).tolist() for p in points], "strip": float(across) + 2 * edge + slack,
            "orientations": _ANGLES[opts.rotations], "gap": float(opts.gap), "time": int(opts.time_limit),
            "seed": int(opts.seed)}
    placed = _remembered(task) if opts.cache and not refresh else None
    if searched is not None:
        searched.append(placed is None)
    if placed is None:
        placed = _sparrow(task, name, seconds=min(int(opts.time_limit), seconds or int(opts.time_limit)))
        if opts.cache:
            _remember(task, placed)
    out = {}
    for k, (rotation, tx, ty) in enumerate(placed):
        theta = np.radians(rotation) % (2 * np.pi)  # in [0, 2 pi): sparrow says -180 for 180
        # sparrow's frame (x along, y across) is the piece's turned by -90 degrees; ours is sparrow's
        # turned back by +90 and moved across by the roll's width: a turn of theta, then a move.
        out[which[k]] = (float(theta), float(across + edge + slack / 2 - ty), float(tx - edge))
    return out


CHILD = Path(__file__).with_name("sparrow_child.py")
"""The script sparrow runs in (:mod:`patterns.sparrow_child`)."""


def _python() -> str:
    """A Python to run :data:`CHILD` with (:func:`patterns.files.child_python`)."""
    found = child_python()
    if found is None:
        raise LayoutError(f"no python{sys.version_info.major}.{sys.version_info.minor} on PATH to run sparrow in")
    return found


def _sparrow(task: dict, name: str, *, seconds: int | None = None) -> list:
    """``[(rotation deg, tx, ty)]`` per item: sparrow's answer to ``task``, searched ``seconds`` (default the
    task's time) in a process of its own, stopped past the search and its set-up
    (:data:`SETUP_GRACE`), and on any signal this process gets; LayoutError (naming ``name``) when sparrow gives
    up, panics (its message in one line, its backtrace kept off the console) or overruns."""
    import importlib.util

    seconds = int(task["time"] if seconds is None else seconds)
    spec = importlib.util.find_spec("spyrrow")
    if spec is None or spec.origin is None:
        raise LayoutError(f"{name}: sparrow (the spyrrow package) is not installed")
    where = str(Path(spec.origin).parent.parent)
    env = dict(os.environ, RUST_BACKTRACE="0",
               PYTHONPATH=os.pathsep.join(p for p in (where, os.environ.get("PYTHONPATH")) if p))
    limit = seconds + SETUP_GRACE + SETUP_PER_PIECE * len(task["items"])
    proc = subprocess.Popen([_python(), "-P", str(CHILD)], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, env=env, start_new_session=True)  # Ctrl-C reaches us alone
    try:
        out, err = proc.communicate(json.dumps({**task, "time": seconds}).encode(), timeout=limit)
    except subprocess.TimeoutExpired:
        raise LayoutError(f"{name}: sparrow did not end within {limit:.0f} s (this search's {seconds} s of the "
                          f"nest's {task['time']} s budget, and the set-up of {len(task['items'])} pieces): stopped; "
                          f"nest fewer pieces at a time") from None
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    try:
        answer = json.loads(out)
    except ValueError:
        said = [line for line in err.decode(errors="replace").splitlines() if line.strip()]
        why = (f"killed by signal {-proc.returncode}" if proc.returncode < 0
               else said[-1].strip()[:300] if said else f"exit {proc.returncode}")
        raise LayoutError(f"{name}: sparrow stopped ({why})") from None
    if "error" in answer:
        raise LayoutError(f"{name}: sparrow could not nest the pieces ({answer['error'][:300]})")
    placed = answer["placed"]
    if len(placed) != len(task["items"]) or any(p is None for p in placed):
        raise LayoutError(f"{name}: sparrow placed {sum(p is not None for p in placed)} of {len(task['items'])} "
                          f"pieces")
    return [tuple(p) for p in placed]


def cache_folder() -> Path:
    """Where markers are kept: ``$PATTERNS_CACHE``, else ``$XDG_CACHE_HOME/patterns/markers``, else
    ``~/.cache/patterns/markers``."""
    if os.environ.get("PATTERNS_CACHE"):
        return Path(os.environ["PATTERNS_CACHE"])
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "patterns" / "markers"


def _key(task: dict) -> str:
    text = json.dumps({**task, "spyrrow": version("spyrrow")}, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()


def _remembered(task: dict):
    """The kept marker of ``task``, or None: none kept, or one that is not a marker of it (cut short,
    edited: a count, a number that is not finite, a turn not allowed), which the search then replaces."""
    try:
        data = json.loads((cache_folder() / f"{_key(task)}.json").read_text())
        rows = [tuple(map(float, row)) for row in data]
    except (OSError, ValueError, TypeError):
        return None
    if len(rows) != len(task["items"]) or any(len(r) != 3 or not all(map(math.isfinite, r)) for r in rows):
        return None
    turns = task["orientations"]
    if turns is not None and any(min(abs((r[0] - a + 180) % 360 - 180) for a in turns) > 1e-3 for r in rows):
        return None
    return rows


def _remember(task: dict, placed: list) -> None:
    """Keep sparrow's answer (a cache: when it cannot be written, nothing is lost but the next search's time)."""
    folder = cache_folder()
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with atomic_output(folder / f"{_key(task)}.json", what="marker cache") as tmp:
            tmp.write_text(json.dumps(placed))
    except (OSError, PatternsError):
        pass


def _laid(every, placements, stock, margin: float) -> tuple:
    """``(pieces moved, their outlines with the margin)``: each piece where sparrow put it, moved back onto its
    roll or sheet where sparrow left it past an edge by no more than :data:`SNAP` (its float noise)."""
    rects = [(x0, y0, x1, np.inf if y1 is None else y1) for x0, y0, x1, y1 in stock]
    laid, placed = [], []
    for i, piece in enumerate(every):
        moved = piece.moved(Motion(*placements[i]))
        shape = _outline(moved, margin)
        shift = onto_stock(shape.bounds, rects)
        if shift != (0.0, 0.0):
            moved = moved.moved(Motion(0.0, *shift))
            shape = _outline(moved, margin)
        laid.append(moved)
        placed.append(shape)
    return tuple(laid), placed


def _verify(name, laid, placed, across, opts, stock) -> None:
    """Raise LayoutError unless every gap holds, no two pieces overlap, and all lie on the stock."""
    tol = _tolerance(across)
    material = [_material(piece, opts.margin) for piece in laid]  # a piece's holes are room for others
    tree = shapely.STRtree(material)
    left, right = tree.query(material, predicate="dwithin", distance=max(opts.gap - tol, 0.0))
    for a, b in zip(left, right):
        if a < b and (opts.gap > 0 or material[a].intersection(material[b]).area > tol):
            d = material[a].distance(material[b])
            raise LayoutError(f"{name}: pieces {laid[a].name} and {laid[b].name} lie {d:.3f} mm "
                              f"apart, under the {opts.gap:g} mm gap (the nest is refused, not written)")
    rects = [shapely.box(x0, y0, x1, y1 if y1 is not None else 1e12) for x0, y0, x1, y1 in stock]
    room = shapely.union_all(rects).buffer(tol)
    for piece, shape in zip(laid, placed):
        if not room.contains(shape):
            raise LayoutError(f"{name}: piece {piece.name} lies off the roll or sheet (the nest is refused)")
