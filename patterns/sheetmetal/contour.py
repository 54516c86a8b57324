"""Stage 5 of an unfold: the blank's cut contour, its bend lines, and flanges that collide.

Skin edges that meet a rim are the cut contour, each an exact piece on the
blank (a line stays a line, a circle on a plane an arc, anything else a finely
sampled polyline), chained by the model's vertices into loops: the largest is
the outline, the others holes.  Each bend's centre line is the middle ruling
of its developed zone.  Faces that land on one another once unfolded are a
``flanges-overlap`` error.
"""

from __future__ import annotations

import numpy as np
import shapely

from ..curves import Arc, Line, Loop, Polyline
from ..errors import FlattenError
from ..findings import Code, Finding, Severity
from ..tessellate.topology import Topology
from .bends import BendGroup
from .join import flat

__all__ = ["bend_line", "cut_loops", "overlaps"]

SAMPLE = 0.001
"""Chord error of curved pieces sampled as polylines, mm."""


def _piece(edge, face: int, maps: dict, motions: dict, flip: bool):
    """One boundary edge of a skin face as an exact piece on the blank, walked as the face's wire walks it."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Curve2d
    from OCP.GCPnts import GCPnts_QuasiUniformDeflection
    from OCP.GeomAbs import GeomAbs_Circle, GeomAbs_Line

    fmap = maps[face]
    c2 = BRepAdaptor_Curve2d(edge, fmap.face.face)
    t0, t1 = c2.FirstParameter(), c2.LastParameter()
    if flip:
        t0, t1 = t1, t0

    def at(ts):
        pts = []
        for t in ts:
            p = c2.Value(float(t))
            pts.append((p.X(), p.Y()))
        return flat(maps, motions, face, np.array(pts))

    kind, surface = c2.GetType(), fmap.kind
    straight = kind == GeomAbs_Line and (surface in ("plane", "cylinder") or (
        surface == "cone" and abs(c2.Line().Direction().X()) < 1e-12))
    if straight:  # a line of the parameters is a line of the flat, but on a cone only along a generator
        a, b = at([t0, t1])
        return Line(a, b)
    if kind == GeomAbs_Circle and surface == "plane":
        circ = c2.Circle()
        c = flat(maps, motions, face, np.array([[circ.Location().X(), circ.Location().Y()]]))[0]
        a, q = at([t0, t0 + 0.25 * (t1 - t0)])
        u, w = a - c, q - c
        sweep = abs(t1 - t0) * np.sign(u[0] * w[1] - u[1] * w[0])
        return Arc(c, float(circ.Radius()), float(np.arctan2(*(a - c)[::-1])), float(sweep))
    curve = BRepAdaptor_Curve(edge)
    sampler = GCPnts_QuasiUniformDeflection(curve, SAMPLE)
    ts = [sampler.Parameter(k) for k in range(1, sampler.NbPoints() + 1)] if sampler.IsDone() else []
    if len(ts) < 2:
        ts = np.linspace(curve.FirstParameter(), curve.LastParameter(), 65)
    ts = np.sort(np.asarray(ts))
    if flip:
        ts = ts[::-1]
    return Polyline(at(ts))


def cut_loops(topology: Topology, maps: dict, motions: dict, skin: frozenset, name: str) -> list:
    """The cut contour: skin edges that meet a rim, chained into closed loops by their vertices."""
    from OCP.TopAbs import TopAbs_REVERSED

    by_start = {}
    for i in sorted(skin):
        for wire in topology.wires[i]:
            for e, edge in wire:
                if topology.degenerate[e] or all(k in skin for k in topology.edge_faces[e]):
                    continue
                flip = edge.Orientation() == TopAbs_REVERSED
                a, b = topology.edge_vertices[e][::-1] if flip else topology.edge_vertices[e]
                by_start.setdefault(a, []).append((b, _piece(edge, i, maps, motions, flip)))
    loops = []
    while by_start:
        first = next(iter(by_start))
        pieces, at = [], first
        while True:
            nxt = by_start.get(at)
            if not nxt:
                raise FlattenError(f"{name}: the cut contour does not close at a vertex of the model "
                                   f"(after {len(pieces)} edges)")
            to, piece = nxt.pop()
            if not nxt:
                del by_start[at]
            pieces.append(piece)
            at = to
            if at == first:
                break
        loops.append(Loop(tuple(pieces)))
    return loops


def bend_line(maps: dict, motions: dict, bend: BendGroup) -> np.ndarray:
    """(2, 2) float64, mm: the centre line of a bend's developed zone, end to end."""
    from OCP.BRepTools import BRepTools

    ends = []
    for i in bend.faces:
        u0, u1, v0, v1 = BRepTools.UVBounds_s(maps[i].face.face)
        um = 0.5 * (u0 + u1)
        ends.append(flat(maps, motions, i, np.array([[um, v0], [um, v1]])))
    ends = np.concatenate(ends)
    d = ends[1] - ends[0]
    d /= np.linalg.norm(d)
    s = (ends - ends[0]) @ d
    return np.array([ends[np.argmin(s)], ends[np.argmax(s)]])


def overlaps(topology: Topology, maps: dict, motions: dict, skin: frozenset, gaps: dict, name: str):
    """``flanges-overlap`` findings: faces of the blank that land on one another once unfolded."""
    from OCP.TopAbs import TopAbs_REVERSED

    polys = {}
    for i in sorted(skin):
        rings = []
        for wire in topology.wires[i]:
            pts = [_piece(edge, i, maps, motions, edge.Orientation() == TopAbs_REVERSED).points(0.01)[:-1]
                   for e, edge in wire if not topology.degenerate[e]]
            if pts:
                rings.append(np.concatenate(pts))
        if rings:
            rings.sort(key=lambda r: -shapely.Polygon(r).area)
            polys[i] = shapely.make_valid(shapely.Polygon(rings[0], rings[1:]))
    keys = sorted(polys)
    tree = shapely.STRtree([polys[k] for k in keys])
    for a, b in zip(*tree.query([polys[k] for k in keys], predicate="intersects")):
        if a >= b:
            continue
        common = polys[keys[a]].intersection(polys[keys[b]])
        # a meshed face meets its neighbours only to within its gap: a sliver that wide along its edge is no overlap
        slack = sum(gaps[k] * polys[k].length for k in (keys[a], keys[b]) if k in gaps)
        if common.area > 0.01 + slack:
            point = np.array(common.representative_point().coords[0])
            yield Finding(Code.FLANGES_OVERLAP, Severity.ERROR, (name,), point[None, :], (), None,
                          f"{name}: faces {keys[a]} and {keys[b]} overlap by {common.area:.2f} mm² once "
                          f"unfolded: the blank cannot be cut in one piece")
