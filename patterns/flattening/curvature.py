"""The surface's curvature as darts see it: where they meet, and how many it asks for.

:func:`gore_bound` is the number of darts (balanced gores) a panel's Gaussian
curvature asks for at a strain limit; :func:`crown_of` where the darts meet on
the flat layout.  :mod:`patterns.flattening.darts` plans from both, and the
report quotes the bound where the darts fall short
(:class:`patterns.DartSearch`).
"""

from __future__ import annotations

import numpy as np
from scipy.sparse.csgraph import dijkstra

from ..measure import angle_defects
from ..mesh import edge_graph, face_areas, unique_edges
from ..pattern import Flattening

__all__ = ["crown_of", "gore_bound", "vertex_areas"]


def crown_of(uv: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """(2,) float64: where darts meet on a flat layout ``uv`` ``(n, 2)`` mm, the centroid of the
    vertices weighted by their positive angle defects ``weights`` ``(n,)`` (their mean without any)."""
    total = float(np.sum(weights))
    return np.einsum("i,ij->j", weights, uv) / total if total > 0 else uv.mean(axis=0)  # no BLAS: its bits


def gore_bound(result: Flattening, limit: float, *, defects=None, crown=None) -> float:
    """How many darts a panel's curvature asks for at a strain limit: the gore bound.

    A gore of half-width ``w`` on Gaussian curvature ``K`` strains about ``w² K / 4`` with its
    lengths balanced (docs/garments.md); ``k`` darts part a circle of 3D length ``C`` into gores of
    half-width ``C / (2 k)``, so ``k >= C sqrt(K / limit) / 4``.  Taken over geodesic circles about
    the crown (rings of equal width, about 2 sqrt(n) vertices to a ring, at most 48: a ring's length
    is its 3D area over its width, its curvature the angle defects of its vertices off the outline
    over their area, with its two neighbours'), the largest.  Within about 10 % of the analytic
    bound on spheres and surfaces of revolution of 2,000-20,000 triangles.  A hemisphere:
    ``pi / (2 sqrt(limit))``, 9.07 at 3 %; darts measured need about 1.2 times as many (11).

    Parameters
    ----------
    result : Flattening
        The panel flattened without darts.
    limit : float
        The strain limit (0.03 = 3 %).
    defects : (n,) float64, optional
        :func:`patterns.measure.angle_defects` of the panel, if at hand.
    crown : (2,) float64, optional
        Where the darts meet on the layout, mm; default the centroid of the positive defects.

    Returns
    -------
    float
        0 where the panel has no positive curvature.
    """
    v, f, uv = result.vertices, result.faces, result.uv
    if defects is None:
        defects = angle_defects(v, f, loops=result.loops)
    positive = np.maximum(defects, 0.0)
    if not positive.sum() > 0:
        return 0.0
    if crown is None:
        crown = crown_of(uv, positive)
    start = int(np.argmin(np.linalg.norm(uv - crown, axis=1)))
    distance = dijkstra(edge_graph(v, unique_edges(f)), indices=start)
    rings = int(np.clip(np.sqrt(len(v)) / 2, 8, 48))  # about 2 sqrt(n) vertices to a ring
    width = float(distance.max()) / rings
    ring = np.minimum((distance / width).astype(np.int64), rings - 1)
    areas = vertex_areas(v, f)
    inside = np.ones(len(v), dtype=bool)
    inside[np.concatenate([np.asarray(loop) for loop in result.loops])] = False  # no defect of their own
    area = np.bincount(ring, weights=areas, minlength=rings)
    curved = np.bincount(ring[inside], weights=areas[inside], minlength=rings)
    curvature = np.bincount(ring, weights=defects, minlength=rings)
    smooth = np.ones(3)  # each ring with its two neighbours: a ring's few vertices are noisy
    curvature, curved = np.convolve(curvature, smooth, "same"), np.convolve(curved, smooth, "same")
    keep = curved > 0
    density = np.maximum(curvature[keep], 0.0) / curved[keep]
    return float(((area[keep] / width) * np.sqrt(density / limit) / 4.0).max())


def vertex_areas(vertices, faces) -> np.ndarray:
    """(n,) float64: a third of the 3D area of each vertex's triangles, mm²."""
    return np.bincount(faces.ravel(), weights=np.repeat(face_areas(vertices, faces) / 3.0, 3), minlength=len(vertices))
