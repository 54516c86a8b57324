"""Remeshing on the exact surface: Delaunay flips by 3D angles, tangential smoothing.

The last stage of meshing a face (:func:`patterns.tessellate.faces.mesh_face`):
its triangles are improved on the CAD surface itself, boundary points fixed.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..mesh import unique_ints

__all__ = ["evaluate", "flip_to_delaunay", "relax_on_surface", "remesh"]


def remesh(surface, xyz_b: np.ndarray, uv_b: np.ndarray, uv_in: np.ndarray, tri: np.ndarray, fixed: np.ndarray):
    """Alternate Delaunay flips (by 3D angles) and smoothing on the surface: ``(uv_in, xyz_in, tri)``.

    Parameters
    ----------
    surface : OCP ``BRepAdaptor_Surface``
    xyz_b, uv_b : (b, 3), (b, 2) float64
        Boundary points (mm) and their parameters; they stay where they are.
    uv_in : (i, 2) float64
        Interior points' parameters.
    tri : (m, 3) int64
        Triangles over boundary then interior points.
    fixed : (s, 2) int64
        Boundary segments, never flipped.
    """
    xyz_in = evaluate(surface, uv_in)
    for _ in range(2):
        tri = flip_to_delaunay(np.concatenate([xyz_b, xyz_in]), np.concatenate([uv_b, uv_in]), tri, fixed)
        uv_in, xyz_in = relax_on_surface(surface, xyz_b, uv_b, uv_in, tri)
    tri = flip_to_delaunay(np.concatenate([xyz_b, xyz_in]), np.concatenate([uv_b, uv_in]), tri, fixed)
    return uv_in, xyz_in, tri


def evaluate(surface, uv: np.ndarray, derivatives: bool = False):
    """Surface points (k, 3) at parameters (k, 2), and optionally the two tangents (k, 3) each."""
    from OCP.gp import gp_Pnt, gp_Vec

    k = len(uv)
    xyz = np.empty((k, 3))
    if not derivatives:
        for i, (u, v) in enumerate(uv):
            q = surface.Value(u, v)
            xyz[i] = (q.X(), q.Y(), q.Z())
        return xyz
    su, sv = np.empty((k, 3)), np.empty((k, 3))
    p, du, dv = gp_Pnt(), gp_Vec(), gp_Vec()
    for i, (u, v) in enumerate(uv):
        surface.D1(u, v, p, du, dv)
        xyz[i] = (p.X(), p.Y(), p.Z())
        su[i] = (du.X(), du.Y(), du.Z())
        sv[i] = (dv.X(), dv.Y(), dv.Z())
    return xyz, su, sv


def relax_on_surface(surface, xyz_b, uv_b, uv_in, tri, iterations: int = 3):
    """Tangential Laplacian smoothing of the interior points, on the exact surface.

    Each interior point moves towards the mean of its neighbours in 3D; the
    move is pulled back to the parameters through the surface's tangents and
    the point re-evaluated on the surface.  Moves that would flip a triangle
    in the parameter plane are undone.  Returns the interior points'
    parameters (k, 2) and positions (k, 3).
    """
    nb, ni = len(uv_b), len(uv_in)
    if ni == 0:
        return uv_in, np.zeros((0, 3))
    n = nb + ni
    e = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
    adj = sp.coo_matrix((np.ones(len(e)), (e[:, 0], e[:, 1])), shape=(n, n)).tocsr()
    adj = ((adj + adj.T) > 0).astype(np.float64)
    deg = np.asarray(adj.sum(axis=1)).ravel()[nb:]
    uv = np.concatenate([uv_b, uv_in])

    def orientation(q):
        p = q[tri]
        return np.sign((p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
                       - (p[:, 1, 1] - p[:, 0, 1]) * (p[:, 2, 0] - p[:, 0, 0]))

    sign = orientation(uv)
    xyz_in = None
    for _ in range(iterations):
        xyz_in, su, sv = evaluate(surface, uv[nb:], derivatives=True)
        xyz = np.concatenate([xyz_b, xyz_in])
        move = (adj @ xyz)[nb:] / deg[:, None] - xyz_in
        # Least-squares parameter step: [su sv] duv = move.
        a11, a12, a22 = (su * su).sum(1), (su * sv).sum(1), (sv * sv).sum(1)
        b1, b2 = (su * move).sum(1), (sv * move).sum(1)
        det = a11 * a22 - a12 * a12
        ok = det > 1e-300
        du = np.where(ok, (a22 * b1 - a12 * b2) / np.where(ok, det, 1), 0.0)
        dv = np.where(ok, (a11 * b2 - a12 * b1) / np.where(ok, det, 1), 0.0)
        step = np.column_stack([du, dv])
        for scale in (1.0, 0.5, 0.25):
            cand = uv.copy()
            cand[nb:] += scale * step
            if np.all(orientation(cand) == sign):
                uv = cand
                break
        else:
            break
    return uv[nb:], evaluate(surface, uv[nb:])


def flip_to_delaunay(xyz: np.ndarray, uv: np.ndarray, tri: np.ndarray, fixed: np.ndarray,
                      rounds: int = 30) -> np.ndarray:
    """Flip edges whose two opposite angles (in 3D) sum to more than pi.

    Boundary segments (``fixed``, (b, 2)) never flip; a flip must keep both
    new triangles positively oriented in the parameter plane.  Each round
    flips a set of edges no two of which share a triangle (each triangle
    claims its worst edge; an edge flips when both its triangles claim it).
    """
    tri = tri.copy()
    n = len(xyz)
    fixed_key = unique_ints(np.sort(fixed, axis=1) @ np.array([n, 1]))

    def orient(a, b, c):
        return (uv[b, 0] - uv[a, 0]) * (uv[c, 1] - uv[a, 1]) - (uv[b, 1] - uv[a, 1]) * (uv[c, 0] - uv[a, 0])

    for _ in range(rounds):
        m = len(tri)
        p = xyz[tri]
        angle = np.empty((m, 3))
        for k in range(3):
            a = p[:, (k + 1) % 3] - p[:, k]
            b = p[:, (k + 2) % 3] - p[:, k]
            norms = np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1)
            cos = np.einsum("ij,ij->i", a, b) / np.where(norms > 0, norms, 1.0)
            angle[:, k] = np.arccos(np.clip(np.where(norms > 0, cos, 1.0), -1.0, 1.0))
        # Side k of a triangle: corners k+1 -> k+2, opposite corner k.
        side_a = tri[:, [1, 2, 0]].ravel()
        side_b = tri[:, [2, 0, 1]].ravel()
        key = np.minimum(side_a, side_b) * n + np.maximum(side_a, side_b)
        order = np.argsort(key, kind="stable")
        ks = key[order]
        pair = np.flatnonzero(ks[1:] == ks[:-1])
        h1, h2 = order[pair], order[pair + 1]  # the two half-edges of each interior edge
        viol = angle.ravel()[h1] + angle.ravel()[h2] - np.pi
        t1, c1 = h1 // 3, h1 % 3
        t2, c2 = h2 // 3, h2 % 3
        a, b = side_a[h1], side_b[h1]  # t1 = (.., a -> b, opposite c)
        # An edge between two copies of one 3D point (the two sides of a slender cone's seam line
        # near its apex, close in the development) makes both its triangles flat: flip it first.
        viol = np.where(np.linalg.norm(xyz[a] - xyz[b], axis=1) > 0, viol, np.pi)
        ok = (viol > 1e-9) & ~np.isin(ks[pair], fixed_key)
        c, d = tri[t1, c1], tri[t2, c2]
        ok &= (orient(a, d, c) > 0) & (orient(d, b, c) > 0) & (np.linalg.norm(xyz[c] - xyz[d], axis=1) > 0)
        if not ok.any():
            break
        cand = np.flatnonzero(ok)
        claim = np.full(m, -1.0)
        np.maximum.at(claim, t1[cand], viol[cand])
        np.maximum.at(claim, t2[cand], viol[cand])
        win = cand[(claim[t1[cand]] == viol[cand]) & (claim[t2[cand]] == viol[cand])]
        # Ties could let one triangle win two edges: keep one edge per triangle.
        _, first1 = unique_ints(t1[win], return_index=True)
        win = win[first1]
        _, first2 = unique_ints(t2[win], return_index=True)
        win = win[first2]
        used = np.concatenate([t1[win], t2[win]])
        if len(unique_ints(used)) != len(used):
            win = win[:1]
        tri[t1[win]] = np.stack([a[win], d[win], c[win]], axis=1)
        tri[t2[win]] = np.stack([d[win], b[win], c[win]], axis=1)
    return tri
