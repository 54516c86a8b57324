"""Where pieces go besides sparrow's strip: into the holes of bigger pieces, onto the stock past sparrow's
round-off, and the strip's width sparrow is given (:func:`patterns.layout` calls these).
"""

from __future__ import annotations

import math
import time
from dataclasses import replace

import numpy as np
import shapely
from shapely import affinity

from .curves import Motion
from .errors import LayoutError

__all__ = ["FILL", "SHEET_SPACING", "SNAP", "ends", "fill_sheets", "into_holes", "onto_stock", "strip_width", "with_guests"]

SNAP = 0.01
"""mm: a piece sparrow leaves past its roll's or sheet's edge by at most this -- its single-precision noise,
measured up to 2.1 µm on a 300 mm sheet -- is moved back onto it by that much before the check (the gap
between pieces has 2 x :data:`patterns.nesting.SIMPLIFY` to spare, more than the move): the nester's own
round-off never costs a nest."""

SHEET_SPACING = 100.0
"""Between two sheets in the drawing, mm."""

FILL = 0.75
"""The share of a sheet pieces are expected to take, for sharing the nest's time among the sheets to come."""


def strip_width(shapes, across: float, along: float | None) -> float:
    """The width of strip sparrow is given: the roll's or sheet's, or less where the pieces are far smaller than it
    -- twice the largest piece's extent or twice the side of a square of their area, and (on a sheet of length
    ``along``) wide enough to hold their area at :data:`FILL` within its length.  Sparrow's first strip is
    their area over the width: on a 3000 mm sheet one 40 x 98 mm blank made it 1.3 mm long, and sparrow
    stopped ("Offset resulted in an empty polygon"); any placement on the narrower strip lies on the stock."""
    area = float(sum(s.area for s in shapes))
    extent = max((max(b[2] - b[0], b[3] - b[1]) for b in (s.bounds for s in shapes)), default=0.0)
    need = max(2.0 * extent, 2.0 * math.sqrt(area))
    if along is not None:
        need = max(need, 1.5 * area / (FILL * along))
    return float(min(across, need))


_HOLE_GRID = 24
"""Places tried across and along a hole, for each turn, when a small piece is put into it."""


def into_holes(every, shapes, opts) -> dict:
    """Pieces nested into the holes and cut-outs of bigger ones before the rest go to sparrow (which fills only
    the strip): ``{guest: (host, (angle rad, dx, dy))}``, the guest's move into its host's frame.  Greedy: the
    biggest pieces first, each into the first hole (biggest first) where it fits at a turn allowed, bottom-left
    first, ``gap`` (and the margins) from the hole's cut edge and from the pieces already in it.  A piece that
    holds others stays a host."""
    rooms = []  # [host, the room in its hole, the guests' outlines there]
    for h, piece in enumerate(every):
        for hole in piece.holes:
            room = shapely.Polygon(hole.points()).buffer(-(opts.gap + opts.margin), join_style="mitre")
            if not room.is_empty and room.area > 0:
                rooms.append([h, room, []])
    if not rooms:
        return {}
    rooms.sort(key=lambda r: -r[1].area)
    turns = {"grain": [0.0, 180.0], "quarter": [0.0, 90.0, 180.0, 270.0], "free": [0.0, 90.0, 180.0, 270.0],
             "none": [0.0]}[opts.rotations]
    guests: dict = {}
    holding = set()
    for g in sorted(range(len(every)), key=lambda i: (-shapes[i].area, i)):
        if g in holding:
            continue
        for room in rooms:
            host, space, taken = room
            if host == g or host in guests or shapes[g].area >= space.area:
                continue
            spot = _spot(shapes[g], space, taken, turns, opts.gap)
            if spot is not None:
                guests[g] = (host, spot)
                holding.add(host)
                taken.append(affinity.translate(affinity.rotate(shapes[g], spot[0], origin=(0, 0), use_radians=True),
                                                spot[1], spot[2]))
                break
    return guests


def _spot(shape, space, taken, turns, gap: float):
    """``(angle rad, dx, dy)`` that puts ``shape`` inside ``space`` and ``gap`` from every one of ``taken``, the
    lowest then leftmost of a grid of places at each turn; None where none does."""
    x0, y0, x1, y1 = space.bounds
    for turn in turns:
        turned = affinity.rotate(shape, turn, origin=(0, 0))
        a0, b0, a1, b1 = turned.bounds
        if a1 - a0 > x1 - x0 or b1 - b0 > y1 - y0:
            continue
        for dy in np.linspace(y0 - b0, y1 - b1, _HOLE_GRID):
            for dx in np.linspace(x0 - a0, x1 - a1, _HOLE_GRID):
                placed = affinity.translate(turned, dx, dy)
                if space.contains(placed) and all(placed.distance(t) >= gap for t in taken):
                    return (float(np.radians(turn)), float(dx), float(dy))
    return None


def with_guests(placements: dict, sheets: list, stock: list, hosts: list, guests: dict, every) -> tuple:
    """The hosts' placements (keyed by their place in ``hosts``) for every piece, each guest moved with its host;
    each sheet with the guests on it (on the sheet that holds their host's middle)."""
    out = {hosts[k]: p for k, p in placements.items()}
    for g, (h, (angle, dx, dy)) in guests.items():
        moved = Motion(*out[h]) @ Motion(angle, dx, dy)
        out[g] = (moved.angle, moved.dx, moved.dy)
    sheets = list(sheets)
    for g, (h, _) in sorted(guests.items()):
        x0, y0, x1, y1 = every[h].moved(Motion(*out[h])).bounds
        for k, (a0, b0, a1, b1) in enumerate(stock):
            if k < len(sheets) and a0 <= (x0 + x1) / 2 <= a1 and b0 <= (y0 + y1) / 2 <= (np.inf if b1 is None else b1):
                sheets[k] = replace(sheets[k], pieces=sheets[k].pieces + (every[g].name,),
                                    area_pieces=sheets[k].area_pieces + float(every[g].outline.polygon.area))
                break
    return out, sheets


def onto_stock(bounds, rects) -> tuple:
    """``(dx, dy)`` mm that moves an outline whose ``bounds`` are ``(x0, y0, x1, y1)`` back inside the rectangle
    of ``rects`` (``(x0, y0, x1, y1)`` each) that holds its middle, when it lies past that rectangle's edges by
    no more than :data:`SNAP`; ``(0, 0)`` when it lies inside, lies farther off (the check then refuses the
    nest), or on no rectangle."""
    x0, y0, x1, y1 = bounds
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    for a0, b0, a1, b1 in rects:
        if a0 <= cx <= a1 and b0 <= cy <= b1:
            low = (a0 - x0, b0 - y0)  # > 0: past the low edge by that much
            high = (x1 - a1, y1 - b1)
            worst = max(*low, *high)
            if 0.0 < worst <= SNAP:
                return (max(low[0], 0.0) - max(high[0], 0.0), max(low[1], 0.0) - max(high[1], 0.0))
            return (0.0, 0.0)
    return (0.0, 0.0)


def ends(shapes, found) -> dict:
    """How far along the strip each placed piece reaches, mm."""
    return {i: affinity.translate(affinity.rotate(shapes[i], angle, origin=(0, 0), use_radians=True), dx, dy).bounds[3]
            for i, (angle, dx, dy) in found.items()}


def fill_sheets(shapes, fits, sizes, solve, deadline: float, *, name: str) -> tuple:
    """Sheet after sheet, the last one the smallest size on hand that takes what is left: ``(placements, sheets, stock)``.

    For each sheet, the pieces left are nested on a strip as wide as each size still on hand (``solve(which, size,
    seconds, short=False)``: sparrow), those lying wholly within its length kept.  The sheet is of the smallest
    size that takes every piece left (the last sheet: its waste is the nest's, and it is made least), else of
    the size that takes the most of the pieces' area (the fewest sheets); a tie goes to the size given first.
    (Measured on the 36-piece marker: choosing the best-used size before the last took four sheets where one
    size takes two -- the small sheet takes the pieces that pack well and leaves the awkward ones.)  Then each piece
    left over, largest first, is tried on that sheet too (a short search of the sheet's pieces and it, kept if
    all fit), until the sheet's time is spent; the rest go on to the next sheet.  The time left to ``deadline``
    (time.monotonic) is shared among the sheets the pieces left are expected to fill (at :data:`FILL` of the
    largest size), and a sheet's first searches among the sizes tried; each search gets at least a second.

    ``fits[i][k]`` says piece ``i`` fits on size ``k`` (:class:`patterns.stock.SheetSize`) in an allowed turn.
    ``sheets`` is ``[(pieces on it, their area, size)]``; ``stock`` the sheets' rectangles ``(x0, y0, x1, y1)``,
    one after another along y, :data:`SHEET_SPACING` apart.  LayoutError (naming ``name``)
    when the sheets on hand run out with pieces left.
    """
    left = list(range(len(shapes)))
    on_hand = [s.count for s in sizes]  # None: as many as needed
    if None not in on_hand and sum(s.area * s.count for s in sizes) < sum(s.area for s in shapes):
        raise LayoutError(f"{name}: the sheets on hand ({', '.join(str(s) for s in sizes)}) are smaller in all than "
                          f"the pieces; give more sheets, or a size without a count (bought as needed)")
    placements, sheets, stock = {}, [], []
    offset = 0.0
    while left:
        start = time.monotonic()
        usable = [k for k in range(len(sizes)) if on_hand[k] != 0 and any(fits[i][k] for i in left)]
        if not usable:
            raise LayoutError(f"{name}: the sheets on hand ({', '.join(str(s) for s in sizes)}) run out with "
                              f"{len(left)} piece{'s' if len(left) != 1 else ''} left to nest; give more sheets, "
                              f"or a size without a count (bought as needed)")
        largest = max(sizes[k].area for k in usable)
        expected = max(1, math.ceil(sum(shapes[i].area for i in left) / (FILL * largest)))
        share = max(1.0, (deadline - start) / expected)
        best = None
        for k in usable:
            size = sizes[k]
            which = [i for i in left if fits[i][k]]
            found = solve(which, size, max(1, int(share / 2 / len(usable))))
            reach = ends(shapes, found)
            on_sheet = [i for i in which if reach[i] <= size.length + 1e-9]
            if not on_sheet:  # the nearest piece alone, from the start of the sheet
                i = min(which, key=lambda j: found[j][2])
                found = solve([i], size, 1, short=True)
                on_sheet = [i]
            placed = sum(shapes[i].area for i in on_sheet)
            # the last sheet (it takes every piece left): the smallest such; else the one that takes most (the
            # fewest sheets: a small sheet before the last takes the pieces that pack well and leaves the
            # awkward ones to sheets of their own); a tie: the size given first
            rank = (len(on_sheet) == len(left), -size.area if len(on_sheet) == len(left) else placed)
            if best is None or rank[0] > best[0][0] or rank[0] == best[0][0] and rank[1] > best[0][1] + 1e-9 * abs(
                    best[0][1]):
                best = (rank, k, on_sheet, {i: found[i] for i in on_sheet})
        _, k, on_sheet, found = best
        size = sizes[k]
        for i in sorted((j for j in left if j not in on_sheet and fits[j][k]), key=lambda j: (-shapes[j].area, j)):
            if time.monotonic() - start + 1 > share:
                break
            attempt = solve(on_sheet + [i], size, max(1, int(share / 10)), short=True)
            if max(ends(shapes, attempt).values()) <= size.length + 1e-9:
                on_sheet.append(i)
                found = attempt
        for i in on_sheet:
            angle, dx, dy = found[i]
            placements[i] = (angle, dx, dy + offset)
        sheets.append((tuple(on_sheet), float(sum(shapes[i].area for i in on_sheet)), size))
        stock.append((0.0, offset, size.width, offset + size.length))
        offset += size.length + SHEET_SPACING
        if on_hand[k] is not None:
            on_hand[k] -= 1
        left = [i for i in left if i not in on_sheet]
    return placements, sheets, stock
