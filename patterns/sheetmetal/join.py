"""Stage 4 of an unfold: the developed faces joined into one blank by rigid motions.

From the fixed face outwards, each face is turned and moved (never mirrored)
so that the edge it shares with a face already placed lands on that face's
copy of it.  Every other shared edge is checked to meet as well: a closed tube
does not (it needs a cut), and a meshed face meets its neighbours only to
within its flattening's strain (the gap is reported with it).
"""

from __future__ import annotations

import numpy as np

from ..curves import Motion
from ..errors import InputError
from ..measure import best_turn
from ..tessellate.topology import Topology
from .faces import edge_uv
from .sheet import SheetModel

__all__ = ["MEET", "flat", "place_faces"]

MEET = 0.01
"""Shared edges must meet on the blank within this, mm."""


def _kabsch(src: np.ndarray, dst: np.ndarray) -> Motion:
    """The rigid motion (never a mirror) taking ``src`` (k, 2) closest to ``dst``."""
    cs, cd = src.mean(axis=0), dst.mean(axis=0)
    angle = best_turn(src - cs, dst - cd)  # no BLAS: every face's place on the blank follows its bits
    turn = Motion(angle)
    shift = cd - turn(cs)
    return Motion(angle, float(shift[0]), float(shift[1]))


def place_faces(topology: Topology, maps: dict, sheet: SheetModel, name: str) -> tuple:
    """``({face: Motion}, {meshed face: gap mm})``: each skin face's placement on the blank, breadth first
    from the fixed face, and how far each meshed face's edges land from its neighbours'."""
    motions = {sheet.fixed: Motion()}
    queue = [sheet.fixed]
    while queue:
        a = queue.pop(0)
        for b, e in sheet.neighbours[a]:
            if b in motions or b not in sheet.skin:
                continue
            edge = topology.edges[e]
            dst = motions[a](maps[a].local(edge_uv(edge, maps[a].face.face, 5)))
            src = maps[b].local(edge_uv(edge, maps[b].face.face, 5))
            motions[b] = _kabsch(src, dst)
            queue.append(b)
    gaps = {i: 0.0 for i, m in maps.items() if m.meshed is not None}
    for a in sorted(sheet.skin):
        for b, e in sheet.neighbours[a]:
            if a >= b:
                continue
            edge = topology.edges[e]
            gap = float(np.abs(motions[a](maps[a].local(edge_uv(edge, maps[a].face.face, 5)))
                               - motions[b](maps[b].local(edge_uv(edge, maps[b].face.face, 5)))).max())
            meshed = [k for k in (a, b) if k in gaps]
            for k in meshed:
                gaps[k] = max(gaps[k], gap)
            if gap > MEET and not meshed:
                raise InputError(f"{name}: the sheet closes on itself (faces {a} and {b} land {gap:.3f} mm "
                                 f"apart once unfolded, along edge {e}): a tube or a box with no seam; "
                                 f"cut it along a line first")
    return motions, gaps


def flat(maps: dict, motions: dict, face: int, uv: np.ndarray) -> np.ndarray:
    """(k, 2) parameters on a skin face to (k, 2) positions on the blank, mm."""
    return motions[face](maps[face].local(uv))

