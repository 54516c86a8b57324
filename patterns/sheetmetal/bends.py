"""Stage 3 of an unfold: the bends, and every skin face's exact map to the flat.

Each cylinder or cone of the skin is a bend face: its curvature says which way
it turns (``concave``: the skin is on the inside of the bend) and its inside
radius.  Joined faces of one axis, radius and angle are one :class:`BendGroup`,
developed to its neutral width: ``angle (r + K t)`` for a cylinder, or the
width a bend table gives; a conical bend rolls out to the annular sector of
its neutral cone.  A :class:`FaceMap` takes a face's own parameters ``(u, v)``
to its flat coordinates: linearly on planes and cylinders (``(R_n u, v)``),
polar about the apex on a cone, through the mesh on a meshed face.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..errors import InputError
from .faces import SheetFace, handedness, normal, point, uv_mid
from .meshed import MeshedFace
from .sheet import SheetModel
from .table import UnfoldOptions

__all__ = ["BendGroup", "Curvature", "FaceMap", "curvatures", "face_maps", "group_bends"]


@dataclass(frozen=True)
class Curvature:
    """How a bend face of the skin curves: ``concave`` (the skin lies on the inside of the bend), the radius
    of curvature across the bend at its middle and the inside radius there, mm."""

    concave: bool
    bend_radius: float
    inside_radius: float


def curvatures(faces: tuple, sheet: SheetModel, name: str) -> dict:
    """``{face: Curvature}`` of every cylinder and cone of the skin."""
    out = {}
    for i in sorted(sheet.skin):
        f = faces[i]
        if f.kind not in ("cylinder", "cone"):
            continue
        u, v = uv_mid(f.face)
        outward = point(f, u, v) - f.origin
        outward -= (outward @ f.axis) * f.axis
        concave = bool(normal(f, u, v) @ outward < 0)
        if f.kind == "cylinder":
            bend_radius = f.radius
        else:  # a cone's radius across the bend: the distance to its axis over cos(a), along the normal
            rel = point(f, u, v) - f.origin
            bend_radius = float(np.linalg.norm(rel - (rel @ f.axis) * f.axis) / np.cos(f.semi_angle))
        inside = bend_radius if concave else bend_radius - sheet.thickness
        if inside < -1e-9:
            raise InputError(f"{name}: face {i} bends tighter than the sheet is thick (radius "
                             f"{bend_radius:g} mm, thickness {sheet.thickness:g} mm): not a sheet")
        out[i] = Curvature(concave, float(bend_radius), float(max(inside, 0.0)))
    return out


@dataclass(frozen=True)
class BendGroup:
    """One bend: joined cylinder (or cone) faces of one axis, radius and angle.

    Attributes
    ----------
    faces : tuple of int
    kind : str
        ``"cylinder"`` or ``"cone"``.
    angle : float
        Degrees the sheet turns in the bend.
    inside_radius : float
        mm.
    allowance : float
        The developed width of the bend zone, mm.
    neutral_radius : float
        A cylindrical bend's neutral radius, ``allowance / angle`` (mm); 0 for a cone.
    direction : str
        ``"up"`` or ``"down"``.
    flanged : bool
        A flat face on both sides.
    k_factor : float or None
        The K-factor it was developed with (``k_factor``, or the material table's for its inside radius); None
        when a bend table gave its allowance.
    """

    faces: tuple
    kind: str
    angle: float
    inside_radius: float
    allowance: float
    neutral_radius: float
    direction: str
    flanged: bool
    k_factor: float | None = None


def _same_bend(fa: SheetFace, fb: SheetFace) -> bool:
    if fb.kind != fa.kind or abs(fb.radius - fa.radius) > 1e-6 or abs(fb.semi_angle - fa.semi_angle) > 1e-9:
        return False
    return abs(abs(fb.axis @ fa.axis) - 1) <= 1e-9 and np.linalg.norm(np.cross(fb.origin - fa.origin, fa.axis)) <= 1e-6


def group_bends(faces: tuple, sheet: SheetModel, curvature: dict, opts: UnfoldOptions, name: str) -> tuple:
    """The bends of the skin, each developed to its neutral width (cones: see :func:`_cone_bend`)."""
    from OCP.BRepTools import BRepTools

    groups, seen = [], set()
    for i in sorted(curvature):
        if i in seen:
            continue
        group, stack = [i], [i]
        seen.add(i)
        while stack:
            a = stack.pop()
            for b, _ in sheet.neighbours[a]:
                if b not in seen and _same_bend(faces[a], faces[b]):
                    seen.add(b)
                    group.append(b)
                    stack.append(b)
        groups.append(tuple(sorted(group)))
    out = []
    for group in groups:
        first = faces[group[0]]
        bend = curvature[group[0]]
        sides = sum(1 for i in group for j, _ in sheet.neighbours[i] if faces[j].kind == "plane")
        direction = "up" if bend.concave else "down"
        k = opts.k_factor_at(sheet.thickness, bend.inside_radius,  # the material's K for its r/t, else k_factor
                             what=f"{name}: the bend at faces {', '.join(map(str, group))}")
        if first.kind == "cone":
            angle, allowance = _cone_bend(faces, group, curvature, sheet, opts, k, name)
            out.append(BendGroup(group, "cone", angle, bend.inside_radius, allowance, 0.0, direction, sides >= 2, k))
            continue
        spans = []
        for i in group:
            u0, u1, _, _ = BRepTools.UVBounds_s(faces[i].face)
            spans.append(u1 - u0)
        angle = float(np.degrees(max(spans)))
        r_in = bend.inside_radius
        if opts.bend_table is not None:
            allowance, k = opts.bend_table.allowance(sheet.thickness, r_in, angle), None
        else:
            allowance = np.radians(angle) * (r_in + k * sheet.thickness)
        out.append(BendGroup(group, "cylinder", angle, r_in, float(allowance), float(allowance / np.radians(angle)),
                             direction, sides >= 2, k))
    return tuple(out)


def _cone_bend(faces, group, curvature, sheet, opts, k_factor, name) -> tuple:
    """A conical bend's angle (the turn of its normal across its middle) and developed width (across its
    middle, on its neutral cone, ``k_factor`` t from the inside skin)."""
    from OCP.BRepTools import BRepTools

    if opts.bend_table is not None:
        raise InputError(f"{name}: faces {', '.join(map(str, group))} are a conical bend; a bend table gives "
                         f"cylindrical bends only (use the K-factor)")
    first = faces[group[0]]
    fmap = _cone_map(first, curvature[group[0]], sheet.thickness, k_factor)
    u0, u1, v0, v1 = BRepTools.UVBounds_s(first.face)
    vm = 0.5 * (v0 + v1)
    angle = float(np.degrees(np.arccos(np.clip(normal(first, u0, vm) @ normal(first, u1, vm), -1.0, 1.0))))
    ends = fmap.local(np.array([[u0, vm], [u1, vm]]))
    s_mid = float(np.linalg.norm(ends[0]))
    return angle, float(s_mid * abs(u1 - u0) * np.sin(abs(first.semi_angle)))


@dataclass(frozen=True, eq=False)
class FaceMap:
    """A skin face's parameters ``(u, v)`` to its own flat coordinates, mm (before it is placed).

    Attributes
    ----------
    face : SheetFace
    scale : (2,) float64
        Plane and cylinder: the flat is ``(scale[0] u, scale[1] v)``.
    offset : float
        Cone: the neutral surface lies this far from the skin, towards the convex side, mm.
    mirror : float
        Cone: -1 when the polar development is flipped to keep the skin's orientation.
    meshed : MeshedFace or None
        A face no plane, cylinder or cone: its meshed development.
    """

    face: SheetFace
    scale: np.ndarray | None = None
    offset: float = 0.0
    mirror: float = 1.0
    meshed: MeshedFace | None = None

    @property
    def kind(self) -> str:
        return self.face.kind

    def local(self, uv: np.ndarray) -> np.ndarray:
        """(k, 2) parameters to the face's own flat coordinates, mm: linear on planes and cylinders; on a
        cone, polar about the apex (distance from it along the generator, of the neutral surface; angle
        ``u sin a``)."""
        uv = np.asarray(uv, dtype=np.float64).reshape(-1, 2)
        f = self.face
        if self.meshed is not None:
            return self.meshed.at(np.array([point(f, u, v) for u, v in uv]).reshape(-1, 3))
        if f.kind != "cone":
            return uv * self.scale
        a = abs(f.semi_angle)
        s = np.abs(uv[:, 1] + f.radius / np.sin(f.semi_angle)) + self.offset / np.tan(a)
        phi = uv[:, 0] * np.sin(a)
        return np.column_stack([s * np.cos(phi), self.mirror * s * np.sin(phi)])


def _cone_map(f: SheetFace, bend: Curvature, thickness: float, k_factor: float) -> FaceMap:
    offset = k_factor * thickness if bend.concave else -(1 - k_factor) * thickness
    fmap = FaceMap(f, offset=offset)
    u, v = uv_mid(f.face)
    h = 1e-4 * max(1.0, abs(v))
    jac = np.vstack([fmap.local([[u + 1e-6, v]]) - fmap.local([[u - 1e-6, v]]),
                     fmap.local([[u, v + h]]) - fmap.local([[u, v - h]])])
    return replace(fmap, mirror=handedness(f, u, v) * float(np.sign(np.linalg.det(jac))))


def face_maps(faces: tuple, sheet: SheetModel, curvature: dict, bends: tuple, meshed: dict, k_factor: float) -> dict:
    """``{face: FaceMap}`` of every skin face (a cone's neutral surface at its bend's K-factor, else ``k_factor``)."""
    neutral = {i: b.neutral_radius for b in bends if b.kind == "cylinder" for i in b.faces}
    k_of = {i: b.k_factor for b in bends if b.k_factor is not None for i in b.faces}
    out = {}
    for i in sorted(sheet.skin):
        f = faces[i]
        if f.kind == "other":
            out[i] = FaceMap(f, meshed=meshed[i])
        elif f.kind == "cone":
            out[i] = _cone_map(f, curvature[i], sheet.thickness, k_of.get(i, k_factor))
        else:
            u, v = uv_mid(f.face)
            across = neutral[i] if f.kind == "cylinder" else 1.0
            out[i] = FaceMap(f, scale=np.array([handedness(f, u, v) * across, 1.0]))
    return out
