"""Stage 1 of an unfold: every CAD face of the solid, recognised by the mesher's surface recogniser.

A :class:`SheetFace` is one face of the folded solid with the developable
surface :func:`patterns.tessellate.recognise.surface_of` finds for it (a
plane, a cylinder or a cone: its frame, radius and half-angle), or none (a
spline bend, a freeform dimple: it is meshed later).  The small functions
below read a face's normal, points and parameters through OpenCascade.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..model import Surface, SurfaceKind
from ..tessellate.recognise import surface_of
from ..tessellate.topology import Topology

if TYPE_CHECKING:
    from OCP.BRepAdaptor import BRepAdaptor_Surface
    from OCP.TopoDS import TopoDS_Edge, TopoDS_Face

__all__ = ["SheetFace", "edge_uv", "handedness", "normal", "point", "recognise", "uv_mid"]

KINDS = {SurfaceKind.PLANE: "plane", SurfaceKind.CYLINDER: "cylinder", SurfaceKind.CONE: "cone"}
"""The surfaces an unfold develops exactly; any other face is ``"other"`` (meshed)."""


@dataclass(frozen=True, eq=False)
class SheetFace:
    """One face of the folded solid.

    Attributes
    ----------
    index : int
        Its number (``shape.faces()`` order).
    face : OCP ``TopoDS_Face``
    adaptor : OCP ``BRepAdaptor_Surface``
        Its surface, for points and derivatives.
    surface : patterns.Surface or None
        Plane, cylinder or cone (frame, radius, half-angle); None for any other surface.
    area : float
        mm².
    """

    index: int
    face: TopoDS_Face
    adaptor: BRepAdaptor_Surface
    surface: Surface | None
    area: float

    @property
    def kind(self) -> str:
        """``"plane"``, ``"cylinder"``, ``"cone"`` or ``"other"``."""
        return "other" if self.surface is None else KINDS.get(self.surface.kind, "other")

    @property
    def axis(self) -> np.ndarray:
        return self.surface.axis

    @property
    def origin(self) -> np.ndarray:
        return self.surface.origin

    @property
    def radius(self) -> float:
        """A cylinder's radius, a cone's reference radius, mm (0 for a plane)."""
        return float(self.surface.radius or 0.0) if self.surface is not None else 0.0

    @property
    def semi_angle(self) -> float:
        """A cone's signed half-angle (OpenCascade's), radians; 0 otherwise."""
        return float(self.surface.semi_angle or 0.0) if self.surface is not None else 0.0


def recognise(topology: Topology) -> tuple:
    """Every face of the shape as a :class:`SheetFace`, in ``shape.faces()`` order."""
    from OCP.BRepAdaptor import BRepAdaptor_Surface
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    out = []
    for i, face in enumerate(topology.faces):
        adaptor = BRepAdaptor_Surface(face)
        props = GProp_GProps()
        BRepGProp.SurfaceProperties_s(face, props)
        surface = surface_of(adaptor, face)
        if surface is not None and surface.kind not in KINDS:
            surface = None
        out.append(SheetFace(i, face, adaptor, surface, float(props.Mass())))
    return tuple(out)


def normal(f: SheetFace, u: float, v: float) -> np.ndarray:
    """(3,) the face's outward unit normal at parameters ``(u, v)``."""
    from OCP.gp import gp_Pnt, gp_Vec
    from OCP.TopAbs import TopAbs_REVERSED

    # du x dv, turned over for a reversed face: what BRepGProp_Face.Normal gives, without building a new surface
    # adaptor (and its parameter box, linear in the face's edges) per call: a plate with 5000 holes took 2 ms a call
    p, du, dv = gp_Pnt(), gp_Vec(), gp_Vec()
    f.adaptor.D1(u, v, p, du, dv)
    n = np.cross([du.X(), du.Y(), du.Z()], [dv.X(), dv.Y(), dv.Z()])
    if f.face.Orientation() == TopAbs_REVERSED:
        n = -n
    return n / np.linalg.norm(n)


def point(f: SheetFace, u: float, v: float) -> np.ndarray:
    """(3,) the point at parameters ``(u, v)``, mm."""
    p = f.adaptor.Value(u, v)
    return np.array([p.X(), p.Y(), p.Z()])


def handedness(f: SheetFace, u: float, v: float) -> float:
    """+1 when ``du x dv`` is the face's outward normal, -1 when it is the inward one."""
    from OCP.gp import gp_Pnt, gp_Vec

    p, du, dv = gp_Pnt(), gp_Vec(), gp_Vec()
    f.adaptor.D1(u, v, p, du, dv)
    cross = np.cross([du.X(), du.Y(), du.Z()], [dv.X(), dv.Y(), dv.Z()])
    return 1.0 if cross @ normal(f, u, v) > 0 else -1.0


def uv_mid(face: TopoDS_Face) -> tuple:
    """The middle of a face's parameter box, ``(u, v)``."""
    from OCP.BRepTools import BRepTools

    u0, u1, v0, v1 = BRepTools.UVBounds_s(face)
    return 0.5 * (u0 + u1), 0.5 * (v0 + v1)


def edge_uv(edge: TopoDS_Edge, face: TopoDS_Face, n: int) -> np.ndarray:
    """(n, 2) parameters on ``face`` of ``n`` points along ``edge`` (its own direction)."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve2d

    c2 = BRepAdaptor_Curve2d(edge, face)
    t = np.linspace(c2.FirstParameter(), c2.LastParameter(), n)
    out = np.empty((n, 2))
    for k, tk in enumerate(t):
        p = c2.Value(float(tk))
        out[k] = p.X(), p.Y()
    return out
