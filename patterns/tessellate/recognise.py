"""Surface recognition: which CAD faces are developable, and how (plane, cylinder, cone, general cone)."""

from __future__ import annotations

import numpy as np

from ..mesh import extent
from ..model import Surface, SurfaceKind
from .remesh import evaluate

__all__ = ["surface_of"]


def surface_of(surface, face, dev=None):
    """The developable surface of a face: a plane, a cylinder, a cone, or any surface
    swept by straight lines from one point (an oblique cone, as in a square-to-round
    transition); else None."""
    from OCP.GeomAbs import GeomAbs_Cone, GeomAbs_Cylinder, GeomAbs_Plane

    kind = surface.GetType()
    if kind not in (GeomAbs_Plane, GeomAbs_Cylinder, GeomAbs_Cone):
        return _general_cone(surface, dev) if dev is not None else None
    if kind == GeomAbs_Plane:
        ax, extra = surface.Plane().Position(), {}
        kind = SurfaceKind.PLANE
    elif kind == GeomAbs_Cylinder:
        cyl = surface.Cylinder()
        ax, extra = cyl.Position(), {"radius": cyl.Radius()}
        kind = SurfaceKind.CYLINDER
    elif kind == GeomAbs_Cone:
        cone = surface.Cone()
        ax, extra = cone.Position(), {"radius": cone.RefRadius(), "semi_angle": cone.SemiAngle()}
        kind = SurfaceKind.CONE
    else:
        return None

    def vec(d):
        return np.array([d.X(), d.Y(), d.Z()])

    return Surface(kind=kind, origin=vec(ax.Location()), x_dir=vec(ax.XDirection()), y_dir=vec(ax.YDirection()),
                   axis=vec(ax.Direction()), **extra)


def _general_cone(surface, dev):
    """A surface made of straight lines through one point (apex), recognised on its
    parameter grid: one side of the grid collapses to a point and every grid line
    from there is straight.  Returns its apex and a dense sample of the opposite
    boundary (the directrix), or None."""

    pts = dev.points  # (nv, nu, 3): rows along u at fixed v
    size = extent(pts.reshape(-1, 3))
    if size <= 0:
        return None
    sides = {"v0": (pts[0], pts), "v1": (pts[-1], pts[::-1]),
             "u0": (pts[:, 0], pts.transpose(1, 0, 2)), "u1": (pts[:, -1], pts.transpose(1, 0, 2)[::-1])}
    for key, (edge, grid) in sides.items():
        if extent(edge) > 1e-9 * size:
            continue
        apex = edge.mean(axis=0)
        # grid[j] are the points at the j-th line parallel to the apex side; lines
        # from the apex run across j.  Straight: every point on its apex-to-far line.
        far = grid[-1]
        line = far - apex
        length = np.linalg.norm(line, axis=1)
        if np.any(length <= 1e-9 * size):
            return None
        unit = line / length[:, None]
        rel = grid - apex
        off = rel - (rel * unit[None]).sum(axis=2)[..., None] * unit[None]
        if np.abs(off).max() > 1e-7 * size:
            return None
        # The directrix: the far boundary, sampled densely on the surface.
        n = 2001
        if key in ("v0", "v1"):
            u = np.linspace(dev.u[0], dev.u[-1], n)
            v = np.full(n, dev.v[-1] if key == "v0" else dev.v[0])
        else:
            v = np.linspace(dev.v[0], dev.v[-1], n)
            u = np.full(n, dev.u[-1] if key == "u0" else dev.u[0])
        directrix = evaluate(surface, np.column_stack([u, v]))
        z = np.zeros(3)
        return Surface(kind=SurfaceKind.GENERAL_CONE, origin=apex, x_dir=z, y_dir=z, axis=z, directrix=directrix)
    return None
