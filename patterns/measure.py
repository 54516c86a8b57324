"""Distortion of a flattening: stretches, strains, areas, boundary lengths.

Every function takes the 3D mesh ``vertices : (n, 3) float64`` and
``faces : (m, 3) int64`` and the flat positions ``uv : (n, 2) float64`` in the
same unit (mm), and returns plain arrays; :func:`distortion` gathers the usual
summary in one frozen :class:`Distortion`.

The per-triangle map from the surface to the plane is affine; its Jacobian ``J``
(2 x 2, in each triangle's own orthonormal frame) has singular values
``sigma1 >= sigma2``: the principal stretches.  An isometry has
``sigma1 = sigma2 = 1``; ``sigma - 1`` are the principal strains; ``det J < 0``
(or a zero flat area) is a folded, i.e. flipped or collapsed, triangle.

The strain a pattern reports is the material's: the principal strains of
this map, weighted by 3D area (:func:`strain_rms`, :func:`strain_stats`).
They converge as the mesh is refined and agree between triangulations of one
surface.  The edge strain ``|l_flat / l_3d - 1|`` over the edges
(:func:`edge_strain`) counts edges instead, so it changes with the
triangulation (slivers and pole fans weigh in by their number); it is kept as
a column, never as the judge (docs/measures.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .mesh import corner_angles, edge_lengths, face_areas, side_vectors, unique_edges

__all__ = [
    "Distortion",
    "StrainStats",
    "TriangleStrain",
    "affine_coefficients",
    "angle_defects",
    "area_ratio",
    "best_turn",
    "boundary_lengths",
    "distortion",
    "edge_strain",
    "flat_direction",
    "folded_faces",
    "local_coordinates",
    "no_strain",
    "principal_stretches",
    "signed_areas",
    "strain_rms",
    "strain_stats",
    "symmetric_dirichlet",
    "triangle_strains",
    "weighted_percentile",
]


def local_coordinates(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Each triangle in its own orthonormal frame (Li & Xue, eqs. 4-6).

    With ``A = p2 - p1``, ``B = p3 - p1``, ``N = A x B / |A x B|``,
    ``X = N x B / |N x B|`` and ``Y = N x X``, the corners are
    ``(0, 0)``, ``(A.X, A.Y)`` and ``(B.X, B.Y)``: an isometric copy of the
    triangle, counter-clockwise when the triangle is counter-clockwise about ``N``.

    Parameters
    ----------
    vertices : (n, 3) float64
    faces : (m, 3) int64

    Returns
    -------
    (m, 3) complex128
        Corner ``k`` of face ``f`` is ``x + iy`` in the face's frame, same unit as
        ``vertices``.
    """
    # In that frame Y = N x X = -B / |B| and X = (N x B) / |B|, so
    # A.X = -|A x B| / |B|, A.Y = -A.B / |B|, B.X = 0 and B.Y = -|B|.
    (ax, ay, az), (bx, by, bz) = side_vectors(vertices, faces)
    cx, cy, cz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
    cross = np.sqrt(cx * cx + cy * cy + cz * cz)
    blen = np.sqrt(bx * bx + by * by + bz * bz)
    z = np.zeros((len(faces), 3), dtype=np.complex128)
    z[:, 1].real = -cross / blen
    z[:, 1].imag = -(ax * bx + ay * by + az * bz) / blen
    z[:, 2].imag = -blen
    return z


def affine_coefficients(vertices: np.ndarray, faces: np.ndarray, uv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The per-triangle map as ``w = alpha z + beta conj(z) + c`` in complex form.

    Returns
    -------
    alpha, beta : (m,) complex128
        ``|alpha| + |beta|`` and ``||alpha| - |beta||`` are the principal
        stretches; ``|alpha|**2 - |beta|**2`` is ``det J`` (flat area over 3D area).
    """
    z = local_coordinates(vertices, faces)
    w = uv[faces, 0] + 1j * uv[faces, 1]
    e1, e2 = z[:, 1] - z[:, 0], z[:, 2] - z[:, 0]
    w1, w2 = w[:, 1] - w[:, 0], w[:, 2] - w[:, 0]
    d = e1 * np.conj(e2) - e2 * np.conj(e1)
    alpha = (w1 * np.conj(e2) - w2 * np.conj(e1)) / d
    beta = (e1 * w2 - e2 * w1) / d
    return alpha, beta


def principal_stretches(vertices: np.ndarray, faces: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """Principal stretches of the surface-to-plane map, per triangle.

    Parameters
    ----------
    vertices : (n, 3) float64
    faces : (m, 3) int64
    uv : (n, 2) float64
        Flat positions, same unit as ``vertices``.

    Returns
    -------
    (m, 2) float64
        ``sigma1 >= sigma2 >= 0`` (dimensionless); 1 is no stretch.
    """
    return _stretches(*affine_coefficients(vertices, faces, uv))


def _stretches(alpha: np.ndarray, beta: np.ndarray) -> np.ndarray:
    """``(m, 2)`` principal stretches ``|alpha| + |beta|``, ``||alpha| - |beta||``."""
    a, b = np.abs(alpha), np.abs(beta)
    return np.stack([a + b, np.abs(a - b)], axis=1)


def best_turn(p: np.ndarray, q: np.ndarray) -> float:
    """The angle, radians, of the rotation that best takes the centred flat points ``p`` onto ``q``.

    Procrustes in the plane in closed form (``arctan2`` of the cross-covariance's antisymmetric and
    symmetric parts), every product written out: a BLAS or LAPACK call rounds by the CPU's kernels (fused
    multiply-adds on one, not on another), and what is placed by the turn would follow those bits.

    Parameters
    ----------
    p, q : (k, 2) float64
        Corresponding points, each set centred on its mean, any one unit.

    Returns
    -------
    float
        In ``(-pi, pi]``; a turn, never a mirror.
    """
    cos = float(np.einsum("i,i->", p[:, 0], q[:, 0]) + np.einsum("i,i->", p[:, 1], q[:, 1]))
    sin = float(np.einsum("i,i->", p[:, 0], q[:, 1]) - np.einsum("i,i->", p[:, 1], q[:, 0]))
    return float(np.arctan2(sin, cos))


def signed_areas(uv: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Signed flat areas ``(m,) float64`` of triangles ``faces`` (m, 3) over flat points ``uv`` (n, 2) (positive =
    counter-clockwise), in the square of ``uv``'s unit."""
    uv, faces = np.asarray(uv, dtype=np.float64), np.asarray(faces, dtype=np.int64)
    x, y = uv[:, 0], uv[:, 1]
    i, j, k = faces[:, 0], faces[:, 1], faces[:, 2]
    x0, y0 = x[i], y[i]
    return 0.5 * ((x[j] - x0) * (y[k] - y0) - (y[j] - y0) * (x[k] - x0))


def folded_faces(uv: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Indices ``(k,) int64`` of the triangles ``faces`` (m, 3) whose signed area over ``uv`` (n, 2) is <= 0."""
    return np.flatnonzero(~(signed_areas(uv, faces) > 0))


def edge_strain(vertices: np.ndarray, faces: np.ndarray, uv: np.ndarray, *, edges: np.ndarray | None = None) -> np.ndarray:
    """Edge strain ``|l_flat / l_3d - 1|`` of every edge.

    Parameters
    ----------
    vertices : (n, 3) float64
    faces : (m, 3) int64
    uv : (n, 2) float64
    edges : (e, 2) int64, optional
        The unique edges (computed from ``faces`` when omitted).

    Returns
    -------
    (e,) float64, dimensionless, in the order of ``edges`` (sorted unique edges
    when computed here).
    """
    if edges is None:
        edges = unique_edges(faces)
    l3 = edge_lengths(vertices, edges)
    l2 = np.linalg.norm(uv[edges[:, 1]] - uv[edges[:, 0]], axis=1)
    return np.abs(l2 / l3 - 1.0)


def area_ratio(vertices: np.ndarray, faces: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """Signed flat area over 3D area, per triangle ``(m,) float64``."""
    return signed_areas(uv, faces) / face_areas(vertices, faces)


def boundary_lengths(vertices: np.ndarray, uv: np.ndarray, loops) -> np.ndarray:
    """Length of each boundary loop on the surface and in the plane.

    Parameters
    ----------
    vertices : (n, 3) float64
    uv : (n, 2) float64
    loops : sequence of (k,) int64 arrays
        Closed vertex loops (see :func:`patterns.mesh.boundary_loops`).

    Returns
    -------
    (len(loops), 2) float64
        Columns: 3D length, flat length (unit of ``vertices``).
    """
    out = np.empty((len(loops), 2))
    for i, loop in enumerate(loops):
        nxt = np.roll(loop, -1)
        out[i, 0] = np.linalg.norm(vertices[nxt] - vertices[loop], axis=1).sum()
        out[i, 1] = np.linalg.norm(uv[nxt] - uv[loop], axis=1).sum()
    return out


@dataclass(frozen=True)
class Distortion:
    """Summary of how far a flattening is from an isometry.

    All strains are dimensionless (0.01 = 1 %); lengths and areas in the mesh unit.
    """

    strain_rms: float
    """Area-weighted RMS of both principal strains of every triangle (:func:`strain_rms`)."""
    strain_max: float
    """Largest principal strain magnitude of any triangle."""
    symmetric_dirichlet: float
    """Area-weighted mean of ``sigma1**2 + sigma2**2 + 1/sigma1**2 + 1/sigma2**2`` (4 for an isometry;
    inf when a triangle is folded): how far the worst-squeezed triangles are from their size."""
    stretch_p1: float
    """1st percentile (by 3D area) of the smallest principal stretch: below 0.1, triangles are crushed."""
    edge_strain_rms: float
    """RMS of ``|l_flat / l_3d - 1|`` over the edges: mesh-dependent, a column only."""
    edge_strain_max: float
    stretch_min: float
    """Smallest principal stretch over all triangles (sigma2)."""
    stretch_max: float
    """Largest principal stretch over all triangles (sigma1)."""
    area_3d: float
    area_flat: float
    """Sum of signed flat areas (folded triangles count negative)."""
    n_folded: int
    boundary_3d: float
    """Total length of all boundary loops on the surface."""
    boundary_flat: float

    @property
    def area_ratio(self) -> float:
        return self.area_flat / self.area_3d


def distortion(vertices: np.ndarray, faces: np.ndarray, uv: np.ndarray, *, loops=None) -> Distortion:
    """Summarise the distortion of ``uv`` as a flattening of ``(vertices, faces)``.

    Parameters
    ----------
    vertices : (n, 3) float64
    faces : (m, 3) int64
    uv : (n, 2) float64
    loops : sequence of (k,) int64 arrays, optional
        Boundary loops; when omitted the boundary lengths are reported as NaN.

    Returns
    -------
    Distortion
    """
    vertices = np.asarray(vertices, dtype=np.float64)
    faces = np.asarray(faces, dtype=np.int64)
    uv = np.asarray(uv, dtype=np.float64)
    # A diverged flattening (the paper's method on a fine mesh) overflows: its
    # measures are honestly inf, without warnings.
    with np.errstate(over="ignore", invalid="ignore"):
        strain = edge_strain(vertices, faces, uv)
        sigma = principal_stretches(vertices, faces, uv)
        a3 = face_areas(vertices, faces)
        sa = signed_areas(uv, faces)
        if loops is None:
            b3 = bf = float("nan")
        else:
            lengths = boundary_lengths(vertices, uv, loops)
            b3, bf = (float(x) for x in lengths.sum(axis=0))
        rms = float(np.sqrt(np.mean(strain**2)))
        principal = np.abs(sigma - 1.0)
        weights = a3 / a3.sum()
        folded = int(np.count_nonzero(~(sa > 0)))
    return Distortion(
        strain_rms=_principal_rms(principal, a3),
        strain_max=float(principal.max()),
        symmetric_dirichlet=float("inf") if folded else _symmetric_dirichlet(sigma, weights),
        stretch_p1=weighted_percentile(sigma[:, 1], a3, 1.0),
        edge_strain_rms=rms,
        edge_strain_max=float(strain.max()),
        stretch_min=float(sigma[:, 1].min()),
        stretch_max=float(sigma[:, 0].max()),
        area_3d=float(a3.sum()),
        area_flat=float(sa.sum()),
        n_folded=folded,
        boundary_3d=b3,
        boundary_flat=bf,
    )


@dataclass(frozen=True, eq=False)
class TriangleStrain:
    """Strain of every triangle of a flattening (read-only arrays, dimensionless).

    Attributes
    ----------
    stretch : (m, 2) float64
        Principal stretches ``sigma1 >= sigma2``: flat length over 3D length
        in the directions of most and least stretch.
    strain : (m, 2) float64
        Principal strains ``stretch - 1`` (0.03 = stretched 3 %, -0.03 =
        compressed 3 %).
    dominant : (m,) float64
        The principal strain of larger magnitude, with its sign.
    direction : (m,) float64
        Angle in the flat pattern (radians, from +u, in [0, pi)) of the
        direction of the dominant strain.
    area_change : (m,) float64
        ``flat area / 3D area - 1`` (signed area: a folded triangle is below -1).
    area_3d : (m,) float64
        3D areas, in the square of the mesh unit (the weights of the statistics).
    """

    stretch: np.ndarray
    strain: np.ndarray
    dominant: np.ndarray
    direction: np.ndarray
    area_change: np.ndarray
    area_3d: np.ndarray

    @property
    def magnitude(self) -> np.ndarray:
        """(m,) float64: ``|dominant|``, the largest strain in any direction."""
        return np.abs(self.dominant)


def triangle_strains(vertices: np.ndarray, faces: np.ndarray, uv: np.ndarray) -> TriangleStrain:
    """Principal strains, their directions and the area change of every triangle.

    Parameters
    ----------
    vertices : (n, 3) float64
    faces : (m, 3) int64
    uv : (n, 2) float64
        Flat positions, same unit as ``vertices``.

    Returns
    -------
    TriangleStrain
    """
    alpha, beta = affine_coefficients(vertices, faces, uv)
    stretch = _stretches(alpha, beta)
    strain = stretch - 1.0
    first = np.abs(strain[:, 0]) >= np.abs(strain[:, 1])
    dominant = np.where(first, strain[:, 0], strain[:, 1])
    # w = alpha z + beta conj(z) stretches most along the flat direction
    # (arg alpha + arg beta) / 2, least at right angles to it.
    angle = 0.5 * (np.angle(alpha) + np.angle(beta)) + np.where(first, 0.0, 0.5 * np.pi)
    direction = np.mod(angle, np.pi)
    a3 = face_areas(vertices, faces)
    change = signed_areas(uv, faces) / a3 - 1.0
    arrays = [stretch, strain, dominant, direction, change, a3]
    for x in arrays:
        x.setflags(write=False)
    return TriangleStrain(*arrays)


def no_strain(vertices: np.ndarray, faces: np.ndarray) -> TriangleStrain:
    """The :class:`TriangleStrain` of an isometry: every stretch 1, every strain 0.

    What an exact development reports: it maps the surface isometrically, and
    what its triangles would show (a straight 3D chord against the flat
    distance between two exact points, ``(h / R)**2 / 24``) is the mesh, not
    the material.
    """
    m = len(faces)
    arrays = [np.ones((m, 2)), np.zeros((m, 2)), np.zeros(m), np.zeros(m), np.zeros(m), face_areas(vertices, faces)]
    for x in arrays:
        x.setflags(write=False)
    return TriangleStrain(*arrays)


def angle_defects(vertices: np.ndarray, faces: np.ndarray, *, loops=()) -> np.ndarray:
    """The surface's Gaussian curvature gathered at each vertex: its angle defect.

    Parameters
    ----------
    vertices : (n, 3) float64
    faces : (m, 3) int64
    loops : sequence of (k,) int, optional
        The boundary loops; their vertices get 0 (a boundary vertex has no
        defect of its own).

    Returns
    -------
    (n,) float64
        ``2 pi`` minus the sum of the corner angles round each vertex,
        radians: positive on a dome, negative on a saddle, 0 on a plane or a
        cylinder; the defects of a surface patch sum to its total curvature.
    """
    angles = corner_angles(np.asarray(vertices, dtype=np.float64), np.asarray(faces, dtype=np.int64))
    total = np.bincount(np.asarray(faces).ravel(), weights=angles.ravel(), minlength=len(vertices))
    defect = 2.0 * np.pi - total
    for loop in loops:
        defect[np.asarray(loop, dtype=np.int64)] = 0.0
    return defect


def weighted_percentile(values: np.ndarray, weights: np.ndarray, q: float) -> float:
    """The ``q``-th percentile (0-100) of ``values`` under ``weights`` (lower value at a tie)."""
    order = np.argsort(values, kind="stable")
    cum = np.cumsum(weights[order])
    k = int(np.searchsorted(cum, q / 100.0 * cum[-1], side="left"))
    return float(values[order][min(k, len(values) - 1)])


def _symmetric_dirichlet(sigma: np.ndarray, weights: np.ndarray) -> float:
    with np.errstate(divide="ignore", over="ignore"):
        return float(np.sum(weights * (sigma**2 + 1.0 / sigma**2).sum(axis=1)))


def symmetric_dirichlet(vertices: np.ndarray, faces: np.ndarray, uv: np.ndarray) -> float:
    """Area-weighted mean symmetric Dirichlet energy ``sigma1**2 + sigma2**2 + sigma1**-2 + sigma2**-2``.

    4 for an isometry, inf where a triangle is folded or collapsed: SLIM's
    measure, which sees crushed triangles that the strain RMS hardly notices.
    """
    sigma = principal_stretches(vertices, faces, uv)
    if np.any(~(signed_areas(uv, faces) > 0)):
        return float("inf")
    a3 = face_areas(vertices, faces)
    return _symmetric_dirichlet(sigma, a3 / a3.sum())


def strain_rms(vertices: np.ndarray, faces: np.ndarray, uv: np.ndarray) -> float:
    """Area-weighted RMS of the principal strains: ``sqrt(sum_t A_t (e1**2 + e2**2) / (2 sum_t A_t))``.

    ``e1, e2 = sigma1 - 1, sigma2 - 1``, ``A_t`` the 3D areas: the material's
    strain, independent of the triangulation (what ARAP minimises).

    Parameters
    ----------
    vertices : (n, 3) float64
    faces : (m, 3) int64
    uv : (n, 2) float64

    Returns
    -------
    float, dimensionless (0.01 = 1 %)
    """
    return _principal_rms(principal_stretches(vertices, faces, uv) - 1.0, face_areas(vertices, faces))


def _principal_rms(strain: np.ndarray, area: np.ndarray) -> float:
    """``sqrt(sum_t A_t (e1**2 + e2**2) / (2 sum_t A_t))`` of principal strains ``(m, 2)`` and areas ``(m,)``."""
    # np.sum, not a BLAS dot: the same sum whatever the thread count (a report must not depend on it)
    return float(np.sqrt(0.5 * np.sum(area * (strain**2).sum(axis=1)) / area.sum()))


@dataclass(frozen=True)
class StrainStats:
    """The principal-strain statistics a pattern reports (dimensionless, 0.01 = 1 %), weighted by 3D area.

    Attributes
    ----------
    rms : float
        RMS of both principal strains (:func:`strain_rms`).
    p95, p99 : float
        95th and 99th percentiles of each triangle's largest principal strain
        magnitude: the strain that 95 % (99 %) of the area stays within.
    max : float
        The largest principal strain magnitude of any triangle.
    worst : int
        That triangle (face index).
    """

    rms: float
    p95: float
    p99: float
    max: float
    worst: int


def strain_stats(strains: TriangleStrain) -> StrainStats:
    """:class:`StrainStats` of a :func:`triangle_strains` result."""
    mag, w = strains.magnitude, strains.area_3d
    rms = _principal_rms(strains.strain, w)
    worst = int(np.argmax(mag))
    return StrainStats(rms, weighted_percentile(mag, w, 95.0), weighted_percentile(mag, w, 99.0),
                       float(mag[worst]), worst)


def flat_direction(vertices, faces, uv, direction) -> np.ndarray:
    """Where a 3D direction points in a flattening: the area-weighted mean of its images.

    On each triangle the direction is projected onto the triangle's plane and
    carried to the plane by the triangle's own linear map.

    Parameters
    ----------
    vertices : (n, 3) float64
    faces : (m, 3) int64
    uv : (n, 2) float64
    direction : (3,) float64
        Any length.

    Returns
    -------
    (2,) float64
        Unit vector in the plane (``(0, 1)`` if the direction has no image).
    """
    p, q = vertices[faces], uv[faces]
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    f1, f2 = q[:, 1] - q[:, 0], q[:, 2] - q[:, 0]
    # Solve direction ~ a e1 + b e2 (least squares on the triangle's plane): Gram system.
    g11, g12, g22 = (e1 * e1).sum(1), (e1 * e2).sum(1), (e2 * e2).sum(1)
    r1, r2 = np.einsum("ij,j->i", e1, direction), np.einsum("ij,j->i", e2, direction)  # no BLAS
    det = g11 * g22 - g12 * g12
    a = (g22 * r1 - g12 * r2) / det
    b = (g11 * r2 - g12 * r1) / det
    images = a[:, None] * f1 + b[:, None] * f2
    area = 0.5 * np.linalg.norm(np.cross(e1, e2), axis=1)
    total = (images * area[:, None]).sum(axis=0)
    norm = math.hypot(*total)
    return total / norm if norm > 0 else np.array([0.0, 1.0])
