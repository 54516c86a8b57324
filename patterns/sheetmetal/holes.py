"""Countersunk and counterbored holes: where a hole's edge on one skin differs from the other's.

A laser cuts a hole through the sheet at its smallest diameter; a countersink
(a cone) or a counterbore (a larger cylinder and a flat step) is machined
afterwards, from one side.  The developed skin shows only one of the hole's
two edges, so :func:`hole_rims` walks each round hole of a planar skin face
through its wall -- the coaxial cylinders, cones and steps between the two
skins -- to the other skin, and returns

* the holes to cut, each at its through diameter (a hole countersunk on the
  fixed face's side is drawn at its smallest diameter, not at its rim), and
* one :class:`~patterns.blank.Rim` per countersunk or counterbored side: the
  rim circle, exact, placed with the same face motion as the hole.

A hole whose wall meets anything else (a bend, a slot, a face off its axis) is
left as it is.
"""

from __future__ import annotations

import numpy as np

from ..blank import Rim
from ..curves import Arc, Loop
from .faces import normal, uv_mid
from .join import flat
from .sheet import SheetModel

__all__ = ["RIM", "hole_rims"]

RIM = 1e-3
"""A hole's edge on a skin at least this much (mm, in radius) larger than its through hole is a rim."""
_ON = 1e-4
"""Lengths (mm) closer than this are the same: a centre on the axis, a depth on a skin."""


def _circle(edge):
    """``(centre (3,), axis (3,), radius)`` of a circular edge, or None."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.GeomAbs import GeomAbs_Circle

    curve = BRepAdaptor_Curve(edge)
    if curve.GetType() != GeomAbs_Circle:
        return None
    c = curve.Circle()
    p, d = c.Location(), c.Axis().Direction()
    return np.array([p.X(), p.Y(), p.Z()]), np.array([d.X(), d.Y(), d.Z()]), float(c.Radius())


def _coaxial(f, centre, axis, thickness) -> bool:
    """Face ``f`` belongs to a hole's wall: a cylinder or cone about the hole's axis, or a flat step across it
    strictly between the two skins."""
    if f.kind in ("cylinder", "cone"):
        off = centre - f.origin
        return abs(abs(f.axis @ axis) - 1) < 1e-9 and np.linalg.norm(off - (off @ axis) * axis) < _ON
    if f.kind == "plane":  # its frame's axis is its normal, one way or the other
        depth = -(f.origin - centre) @ axis
        return abs(abs(f.axis @ axis) - 1) < 1e-9 and _ON < depth < thickness - _ON
    return False


def _wall(topology, faces, skin_face: int, wire, centre, axis, thickness):
    """``[(depth, radius), ...]`` of every circle of the hole's wall (depth into the sheet from the skin face,
    mm), walked from the hole's edges on ``skin_face``; None when the wall meets a face that is not a skin or
    part of it."""
    start = {k for e, _ in wire for k in topology.edge_faces[e] if k != skin_face}
    seen, stack, circles = set(start), list(start), []
    while stack:
        k = stack.pop()
        if not _coaxial(faces[k], centre, axis, thickness):
            return None
        for wire_k in topology.wires[k]:
            for e, edge in wire_k:
                if topology.degenerate[e]:
                    continue
                got = _circle(edge)
                if got is not None:
                    c, _, r = got
                    off = c - centre
                    if np.linalg.norm(off - (off @ axis) * axis) < _ON:
                        circles.append((float(-off @ axis), r))
                for j in topology.edge_faces[e]:
                    if j in seen or j == k:
                        continue
                    f = faces[j]
                    if f.kind == "plane":  # a skin: the face the hole starts from, or the sheet's other side
                        depth = -(f.origin - centre) @ axis
                        if abs(abs(f.axis @ axis) - 1) < 1e-9 and (abs(depth) < _ON or abs(depth - thickness) < _ON):
                            continue
                    seen.add(j)
                    stack.append(j)
    return circles


def _round(topology, wire):
    """``(centre, axis, radius)`` of a wire that is one circle (one edge or several arcs of it), or None."""
    got = [_circle(edge) for e, edge in wire if not topology.degenerate[e]]
    if not got or any(g is None for g in got):
        return None
    c, a, r = got[0]
    if any(np.linalg.norm(g[0] - c) > _ON or abs(g[2] - r) > _ON for g in got[1:]):
        return None
    return c, a, r


def _rims_of(circles, thickness):
    """``(through radius, [(side, rim radius, depth, kind), ...])`` from a wall's circles ``(depth, radius)``:
    on each skin where the hole is wider than its narrowest, a rim; a counterbore when the rim's width goes on
    down into the sheet (a cylinder to a step), else a countersink (a cone down to the hole)."""
    through = min(r for _, r in circles)
    out = []
    for side, skin in (("near", 0.0), ("far", thickness)):
        at = [r for d, r in circles if abs(d - skin) < _ON]
        if not at or max(at) < through + RIM:
            continue
        rim = max(at)
        depth = min(abs(d - skin) for d, r in circles if r < through + RIM)  # where the wall is down to the hole
        bored = any(abs(d - skin) > _ON and abs(r - rim) < _ON for d, r in circles)
        out.append((side, rim, depth, "counterbore" if bored else "countersink"))
    return through, out


def hole_rims(topology, faces: tuple, maps: dict, motions: dict, sheet: SheetModel, holes: tuple) -> tuple:
    """The holes to cut at their through diameter, and the countersinks' and counterbores' rims.

    Parameters
    ----------
    topology : patterns.tessellate.topology.Topology
    faces : tuple of SheetFace
    maps : dict
        ``{face: FaceMap}`` of the skin.
    motions : dict
        ``{face: patterns.curves.Motion}``: each skin face's placement on the blank.
    sheet : SheetModel
    holes : tuple of patterns.curves.Loop
        The blank's holes as the developed skin draws them (clockwise).

    Returns
    -------
    holes : tuple of patterns.curves.Loop
        ``holes`` with every hole countersunk or counterbored on the fixed face's side drawn at its through
        diameter (one full clockwise circle); the others as they are.
    rims : tuple of patterns.blank.Rim
        One per countersunk or counterbored side of a hole, in the order of the holes.
    """
    from OCP.BRepAdaptor import BRepAdaptor_Curve2d

    holes, rims = list(holes), []
    t = sheet.thickness
    centres = _centres(holes)
    for i in sorted(sheet.skin):
        if faces[i].kind != "plane":
            continue
        u, v = uv_mid(faces[i].face)
        n = normal(faces[i], u, v)
        for wire in topology.wires[i]:
            got = _round(topology, wire)
            if got is None or any(k in sheet.skin for e, _ in wire for k in topology.edge_faces[e]
                                  if k != i) or abs(abs(got[1] @ n) - 1) > 1e-9:
                continue
            centre, _, radius = got
            edge0 = next(edge for e, edge in wire if not topology.degenerate[e])
            loc = BRepAdaptor_Curve2d(edge0, faces[i].face).Circle().Location()
            at = flat(maps, motions, i, np.array([[loc.X(), loc.Y()]]))[0]
            k = next((k for k in sorted(centres.query_ball_point(at, 1e-4)) if _is_hole(holes[k], at, radius)), None)
            circles = _wall(topology, faces, i, wire, centre, n, t)
            if k is None or not circles or not any(abs(d - t) < _ON for d, _ in circles):
                continue
            through, sides = _rims_of(circles, t)
            for side, rim, depth, kind in sides:
                angle = float(np.degrees(2 * np.arctan2(rim - through, depth))) if kind == "countersink" else None
                rims.append(Rim(circle=Arc(at, rim, 0.0, 2 * np.pi), through=2 * through, kind=kind, side=side,
                                depth=depth, angle=angle, face=i))
                if side == "near":
                    holes[k] = Loop((Arc(at, through, 0.0, -2 * np.pi),))
    return tuple(holes), tuple(rims)


def _centres(holes: list):
    """A KD-tree of each hole's first piece's centre (its first point where that is no arc): a lookup per round
    wire instead of a scan of every hole (a plate with 5000 holes made that 25 million checks)."""
    from scipy.spatial import cKDTree

    return cKDTree(np.array([h.pieces[0].center if isinstance(h.pieces[0], Arc) else h.pieces[0].points()[0]
                             for h in holes]).reshape(-1, 2))


def _is_hole(loop: Loop, at: np.ndarray, radius: float) -> bool:
    """The loop is a circle (arcs of one) about ``at`` of ``radius``."""
    return all(isinstance(p, Arc) and np.linalg.norm(p.center - at) < 1e-4 and abs(p.radius - radius) < 1e-6
               for p in loop.pieces)
