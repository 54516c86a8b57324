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
from ..findings import Code, Finding, Severity
from ..tessellate.topology import Topology
from .bends import BendGroup
from .corners import is_bend_end, treat_corners
from .join import flat

__all__ = ["CUSP_DEGREES", "bend_line", "clip_to", "contour_faults", "cut_loops", "edge_parameters", "edge_piece", "overlaps"]

CUSP_DEGREES = 30.0
"""A corner of the cut contour sharper than this (degrees) is a cusp: a spike of material a laser burns, or a
notch narrower than its kerf (the model's corner developed as it is makes notches of 19-27 degrees)."""
SLIVER = 0.5
"""Material narrower than this many thicknesses is a sliver."""

SAMPLE = 0.001
"""Chord error of curved pieces sampled as polylines, mm."""


def edge_piece(edge, face: int, maps: dict, motions: dict, flip: bool):
    """One boundary edge of a skin face as an exact piece on the blank, walked as the face's wire walks it."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve2d
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
    return Polyline(at(edge_parameters(edge, SAMPLE, reverse=flip)))


def edge_parameters(edge, deflection: float, *, reverse: bool) -> np.ndarray:
    """(k,) float64 parameters of an edge's 3D curve, its ends included, whose chord error is at most
    ``deflection`` mm; in the walk's direction (``reverse``: from the curve's last parameter)."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.GCPnts import GCPnts_QuasiUniformDeflection

    curve = BRepAdaptor_Curve(edge)
    sampler = GCPnts_QuasiUniformDeflection(curve, deflection)
    ts = [sampler.Parameter(k) for k in range(1, sampler.NbPoints() + 1)] if sampler.IsDone() else []
    if len(ts) < 2:
        ts = np.linspace(curve.FirstParameter(), curve.LastParameter(), 65)
    ts = np.sort(np.asarray(ts, dtype=np.float64))
    return ts[::-1] if reverse else ts


def cut_loops(topology: Topology, maps: dict, motions: dict, skin: frozenset, name: str, *, relief: str = "none",
              thickness: float = 0.0, bend_lines: dict | None = None, relief_size: float | None = None,
              missed: list | None = None, chains: list | None = None) -> tuple:
    """The cut contour: skin edges that meet a rim, chained into closed loops by their vertices, with the
    corners where bends meet treated as ``relief`` says, of ``relief_size`` mm when given (``missed`` gets
    where that size does not reach a flange's edge: :func:`~patterns.sheetmetal.corners.treat_corners`).
    ``chains``, when given, gets each loop's skin edges in the loop's order, ``((edge, face, reversed), ...)``
    (None for a loop that does not close), for :func:`~patterns.sheetmetal.oblique.neutral_trace`.

    Returns
    -------
    loops : list of (Loop, tuple of int)
        Each loop and the skin face each of its pieces comes from.
    gaps : list of (2, 2) float64, mm
        Where a contour that does not close stops and where it should go on (the loop is closed across
        it by a line, so that the blank can be drawn for the finding; :func:`~patterns.sheetmetal.rules.
        open_contours` makes the errors).
    """
    from OCP.TopAbs import TopAbs_REVERSED

    by_start = {}
    for i in sorted(skin):
        for wire in topology.wires[i]:
            for e, edge in wire:
                if topology.degenerate[e] or all(k in skin for k in topology.edge_faces[e]):
                    continue
                flip = edge.Orientation() == TopAbs_REVERSED
                a, b = topology.edge_vertices[e][::-1] if flip else topology.edge_vertices[e]
                piece = edge_piece(edge, i, maps, motions, flip)
                by_start.setdefault(a, []).append((b, (piece, i, is_bend_end(piece, maps[i].kind)), (e, i, flip)))
    loops, gaps = [], []
    ends = {b for chain in by_start.values() for b, _, _ in chain}
    while by_start:
        first = next((v for v in by_start if v not in ends), next(iter(by_start)))  # an open chain from its start
        pieces, links, at, closed = [], [], first, True
        while True:
            nxt = by_start.get(at)
            if not nxt:  # open: closed by a line across the gap for the drawing, and said (an open-contour error)
                closed = False
                start, stop = pieces[0][0].points()[0], pieces[-1][0].points()[-1]
                if np.linalg.norm(start - stop) > 1e-6:
                    gaps.append(np.array([stop, start]))
                    pieces.append((Line(stop, start), pieces[-1][1], False))
                break
            to, piece, link = nxt.pop()
            if not nxt:
                del by_start[at]
            pieces.append(piece)
            links.append(link)
            at = to
            if at == first:
                break
        treated = (treat_corners(pieces, relief=relief, thickness=thickness, bend_lines=bend_lines or {},
                                 size=relief_size, missed=missed) if closed
                   else [(p, f) for p, f, _ in pieces])  # an open loop is drawn as it is found
        treated = _joined(treated)
        loops.append((Loop(tuple(p for p, _ in treated)), tuple(f for _, f in treated)))
        if chains is not None:
            chains.append(tuple(links) if closed else None)
    return loops, gaps


def _moved(piece, *, start=None, end=None):
    """A line or polyline with its first or last point moved; None for an arc (kept whole)."""
    if isinstance(piece, Line):
        return Line(piece.start if start is None else start, piece.end if end is None else end)
    if isinstance(piece, Polyline):
        pts = piece.points().copy()
        if start is not None:
            pts[0] = start
        if end is not None:
            pts[-1] = end
        return Polyline(pts)
    return None


def _joined(pieces: list) -> list:
    """A closed loop's ``(piece, face)`` list in which every piece starts where the one before it ends.

    Where they do not (more than 10 nm apart: a meshed face's edge lands beside its neighbour's, as its
    ``meshed-face`` note says), the next piece's start is moved to the end of the one before (or that one's
    end to the next's start, when the next is an arc; a line joins two arcs), so that every arc is drawn
    whole, to its own ends, and no piece runs back over another.
    """
    out, k = list(pieces), 0
    while k < len(out):
        (piece, face), (after, face_after) = out[k], out[(k + 1) % len(out)]
        end, start = piece.points()[-1], after.points()[0]
        if np.linalg.norm(end - start) > 1e-5:
            last = k + 1 == len(out)  # the first piece keeps its start: the loop begins there
            moved = None if last else _moved(after, start=end)
            if moved is not None:
                out[k + 1] = (moved, face_after)
            elif (moved := _moved(piece, end=start)) is not None:
                out[k] = (moved, face)
            else:
                out.insert(k + 1, (Line(end, start), face))  # two arcs: a line between them
        k += 1
    return out


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


def clip_to(line: np.ndarray, outline: Loop) -> np.ndarray:
    """(2, 2) float64, mm: a bend line cut back to the part of it inside the outline (first to last point inside),
    so that it stops at a corner relief; the line as it is when it lies wholly inside (or, oddly, wholly outside)."""
    polygon = outline.polygon
    if not polygon.is_valid:  # a contour crossing itself is a finding of its own; the line stays as it is
        return line
    inside = shapely.LineString(line).intersection(polygon)
    if inside.is_empty or inside.length >= np.linalg.norm(line[1] - line[0]) - 1e-9:
        return line
    d = line[1] - line[0]
    s = np.concatenate([np.asarray(g.coords) for g in getattr(inside, "geoms", [inside]) if g.length > 0]) - line[0]
    t = s @ d / (d @ d)
    return np.array([line[0] + t.min() * d, line[0] + t.max() * d])


def overlaps(topology: Topology, maps: dict, motions: dict, skin: frozenset, gaps: dict, name: str):
    """``flanges-overlap`` findings: faces of the blank that land on one another once unfolded."""
    from OCP.TopAbs import TopAbs_REVERSED

    polys = {}
    for i in sorted(skin):
        rings = []
        for wire in topology.wires[i]:
            pts = [edge_piece(edge, i, maps, motions, edge.Orientation() == TopAbs_REVERSED).points(0.01)[:-1]
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


def contour_faults(loops: list, thickness: float, name: str, *, overlapping: bool = False) -> list:
    """``outline-cusp``, ``outline-touches-itself`` and ``sliver`` findings on a blank's cut loops.

    Parameters
    ----------
    loops : list of (Loop, tuple of int)
        The cut loops (the largest the outline) and the skin face each of their pieces comes from.
    thickness : float
        The sheet's thickness, mm (a sliver is narrower than :data:`SLIVER` of it).
    name : str
        The part, for messages.
    overlapping : bool
        Flanges already found to land on one another: their contours cross, and that is said once, there.
    """
    out = []
    outline = max(loops, key=lambda lp: lp[0].area)[0]
    for loop, faces in loops:
        sign = 1.0 if (loop is outline) == loop.counter_clockwise else -1.0  # material on the left when > 0
        for k, (piece, face) in enumerate(zip(loop.pieces, faces)):
            pts = piece.points(0.01)
            nxt = loop.pieces[(k + 1) % len(loop.pieces)].points(0.01)
            run = np.vstack([pts, nxt[1:2]])  # the piece's own corners and the one where it meets the next
            a, b = run[1:-1] - run[:-2], run[2:] - run[1:-1]
            keep = (np.linalg.norm(a, axis=1) > 1e-9) & (np.linalg.norm(b, axis=1) > 1e-9)
            a, b, at = a[keep], b[keep], run[1:-1][keep]
            turn = np.degrees(np.arctan2(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0], (a * b).sum(axis=1))) * sign
            sharp = np.abs(turn) > 180.0 - CUSP_DEGREES  # the contour turns back on itself
            if sharp.any():
                k = int(np.argmax(np.abs(turn)))
                what = "a spike of material" if turn[k] > 0 else "a notch narrower than a kerf at its tip"
                out.append(Finding(Code.OUTLINE_CUSP, Severity.NOTE, (name,), at[k][None, :], (), None,
                                   f"{name}: the cut contour comes to a point of {180 - abs(turn[k]):.1f} degrees at "
                                   f"x {at[k][0]:.3f}, y {at[k][1]:.3f} mm (face {face}): {what}"))
    polygon = shapely.Polygon(outline.points(0.01), [lp.points(0.01) for lp, _ in loops if lp is not outline])
    if not polygon.is_valid:
        if overlapping:
            return out
        where = shapely.get_coordinates(shapely.make_valid(polygon).boundary)[:1]
        out.append(Finding(Code.OUTLINE_TOUCHES_ITSELF, Severity.ERROR, (name,), where, (), None,
                           f"{name}: the cut contours touch or cross ({shapely.is_valid_reason(polygon)}): the blank "
                           f"cannot be cut in one piece"))
        return out
    width = SLIVER * thickness
    opened = polygon.buffer(-width / 2, join_style="mitre", mitre_limit=10.0).buffer(
        width / 2, join_style="mitre", mitre_limit=10.0)
    thin = polygon.difference(opened.buffer(1e-6, join_style="mitre"))
    for part in getattr(thin, "geoms", [thin]):
        if part.area > 0.05 * width * width and part.length > 4 * width:
            at = np.array(part.representative_point().coords)
            out.append(Finding(Code.SLIVER, Severity.NOTE, (name,), at, (), None,
                               f"{name}: a strip narrower than {width:.2f} mm (half the thickness) at x "
                               f"{at[0][0]:.3f}, y {at[0][1]:.3f} mm, {part.area:.2f} mm²"))
    return out
