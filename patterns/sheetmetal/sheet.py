"""Stage 2 of an unfold: the sheet -- its thickness, and the skin that becomes the blank.

A bent sheet-metal part is a solid of constant thickness ``t``: two skins
(the inside and the outside of every bend) joined by narrow rim faces.  The
thickness is the distance from the fixed planar face to the nearest opposite,
parallel face behind it; the skin is every face reached from the fixed face
across tangent edges (the rims meet it at a corner).  A part whose skin is
much less than half its surface is not a sheet (a block, a thick plate, the
end of a tube); one whose volume is not that of a sheet of this thickness over
its skin (within 1 %) is refused too, by :func:`check_volume`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..errors import InputError
from ..tessellate.topology import Topology
from .faces import normal, point, uv_mid

if TYPE_CHECKING:
    from OCP.TopoDS import TopoDS_Shape

__all__ = ["SheetModel", "check_volume", "find_sheet"]

TANGENT = 1e-4
"""Two faces are tangent along an edge when their normals there differ by less than this (radians, about)."""
SIDE = 0.4
"""One skin of a sheet is nearly half its surface (0.46-0.50 on the parts measured); below this share, not a sheet."""


@dataclass(frozen=True, eq=False)
class SheetModel:
    """The sheet a part is bent from, as read from its solid (a nest's stock sheet is
    :class:`patterns.nesting.Sheet`).

    Attributes
    ----------
    thickness : float
        mm.
    fixed : int
        The planar face that keeps its place.
    skin : frozenset of int
        The faces of the skin the blank is developed from (the fixed face's side).
    neighbours : tuple
        Per face, ``((other face, shared edge), ...)`` across its tangent edges.
    """

    thickness: float
    fixed: int
    skin: frozenset
    neighbours: tuple


def find_sheet(shape: TopoDS_Shape, topology: Topology, faces: tuple, fixed_face: int | None, name: str) -> SheetModel:
    """The sheet: its fixed face, thickness and skin.

    The fixed face is ``fixed_face`` when given, else the largest planar face
    that starts a sheet: the first, by area, whose smooth region (the faces
    reached across tangent edges) is nearly half the part's surface and that
    has a parallel face behind it.  A corrugated strip's end face (the whole
    profile, larger than any one flat) is passed over that way.
    """
    largest = max(faces, key=lambda f: f.area)
    if largest.kind == "cylinder" and any(owners == (largest.index, largest.index) for owners in topology.edge_faces):
        raise InputError(f"{name}: a closed tube (face {largest.index} goes all the way round, with no seam): "
                         f"cut it along a line of its axis first")
    planes = sorted((f for f in faces if f.kind == "plane"), key=lambda f: -f.area)
    planes = _equal_sides_inside_first(planes, faces)
    if not planes:
        raise InputError(f"{name}: not a sheet-metal part: it has no planar face")
    if fixed_face is not None and (fixed_face >= len(faces) or faces[fixed_face].kind != "plane"):
        raise InputError(f"{name}: fixed_face {fixed_face} is not a planar face of the part "
                         f"(it has faces 0..{len(faces) - 1})")
    tangent = _tangent_edges(topology, faces)
    neighbours = _neighbours(tangent, len(faces))
    total = sum(f.area for f in faces)
    first = None
    for fixed in [fixed_face] if fixed_face is not None else [f.index for f in planes]:
        skin = _skin(topology, tangent, neighbours, fixed, name, faces)  # a sheet closed on itself: said at once
        try:
            share = sum(faces[i].area for i in skin) / total
            if share < SIDE:
                raise InputError(f"{name}: not a sheet: face {fixed} and the faces joined to it smoothly are "
                                 f"{share:.0%} of the part's surface, one side of a sheet nearly half (a block, a "
                                 f"thick plate, the end of a tube)")
            return SheetModel(_thickness(shape, faces, fixed, name), fixed, frozenset(skin), neighbours)
        except InputError as exc:
            first = first or exc
    if fixed_face is None and len(planes) > 1:
        raise InputError(f"{first}; no other planar face starts a sheet either (fixed_face=N, --fixed-face N, "
                         f"names the face to unfold from)") from None
    raise first


SAME_AREA = 1e-6
"""Planar faces whose areas differ by less than this share of the larger are of one area (a plate's two sides)."""


def _equal_sides_inside_first(planes: list, faces) -> list:
    """``planes`` (by area, largest first) with each run of faces of one area ordered by how far the part's
    surface lies on their outward side (its faces' mid points, weighted by area): of a plate's two sides the
    one its flanges rise from comes first, whatever order the file lists them in."""
    mids = np.array([point(g, *uv_mid(g.face)) for g in faces])
    weights = np.array([g.area for g in faces]) / sum(g.area for g in faces)

    def inwards(f) -> float:
        u, v = uv_mid(f.face)
        return float(((mids - point(f, u, v)) @ normal(f, u, v) * weights).sum())

    out, k = [], 0
    while k < len(planes):
        j = k
        while j + 1 < len(planes) and planes[k].area - planes[j + 1].area <= SAME_AREA * planes[k].area:
            j += 1
        run = planes[k:j + 1]
        out += sorted(run, key=lambda f: -inwards(f)) if len(run) > 1 else run
        k = j + 1
    return out


def _thickness(shape: TopoDS_Shape, faces: tuple, fixed: int, name: str) -> float:
    """Distance from the fixed planar face to the opposite parallel face behind it, mm.

    The nearest such face, unless the part is not sheet there: a counterbore's floor on the far side is
    an opposite face nearer than the far skin, so each depth, nearest first, is tried at points spread over the
    fixed face; the thickness is the first depth just past which most of them leave the solid."""
    f = faces[fixed]
    u, v = uv_mid(f.face)
    n, p = normal(f, u, v), point(f, u, v)
    depths = set()
    for g in faces:
        if g.kind != "plane" or g.index == fixed:
            continue
        gu, gv = uv_mid(g.face)
        m, q = normal(g, gu, gv), point(g, gu, gv)
        depth = float(-(q - p) @ n)
        if m @ n < -1 + 1e-8 and depth > 1e-6:
            depths.add(round(depth, 9))
    if not depths:
        raise InputError(f"{name}: not a sheet: face {fixed} has no parallel face behind it (no constant thickness)")
    depths = sorted(depths)
    if len(depths) == 1:
        return depths[0]
    samples = _points_on(f)
    for depth in depths:
        if _outside_share(shape, samples - (depth * (1 + 1e-6) + 1e-6) * n) > 0.5:
            return depth
    return depths[0]


def _points_on(f, n: int = 9) -> np.ndarray:
    """(k, 3) points of a planar face: a grid over its parameter box, those inside the face (holes out), mm."""
    from OCP.BRepTools import BRepTools
    from OCP.gp import gp_Pnt2d
    from OCP.IntTools import IntTools_FClass2d
    from OCP.TopAbs import TopAbs_IN

    u0, u1, v0, v1 = BRepTools.UVBounds_s(f.face)
    inside = IntTools_FClass2d(f.face, 1e-7)
    us, vs = u0 + (u1 - u0) * (np.arange(n) + 0.5) / n, v0 + (v1 - v0) * (np.arange(n) + 0.5) / n
    out = [point(f, float(a), float(b)) for a in us for b in vs
           if inside.Perform(gp_Pnt2d(float(a), float(b))) == TopAbs_IN]
    return np.array(out).reshape(-1, 3)


def _outside_share(shape: TopoDS_Shape, points: np.ndarray) -> float:
    """The share of ``points`` ((k, 3) mm) outside the solid ``shape`` (1 when there are none)."""
    from OCP.BRepClass3d import BRepClass3d_SolidClassifier
    from OCP.gp import gp_Pnt
    from OCP.TopAbs import TopAbs_OUT

    if not len(points):
        return 1.0
    classifier = BRepClass3d_SolidClassifier(shape)
    out = 0
    for x, y, z in points:
        classifier.Perform(gp_Pnt(float(x), float(y), float(z)), 1e-7)
        out += classifier.State() == TopAbs_OUT
    return out / len(points)


def _tangent_edges(topology: Topology, faces) -> dict:
    """``{edge: (face a, face b)}`` of every edge along which two faces meet tangentially, ``{edge: None}`` for
    a closed face's own seam line."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Curve2d

    out = {}
    for e, owners in enumerate(topology.edge_faces):
        if topology.degenerate[e]:
            continue
        if len(owners) == 2 and owners[0] == owners[1]:
            out[e] = None
            continue
        if len(set(owners)) != 2:
            continue
        edge = topology.edges[e]
        c = BRepAdaptor_Curve(edge)
        tm = 0.5 * (c.FirstParameter() + c.LastParameter())
        normals = []
        for k in owners:
            p = BRepAdaptor_Curve2d(edge, faces[k].face).Value(tm)
            normals.append(normal(faces[k], p.X(), p.Y()))
        if normals[0] @ normals[1] > 1 - TANGENT:
            out[e] = tuple(owners)
    return out


def _neighbours(tangent: dict, n: int) -> tuple:
    """Per face, ``((other face, shared edge), ...)`` across its tangent edges."""
    neighbours = [[] for _ in range(n)]
    for e, pair in tangent.items():
        if pair is not None:
            a, b = pair
            neighbours[a].append((b, e))
            neighbours[b].append((a, e))
    return tuple(tuple(x) for x in neighbours)


def _skin(topology: Topology, tangent: dict, neighbours: tuple, fixed: int, name: str, faces=()) -> set:
    """The faces reached from ``fixed`` across tangent edges; InputError where the skin closes on itself round
    a face's own seam: a tube's, or a formed shell's when that face is doubly curved (a dimple's torus)."""
    skin, stack = {fixed}, [fixed]
    while stack:
        i = stack.pop()
        for j, _ in neighbours[i]:
            if j not in skin:
                skin.add(j)
                stack.append(j)
    for e, pair in tangent.items():
        if pair is None and topology.edge_faces[e][0] in skin:
            formed = [(i, k) for i, k in _doubly_curved(faces) if i in skin]
            if topology.edge_faces[e][0] in {i for i, _ in formed}:
                raise _formed(formed, name)
            raise InputError(f"{name}: the sheet closes on itself around face {topology.edge_faces[e][0]} "
                             f"(a tube with no seam): cut it along a line first")
    return skin


def check_volume(shape, sheet: SheetModel, faces, curvature: dict, meshed: dict, name: str) -> None:
    """InputError unless the solid holds the volume a sheet of this thickness over the skin holds (1 %).

    ``curvature`` gives each bend face's ``(bend radius, inside radius)``, ``meshed`` each meshed face's
    :class:`~patterns.sheetmetal.meshed.MeshedFace` (its own volume).
    """
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props)
    volume = abs(props.Mass())
    t = sheet.thickness
    expected = 0.0
    for i in sheet.skin:
        f = faces[i]
        if f.kind == "other":
            expected += meshed[i].volume
        elif f.kind == "plane":
            expected += f.area * t
        else:
            bend_radius, r_in = curvature[i]
            expected += f.area / bend_radius * ((r_in + t) ** 2 - r_in ** 2) / 2
    if abs(volume - expected) > 0.01 * volume:
        formed = _doubly_curved(faces)
        if formed:
            raise _formed(formed, name)
        raise InputError(f"{name}: not a sheet of constant thickness: the solid holds {volume:.0f} mm³, a "
                         f"{t:g} mm sheet over its skin {expected:.0f} mm³ (a machined block or a "
                         f"part of several thicknesses)")


def _formed(formed: list, name: str) -> InputError:
    """The refusal of a formed shell, naming its doubly curved faces (``formed``: :func:`_doubly_curved`'s)."""
    return InputError(f"{name}: faces {', '.join(str(i) for i, _ in formed[:6])}{' ...' if len(formed) > 6 else ''} "
                      f"are doubly curved ({', '.join(sorted({k for _, k in formed}))}): a formed or drawn shell "
                      f"has no flat blank to unfold (patterns flatten makes its pattern, with the strain)")


def _doubly_curved(faces) -> list:
    """``[(face, "sphere" | "torus")]``: the faces no press brake or roll can make (a formed or drawn shell)."""
    from OCP.BRepAdaptor import BRepAdaptor_Surface
    from OCP.GeomAbs import GeomAbs_Sphere, GeomAbs_Torus

    kinds = {GeomAbs_Sphere: "sphere", GeomAbs_Torus: "torus"}
    found = [(i, kinds.get(BRepAdaptor_Surface(f.face).GetType())) for i, f in enumerate(faces)]
    return [(i, k) for i, k in found if k is not None]


def bent_sheet(surfaces) -> tuple | None:
    """``(thickness mm, bends)`` when a part's faces look like a bent sheet, else None: the largest plane has a
    parallel one a thickness behind it (under a tenth of its size), and some coaxial cylinders' radii differ by
    that thickness (a bend's two skins).  ``surfaces``: each face's :class:`patterns.model.Surface` (None for
    a face of no analytic kind), with its area, as ``(surface, area)``.  A hint for ``flatten`` (each face a
    loose panel) that ``unfold`` is meant: never a decision of the engine's."""
    planes = sorted(((s, a) for s, a in surfaces if s is not None and s.kind.value == "plane"), key=lambda p: -p[1])
    cylinders = [s for s, _ in surfaces if s is not None and s.kind.value == "cylinder"]
    if not planes or len(cylinders) < 2:
        return None
    top, area = planes[0]
    n = top.axis / np.linalg.norm(top.axis)
    gaps = [abs(float(np.dot(s.origin - top.origin, n))) for s, _ in planes[1:]
            if abs(abs(float(np.dot(s.axis / np.linalg.norm(s.axis), n))) - 1.0) < 1e-6]
    gaps = [g for g in gaps if 1e-3 < g < 0.1 * np.sqrt(area)]
    if not gaps:
        return None
    t = min(gaps)
    bends = 0
    for i, a in enumerate(cylinders):
        axis = a.axis / np.linalg.norm(a.axis)
        for b in cylinders[i + 1:]:
            apart = np.cross(b.origin - a.origin, axis)
            if abs(abs(float(np.dot(b.axis / np.linalg.norm(b.axis), axis))) - 1.0) < 1e-6 \
                    and np.linalg.norm(apart) < 1e-6 * max(1.0, a.radius) and abs(abs(a.radius - b.radius) - t) < 1e-6 * max(1.0, t):
                bends += 1
    return (t, bends) if bends else None
