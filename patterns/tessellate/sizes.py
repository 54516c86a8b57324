"""Sizes: each face's development table and target edge length, from the part's area, curvature and tolerances."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import CadError
from ..measure import weighted_percentile
from ..mesh import MAX_TRIANGLES, extent
from .topology import Topology

__all__ = ["DEFAULT_TRIANGLES", "FACES_TRIANGLES", "LEAST_FACE_TRIANGLES", "MAX_TRIANGLES", "MIN_FACE_TRIANGLES", "Development", "Sizes", "face_sizes"]

DEFAULT_TRIANGLES = 4000
"""With no ``max_edge``, the target edge length gives about this many triangles over
the whole shape's area (before curvature refines it)..."""

MIN_FACE_TRIANGLES = 1000
"""... and each face at least about this many of its own ..."""

FACES_TRIANGLES = 200_000
"""... unless the part has so many faces that their minimums together would make more than this: then each
face's minimum is this over the number of faces (a plate with 5,000 holes: 40 a face, not 5 million triangles
in all), but never below :data:`LEAST_FACE_TRIANGLES`."""

LEAST_FACE_TRIANGLES = 20
"""The least of a face's own triangles on a part of very many faces."""


_GRID = 41  # samples per parameter direction of a face's development table


def _table(surface, us: np.ndarray, vs: np.ndarray) -> tuple:
    """``(points (n, n, 3), normals (n, n, 3))`` of a face's surface at ``vs`` x ``us`` (rows by v), mm; a
    normal NaN where the surface has none (a cone's apex).  Planes and cylinders in closed form, in one numpy
    pass (the same numbers as OpenCascade's ``D1`` to round-off: a plate's 5,000 hole walls took 9 s point by
    point); any other surface point by point through ``D1``."""
    from OCP.GeomAbs import GeomAbs_Cylinder, GeomAbs_Plane
    from OCP.gp import gp_Pnt, gp_Vec

    kind = surface.GetType()
    if kind in (GeomAbs_Plane, GeomAbs_Cylinder):
        frame = (surface.Plane() if kind == GeomAbs_Plane else surface.Cylinder()).Position()
        o, x, y, z = (np.array([a.X(), a.Y(), a.Z()]) for a in (frame.Location(), frame.XDirection(),
                                                                 frame.YDirection(), frame.Direction()))
        u, v = np.meshgrid(us, vs)  # (n, n), rows by v
        if kind == GeomAbs_Plane:  # P = O + u X + v Y
            pts = o + u[..., None] * x + v[..., None] * y
            du, dv = np.broadcast_to(x, pts.shape), np.broadcast_to(y, pts.shape)
        else:  # P = O + R (cos u X + sin u Y) + v Z
            r = surface.Cylinder().Radius()
            radial = np.cos(u)[..., None] * x + np.sin(u)[..., None] * y
            pts = o + r * radial + v[..., None] * z
            du = r * (np.cos(u)[..., None] * y - np.sin(u)[..., None] * x)
            dv = np.broadcast_to(z, pts.shape)
        nrm = np.cross(du, dv)
        mag = np.linalg.norm(nrm, axis=2)
        ok = mag > 1e-12 * (np.linalg.norm(du, axis=2) * np.linalg.norm(dv, axis=2) + 1e-300)
        normals = np.full(pts.shape, np.nan)
        normals[ok] = nrm[ok] / mag[ok, None]
        return pts, normals
    pts = np.empty((len(vs), len(us), 3))
    normals = np.full((len(vs), len(us), 3), np.nan)
    p, du, dv = gp_Pnt(), gp_Vec(), gp_Vec()
    for j, v in enumerate(vs):
        for i, u in enumerate(us):
            surface.D1(u, v, p, du, dv)
            pts[j, i] = (p.X(), p.Y(), p.Z())
            nrm = du.Crossed(dv)
            mag = nrm.Magnitude()
            if mag > 1e-12 * (du.Magnitude() * dv.Magnitude() + 1e-300):
                normals[j, i] = (nrm.X() / mag, nrm.Y() / mag, nrm.Z() / mag)
    return pts, normals


class Development:
    """A near-isometric 2D layout of a face's parameter domain, for meshing.

    ``y`` is the arc length along the v direction on the middle u line, ``x``
    the arc length along each u line from the middle u.  Exact on planes and
    cylinders, keeps lengths along parameter lines everywhere else.
    """

    def __init__(self, surface, u0, u1, v0, v1, n=_GRID):
        self.u = np.linspace(u0, u1, n)
        self.v = np.linspace(v0, v1, n)
        pts, normals = _table(surface, self.u, self.v)
        self.points = pts
        self.normals = normals
        row = np.linalg.norm(np.diff(pts, axis=1), axis=2)  # (n, n-1) along u
        x = np.concatenate([np.zeros((n, 1)), np.cumsum(row, axis=1)], axis=1)
        mid = n // 2
        self.x = x - x[:, [mid]]
        col = np.linalg.norm(np.diff(pts[:, mid], axis=0), axis=1)
        self.y = np.concatenate([[0.0], np.cumsum(col)])
        # Keep y strictly increasing (a degenerate column would stall it).
        span = max(float(self.y[-1]), 1e-12)
        self.y = self.y + np.linspace(0.0, 1e-9 * span, n)

    def curvature(self) -> float:
        """Normal curvature between neighbouring samples, 1/mm (0 if flat): the 95th
        percentile by surface area, so that a small region where it has no bound (a
        cone's apex) does not make the whole face fine.  By area, not by sample: the
        samples are even in the parameters, and a cone's rows near the apex hold many
        samples and little area."""
        k, w = [], []
        size = extent(self.points.reshape(-1, 3))
        p = self.points
        cell = np.linalg.norm(np.cross(p[1:, 1:] - p[:-1, :-1], p[1:, :-1] - p[:-1, 1:]), axis=2) / 2  # (n-1, n-1)
        node = np.zeros(p.shape[:2])
        for dj, di in ((0, 0), (0, 1), (1, 0), (1, 1)):
            node[dj:dj + cell.shape[0], di:di + cell.shape[1]] += cell / 4
        for axis in (0, 1):
            dn = np.diff(self.normals, axis=axis)
            dp = np.diff(p, axis=axis)
            ang = np.linalg.norm(dn, axis=2)
            dist = np.linalg.norm(dp, axis=2)
            area = node[1:] + node[:-1] if axis == 0 else node[:, 1:] + node[:, :-1]
            ok = np.isfinite(ang) & (dist > 1e-6 * size)
            if ok.any():
                k.append((ang[ok] / dist[ok]).ravel())
                w.append(area[ok].ravel())
        if not k:
            return 0.0
        k, w = np.concatenate(k), np.concatenate(w)
        if not w.sum() > 0:  # no area to weigh by (a degenerate table): by sample
            return float(np.percentile(k, 95))
        return weighted_percentile(k, w, 95)

    def forward(self, uv: np.ndarray) -> np.ndarray:
        """(k, 2) parameters -> (k, 2) development coordinates, mm."""
        u, v = uv[:, 0], uv[:, 1]
        n = len(self.u)
        fu = np.clip((u - self.u[0]) / (self.u[-1] - self.u[0]) * (n - 1), 0, n - 1 - 1e-12)
        fv = np.clip((v - self.v[0]) / (self.v[-1] - self.v[0]) * (n - 1), 0, n - 1 - 1e-12)
        i, j = fu.astype(int), fv.astype(int)
        a, b = fu - i, fv - j
        x = ((1 - a) * (1 - b) * self.x[j, i] + a * (1 - b) * self.x[j, i + 1]
             + (1 - a) * b * self.x[j + 1, i] + a * b * self.x[j + 1, i + 1])
        y = np.interp(v, self.v, self.y)
        return np.column_stack([x, y])

    def inverse(self, xy: np.ndarray) -> np.ndarray:
        """(k, 2) development coordinates -> (k, 2) parameters (inverse of :meth:`forward`)."""
        n = len(self.u)
        v = np.interp(xy[:, 1], self.y, self.v)
        fv = np.clip((v - self.v[0]) / (self.v[-1] - self.v[0]) * (n - 1), 0, n - 1 - 1e-12)
        j = fv.astype(int)
        b = (fv - j)[:, None]
        rows = (1 - b) * self.x[j] + b * self.x[j + 1]  # (k, n), increasing along u
        x = xy[:, 0]
        i = np.clip(np.sum(rows < x[:, None], axis=1) - 1, 0, n - 2)
        lo = rows[np.arange(len(x)), i]
        hi = rows[np.arange(len(x)), i + 1]
        with np.errstate(divide="ignore", invalid="ignore"):
            a = np.where(hi > lo, (x - lo) / (hi - lo), 0.5)
        u = self.u[i] + np.clip(a, 0, 1) * (self.u[1] - self.u[0])
        return np.column_stack([u, v])


@dataclass(frozen=True, eq=False)
class Sizes:
    """How finely each face is meshed.

    Attributes
    ----------
    h : float
        The target edge length, mm (``max_edge``, or from the part's area).
    face_h : tuple of float
        Per face, mm: ``h``, shorter where curvature and the tolerances ask.
    surfaces : tuple of OCP ``BRepAdaptor_Surface``
    developments : tuple of Development
        Per face, the near-isometric layout of its parameter domain.
    """

    h: float
    face_h: tuple
    surfaces: tuple
    developments: tuple


def _spacing(area: float, triangles: float) -> float:
    """The edge length that fills ``area`` with about ``triangles`` equilateral triangles, mm."""
    return float(np.sqrt(4 * area / (np.sqrt(3) * triangles)))


def face_sizes(topology: Topology, *, max_edge, chord_tolerance: float, angular_tolerance: float) -> Sizes:
    """Each face's development and edge length; CadError for a face without bounds or area, or too many triangles."""
    from OCP.BRepAdaptor import BRepAdaptor_Surface
    from OCP.BRepGProp import BRepGProp
    from OCP.BRepTools import BRepTools
    from OCP.GProp import GProp_GProps

    name = topology.name
    areas, surfaces, devs = [], [], []
    for k, face in enumerate(topology.faces):
        props = GProp_GProps()
        BRepGProp.SurfaceProperties_s(face, props)
        areas.append(abs(props.Mass()))
        surface = BRepAdaptor_Surface(face)
        try:
            u0, u1, v0, v1 = BRepTools.UVBounds_s(face)
        except Exception as exc:  # noqa: BLE001
            raise CadError(f"{name}: face {k} has no parameter bounds ({exc})") from None
        if not (np.isfinite([u0, u1, v0, v1]).all() and u1 > u0 and v1 > v0):
            raise CadError(f"{name}: face {k} has empty or infinite parameter bounds")
        surfaces.append(surface)
        devs.append(Development(surface, u0, u1, v0, v1))
    total = float(sum(areas))
    if not total > 0:
        raise CadError(f"{name}: the faces have no area")
    h = float(max_edge) if max_edge is not None else _spacing(total, DEFAULT_TRIANGLES)
    face_h = []
    least = max(LEAST_FACE_TRIANGLES, min(MIN_FACE_TRIANGLES, FACES_TRIANGLES / len(areas)))
    for dev, area in zip(devs, areas):
        kappa = dev.curvature()
        # By default a small face still gets MIN_FACE_TRIANGLES of its own (fewer on a part of many faces).
        hf = h if max_edge is not None else min(h, _spacing(area, least))
        if kappa > 0:
            hf = min(hf, np.sqrt(8 * chord_tolerance / kappa), angular_tolerance / kappa)
        face_h.append(max(hf, h / 50))
    estimate = sum(a / (0.433 * hf * hf) for a, hf in zip(areas, face_h))
    if estimate > MAX_TRIANGLES:
        raise CadError(f"{name}: meshing at max_edge {min(face_h):.3g} mm (chord tolerance {chord_tolerance:g} mm) "
                       f"would make about {estimate:.3g} triangles, over the limit of {MAX_TRIANGLES:.0e}; "
                       f"use a larger max_edge or chord_tolerance")
    return Sizes(h=h, face_h=tuple(face_h), surfaces=tuple(surfaces), developments=tuple(devs))
