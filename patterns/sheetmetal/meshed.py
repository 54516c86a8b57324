"""A face of a sheet that is no plane, cylinder or cone: meshed, moved to its neutral surface, flattened.

Such a face (a bend drawn as a spline, a freeform dimple) has no exact
development.  :func:`meshed_face` meshes its skin (well-shaped triangles, half
the thickness across), moves the mesh to the neutral surface (``K t`` into the
sheet from the concave skin, ``(1 - K) t`` from the convex one) and flattens
it with the engine; :meth:`MeshedFace.at` maps points of the face to the flat
through the nearest triangle.  The blank reports every such face with its
strain (``meshed-face``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..flattening.engine import flatten_mesh
from ..measure import signed_areas
from ..pattern import Flattening
from ..tessellate import mesh_shape
from .faces import SheetFace, normal, point, uv_mid

__all__ = ["MeshedFace", "meshed_face"]


@dataclass(frozen=True, eq=False)
class MeshedFace:
    """A face's skin meshed and flattened.

    Attributes
    ----------
    vertices : (n, 3) float64, mm
        The skin's mesh.
    triangles : (m, 3) int64
    uv : (n, 2) float64, mm
        The mesh's vertices flattened (of the neutral surface).
    flattening : patterns.Flattening
        The engine's result, with its strain.
    volume : float
        The sheet behind the face, mm³.
    """

    vertices: np.ndarray
    triangles: np.ndarray
    uv: np.ndarray
    flattening: Flattening
    volume: float

    @cached_property
    def _tree(self):
        from scipy.spatial import cKDTree

        return cKDTree(self.vertices[self.triangles].mean(axis=1))

    def at(self, points: np.ndarray) -> np.ndarray:
        """(k, 3) points on the face (on its mesh to the tessellation's tolerance) to (k, 2) flat, mm:
        through the nearest triangle (among those with the nearest centroids), barycentrically."""
        vertices, tris = self.vertices, self.triangles
        cand = self._tree.query(points, k=min(12, len(tris)))[1].reshape(len(points), -1)
        tri = vertices[tris[cand]]  # (p, k, 3, 3)
        a = tri[..., 0, :]
        e0, e1, e2 = tri[..., 1, :] - a, tri[..., 2, :] - a, points[:, None, :] - a
        d00, d01, d11 = (e0 * e0).sum(-1), (e0 * e1).sum(-1), (e1 * e1).sum(-1)
        d20, d21 = (e2 * e0).sum(-1), (e2 * e1).sum(-1)
        den = d00 * d11 - d01 * d01
        v, w = (d11 * d20 - d01 * d21) / den, (d00 * d21 - d01 * d20) / den
        bary = np.clip(np.stack([1 - v - w, v, w], axis=-1), 0, None)
        bary /= bary.sum(axis=-1, keepdims=True)
        near = np.linalg.norm(np.einsum("pkj,pkjd->pkd", bary, tri) - points[:, None, :], axis=-1).argmin(axis=1)
        rows = np.arange(len(points))
        return np.einsum("pj,pjd->pd", bary[rows, near], self.uv[tris[cand[rows, near]]])


K_FLAT = 0.5
"""The K-factor of a meshed face that is flat at its middle, or bent gentler than :data:`FLAT_RT`: as r/t grows
the neutral layer goes to the middle of the sheet (every published table's last class is 0.5)."""
FLAT_RT = 100.0
"""An inside radius over this many thicknesses is as good as flat for a material's K-factor."""


def inside_radius(f: SheetFace, thickness: float, concave: bool) -> float:
    """A face's inside bend radius at its middle, mm: its tightest radius of curvature there, less the
    thickness when the skin is on the outside of the bend (0 where it is flat)."""
    from OCP.BRepLProp import BRepLProp_SLProps

    u, v = uv_mid(f.face)
    props = BRepLProp_SLProps(f.adaptor, u, v, 2, 1e-9)
    curvature = max(abs(props.MaxCurvature()), abs(props.MinCurvature())) if props.IsCurvatureDefined() else 0.0
    if curvature <= 1e-12:
        return float("inf")
    return max(1.0 / curvature - (0.0 if concave else thickness), 0.0)


def meshed_face(f: SheetFace, thickness: float, k_factor: float | Callable, name: str) -> MeshedFace:
    """Mesh and flatten a face that is not developable as a plane, cylinder or cone.

    ``k_factor``: the K-factor, or ``k_factor(inside radius mm) -> K`` (a material's), asked at the face's
    middle (:func:`inside_radius`).
    """
    import trimesh

    # well-shaped triangles, half the thickness across (fewer, larger on a large face: about 2000)
    edge = max(thickness / 2, np.sqrt(f.area / 1000.0))
    (panel,) = mesh_shape(f.face, max_edge=edge, chord_tolerance=0.002, name=f"{name} face {f.index}").panels
    vertices, tris = np.asarray(panel.vertices), np.asarray(panel.faces)
    normals = np.asarray(trimesh.Trimesh(vertices, tris, process=False).vertex_normals)
    u, v = uv_mid(f.face)
    concave = float(np.mean((vertices - point(f, u, v)) @ normal(f, u, v))) > 0  # curving towards its normal
    radius = inside_radius(f, thickness, concave)
    if callable(k_factor):  # a material's K; flat at its middle (or gentler than any table's r/t): the mid-plane
        k = K_FLAT if not np.isfinite(radius) or radius > FLAT_RT * thickness else k_factor(radius)
    else:
        k = k_factor
    into = k * thickness if concave else (1 - k) * thickness  # the neutral surface, into the sheet
    result = flatten_mesh(vertices - into * normals, tris, name=f"{name} face {f.index}")
    uv = np.array(result.uv)
    if signed_areas(uv, tris).sum() < 0:
        uv[:, 1] *= -1

    def area(depth):  # of the skin moved ``depth`` into the sheet
        tri = (vertices - depth * normals)[tris]
        return 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1).sum()

    volume = thickness * (area(0) + 4 * area(thickness / 2) + area(thickness)) / 6  # Simpson across the sheet
    return MeshedFace(vertices, tris, uv, result, float(volume))
