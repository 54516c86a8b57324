"""Exact unrolling of planes, cylinders and cones, and the neutral surface of a sheet.

A plane, a cylinder and a cone are developable: each point has exact flat
coordinates, computed here from its 3D position, with no mesh engine and no
error beyond round-off.

* plane: coordinates in the plane's own frame;
* cylinder of radius ``R``: ``(R u, v)``, ``u`` the angle around the axis and
  ``v`` the height along it;
* cone with apex ``A`` and half-angle ``a``: polar coordinates ``(s, u sin a)``,
  ``s`` the distance from the apex along the generator.

Sheet thickness: the blank is cut so that the *neutral* surface -- the one that
neither stretches nor shrinks when the sheet is bent, at ``k t`` from the inside
skin (``k`` the K-factor, ``t`` the thickness) -- has the modelled size.  Its
offset from the modelled skin, :func:`neutral_offset`, is measured towards the
convex side (away from the axis of a cylinder or cone).  A plane's development
does not change with an offset; a cylinder's radius becomes ``R + d``; a cone
keeps its axis and angle and its apex moves along the axis.
"""

from __future__ import annotations

import numpy as np

from ..errors import FlattenError, InputError
from ..measure import signed_areas
from ..mesh import _readonly, validate_mesh
from ..model import SurfaceKind
from ..options import check_number
from ..pattern import Flattening
from ..predicates import overlap_verdict
from .settings import REFERENCES

__all__ = ["REFERENCES", "develop", "developed", "neutral_offset", "offset_along_normals", "offset_points"]

def neutral_offset(thickness: float, k_factor: float, reference: str, *, name: str = "pattern") -> float:
    """Signed distance from the modelled skin to the neutral surface, mm (positive: convex side).

    Parameters
    ----------
    thickness : float
        Sheet thickness, mm (>= 0).
    k_factor : float
        Position of the neutral surface from the inside skin, as a fraction of
        the thickness (0 <= k <= 1; 0.5 is the middle).
    reference : {"inside", "outside", "mid"}
        The skin the model shows: the inside of the bends, the outside, or the
        middle of the sheet.
    """
    thickness = check_number(thickness, "thickness (mm)", low=0, name=name)
    k_factor = check_number(k_factor, "k_factor", low=0, high=1, name=name)
    if reference not in REFERENCES:
        raise InputError(f"{name}: reference must be one of {', '.join(REFERENCES)}, got {reference!r}")
    inside = {"inside": 0.0, "outside": -thickness, "mid": -0.5 * thickness}[reference]
    return float(inside + k_factor * thickness)


def _radial(surface, points):
    """Axial height, radial distance and angle of points about the surface's axis."""
    rel = points - surface.origin
    x, y = _along(rel, surface.x_dir), _along(rel, surface.y_dir)
    return _along(rel, surface.axis), np.hypot(x, y), np.arctan2(y, x)


def _along(rel: np.ndarray, direction) -> np.ndarray:
    """(n,) each row of ``rel`` (n, 3) dotted with ``direction`` (3,): ``einsum``, not a BLAS product, whose
    rounding follows the CPU's kernels (fused multiply-adds on one, not on another)."""
    return np.einsum("ij,j->i", rel, np.asarray(direction, dtype=np.float64))


def offset_points(surface, points: np.ndarray, offset: float) -> np.ndarray:
    """Move points on an analytic surface by ``offset`` along its normal (towards the convex side)."""
    if offset == 0.0 or surface.kind is SurfaceKind.PLANE:
        return np.array(points, dtype=np.float64)
    rel = points - surface.origin
    h = _along(rel, surface.axis)
    radial = rel - np.outer(h, surface.axis)
    r = np.linalg.norm(radial, axis=1, keepdims=True)
    out_dir = radial / np.maximum(r, 1e-300)
    if surface.kind is SurfaceKind.CYLINDER:
        normal = out_dir
    else:
        a = surface.semi_angle  # the generator climbs by cos a along the axis for sin a outwards
        normal = out_dir * np.cos(a) - np.outer(np.full(len(points), np.sin(a)), surface.axis)
        normal *= np.sign(np.cos(a))
    return points + offset * normal


def develop(surface, points: np.ndarray, param: np.ndarray | None = None, *, offset: float = 0.0) -> np.ndarray:
    """Exact flat coordinates of points on a plane, cylinder or cone.

    Parameters
    ----------
    surface : patterns.Surface
    points : (n, 3) float64, mm
        On the surface (or on its offset by :func:`offset_points`: the same
        formulas hold for the offset cylinder and cone).
    param : (n, 2) float64, optional
        Approximate surface parameters, to pick the right turn of the angle
        ``u`` for points that appear twice (both sides of a seam line).
    offset : float
        The points lie on the surface offset by this much (mm, towards the
        convex side): a cone's apex then moves along its axis.

    Returns
    -------
    (n, 2) float64, mm
        Counter-clockwise as the surface's parametrisation is; the caller
        mirrors if its triangles come out clockwise.
    """
    points = np.asarray(points, dtype=np.float64)
    if surface.kind is SurfaceKind.GENERAL_CONE:
        return _develop_general_cone(surface, points)
    if surface.kind is SurfaceKind.PLANE:
        rel = points - surface.origin
        return np.column_stack([_along(rel, surface.x_dir), _along(rel, surface.y_dir)])
    h, r, angle = _radial(surface, points)
    if param is not None:
        # The same 3D point on both sides of a seam: atan2 cannot tell; the
        # parameter says which turn it is on.
        angle = angle + 2 * np.pi * np.round((param[:, 0] - angle) / (2 * np.pi))
    else:
        angle = np.unwrap(angle)
    if surface.kind is SurfaceKind.CYLINDER:
        return np.column_stack([np.median(r) * angle, h])  # the radius is the same for all, to round-off
    a = surface.semi_angle
    sin_a = np.sin(a)
    # Apex: where the radius vanishes (radius + v sin a = 0, at height v cos a);
    # the offset cone's apex lies offset / sin a lower along the axis.
    apex_h = -surface.radius / np.tan(a) - offset / sin_a
    s = np.hypot(r, h - apex_h)
    theta = angle * abs(sin_a)
    return np.column_stack([s * np.cos(theta), s * np.sin(theta)])


def _develop_general_cone(surface, points: np.ndarray) -> np.ndarray:
    """Polar coordinates about the apex: the distance from it, and the angle turned
    so far by the line from the apex -- the length of the line's direction's path
    on the unit sphere, which the development keeps."""
    apex = surface.origin
    table = surface.directrix - apex
    table = table / np.linalg.norm(table, axis=1, keepdims=True)
    step = np.arccos(np.clip((table[1:] * table[:-1]).sum(axis=1), -1.0, 1.0))
    theta = np.concatenate([[0.0], np.cumsum(step)])
    rel = points - apex
    s = np.linalg.norm(rel, axis=1)
    out = np.zeros((len(points), 2))
    at_apex = s <= 1e-12 * max(float(s.max()), 1.0)
    u = rel[~at_apex] / s[~at_apex, None]
    # Nearest sample of the directrix's direction, then the segment beside it that the
    # direction lies nearest; on it, the angle turned from the segment's start (exact where the
    # cone is flat between two rulings: the direction then lies on their great circle).
    k = np.argmax(np.einsum("ij,kj->ik", u, table), axis=1)
    k = np.clip(k, 1, len(table) - 2)
    for shift in (-1, 0):
        a, b = table[k + shift], table[k + shift + 1]
        ab = b - a
        t = np.clip(((u - a) * ab).sum(axis=1) / np.maximum((ab * ab).sum(axis=1), 1e-300), 0.0, 1.0)
        d = np.linalg.norm(a + t[:, None] * ab - u, axis=1)
        within = np.arccos(np.clip((u * a).sum(axis=1), -1.0, 1.0))
        value = theta[k + shift] + np.where(t > 0.0, np.minimum(within, step[k + shift]), 0.0)
        if shift == -1:
            best_d, best = d, value
        else:
            better = d < best_d
            best = np.where(better, value, best)
    out[~at_apex] = np.column_stack([s[~at_apex] * np.cos(best), s[~at_apex] * np.sin(best)])
    return out


def developed(panel, offset: float, name: str) -> Flattening:
    """The exact development of a planar, cylindrical or conical panel (of its offset by ``offset``)."""
    vertices = offset_points(panel.surface, panel.vertices, offset)
    uv = develop(panel.surface, vertices, panel.param, offset=offset)
    if np.sum(signed_areas(uv, panel.faces)) < 0:
        uv[:, 0] = -uv[:, 0]  # the parametrisation runs the other way round: mirror (an isometry)
    if not np.all(np.isfinite(uv)):
        raise FlattenError(f"{name}: the exact development gave non-finite coordinates")
    v, f, conn = validate_mesh(vertices, panel.faces, name=name)
    return Flattening(uv=_readonly(uv), vertices=_readonly(v), faces=_readonly(f), loops=conn.loops,
                      method="exact", seed_face=-1, overlap=overlap_verdict(uv, f, conn.loops), start="analytic")


def offset_along_normals(panel, offset: float) -> np.ndarray:
    """Panel vertices moved by ``offset`` along their area-weighted normals (freeform sheet thickness)."""
    v, f = panel.vertices, panel.faces
    n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])  # length = 2 x area: area-weighted
    vn = np.zeros_like(v)
    for k in range(3):
        np.add.at(vn, f[:, k], n)
    vn /= np.maximum(np.linalg.norm(vn, axis=1, keepdims=True), 1e-300)
    return v + offset * vn
