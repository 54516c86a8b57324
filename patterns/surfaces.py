"""Generated surfaces with known geometry, for tests, benchmarks and demos.

Each function returns ``(vertices, faces)``: ``(n, 3) float64`` in millimetres and
``(m, 3) int64`` counter-clockwise seen from outside (+z for the dishes).  The
triangles are near-equilateral, as a good tessellation is, and the face count
is close to the ``n_faces`` asked for.

Developable surfaces (:func:`cylinder_patch`, :func:`cone_patch`) are
triangulated along their rulings, so the triangle mesh itself is exactly
developable: a length-preserving flattening has zero strain.
"""

from __future__ import annotations

import numpy as np

from .errors import InputError

__all__ = [
    "cone_patch",
    "cylinder_patch",
    "disk_mesh",
    "ellipsoid_cup",
    "grid_mesh",
    "paraboloid_dish",
    "saddle",
    "spherical_cap",
]


def disk_mesh(n_faces: int) -> tuple[np.ndarray, np.ndarray]:
    """Unit disk triangulated in concentric rings.

    Ring ``i`` (``i = 1..K``) has ``6 i`` points at radius ``i / K``; consecutive
    rings are zipped together by angle.  About ``6 K**2`` faces.

    Returns
    -------
    points : (n, 2) float64
        In the unit disk.
    faces : (m, 3) int64
        Counter-clockwise.
    """
    if n_faces < 6:
        raise InputError(f"n_faces must be at least 6, got {n_faces}")
    k_rings = max(1, round(np.sqrt(n_faces / 6.0)))
    counts = 6 * np.arange(1, k_rings + 1)
    offsets = np.concatenate([[1], 1 + np.cumsum(counts)])
    ring = np.repeat(np.arange(1, k_rings + 1), counts)
    local = np.arange(len(ring)) - (offsets[ring - 1] - 1)
    theta = 2 * np.pi * local / counts[ring - 1]
    radius = ring / k_rings
    points = np.concatenate([[[0.0, 0.0]], np.stack([radius * np.cos(theta), radius * np.sin(theta)], axis=1)])

    faces = [np.stack([np.zeros(6, np.int64), 1 + np.arange(6), 1 + (np.arange(6) + 1) % 6], axis=1)]
    for i in range(1, k_rings):
        a_n, b_n = counts[i - 1], counts[i]
        a0, b0 = offsets[i - 1], offsets[i]
        # Advance events sorted by the angle of the point advanced to.
        ta = np.arange(1, a_n + 1) / a_n
        tb = np.arange(1, b_n + 1) / b_n
        t = np.concatenate([ta, tb])
        is_a = np.concatenate([np.ones(a_n, bool), np.zeros(b_n, bool)])
        order = np.lexsort((~is_a, t))
        is_a = is_a[order]
        # Index (before wrapping) of the current A and B point after each event.
        ia = np.cumsum(is_a)
        ib = np.cumsum(~is_a)
        prev_a = ia - is_a
        prev_b = ib - ~is_a
        A = a0 + prev_a % a_n
        A_next = a0 + ia % a_n
        B = b0 + prev_b % b_n
        B_next = b0 + ib % b_n
        tri = np.where(
            is_a[:, None],
            np.stack([A, B, A_next], axis=1),
            np.stack([B, B_next, A], axis=1),
        )
        faces.append(tri.astype(np.int64))
    return points, np.concatenate(faces)


def paraboloid_dish(*, diameter: float = 600.0, sag: float = 54.0, n_faces: int = 10_000) -> tuple[np.ndarray, np.ndarray]:
    """A paraboloid dish ``z = sag (r / R)**2`` (doubly curved, K > 0).

    Parameters
    ----------
    diameter, sag : float
        Rim diameter and depth, mm.
    n_faces : int
        Approximate number of triangles.
    """
    p, f = disk_mesh(n_faces)
    radius = diameter / 2
    xy = p * radius
    z = sag * (p**2).sum(axis=1)
    return np.column_stack([xy, z]), f


def spherical_cap(*, radius: float = 100.0, half_angle: float = 90.0, n_faces: int = 10_000) -> tuple[np.ndarray, np.ndarray]:
    """A spherical cap of polar half-angle ``half_angle`` degrees (90 = hemisphere).

    The cap is centred on +z, rim at the bottom; vertices are spaced evenly in
    geodesic distance from the pole.
    """
    p, f = disk_mesh(n_faces)
    r = np.linalg.norm(p, axis=1)
    phi = r * np.radians(half_angle)
    theta = np.arctan2(p[:, 1], p[:, 0])
    s = np.sin(phi)
    v = radius * np.column_stack([s * np.cos(theta), s * np.sin(theta), np.cos(phi)])
    return v, f


def saddle(*, diameter: float = 400.0, height: float = 40.0, n_faces: int = 10_000) -> tuple[np.ndarray, np.ndarray]:
    """A hyperbolic-paraboloid disk ``z = height (x**2 - y**2) / R**2`` (K < 0)."""
    p, f = disk_mesh(n_faces)
    radius = diameter / 2
    z = height * (p[:, 0] ** 2 - p[:, 1] ** 2)
    return np.column_stack([p * radius, z]), f


def ellipsoid_cup(*, axes: tuple[float, float, float] = (90.0, 70.0, 60.0), n_faces: int = 10_000) -> tuple[np.ndarray, np.ndarray]:
    """The lower half of an ellipsoid with semi-axes ``axes`` (a bra-cup like shell).

    Opening at the top (z = 0), bottom at ``z = -axes[2]``; normals point outward.
    """
    p, f = disk_mesh(n_faces)
    r = np.linalg.norm(p, axis=1)
    phi = r * (np.pi / 2)
    theta = np.arctan2(p[:, 1], p[:, 0])
    s = np.sin(phi)
    a, b, c = axes
    v = np.column_stack([a * s * np.cos(theta), b * s * np.sin(theta), -c * np.cos(phi)])
    # The disk's counter-clockwise order seen from +z is clockwise seen from below:
    # flip so the normals point out of the cup.
    return v, f[:, [0, 2, 1]]


def grid_mesh(n_u: int, n_v: int) -> tuple[np.ndarray, np.ndarray]:
    """Unit square ``[0, 1]**2`` as an ``n_u x n_v`` grid of quads split in two.

    Returns
    -------
    st : (n, 2) float64
        Grid parameters; ``st[:, 0]`` runs along u (``n_u + 1`` values).
    faces : (m, 3) int64
        Counter-clockwise in the (s, t) plane; ``2 n_u n_v`` faces.
    """
    if n_u < 1 or n_v < 1:
        raise InputError(f"grid needs at least 1 x 1 cells, got {n_u} x {n_v}")
    s, t = np.meshgrid(np.linspace(0, 1, n_u + 1), np.linspace(0, 1, n_v + 1), indexing="ij")
    st = np.column_stack([s.ravel(), t.ravel()])
    idx = np.arange((n_u + 1) * (n_v + 1)).reshape(n_u + 1, n_v + 1)
    a = idx[:-1, :-1].ravel()
    b = idx[1:, :-1].ravel()
    c = idx[1:, 1:].ravel()
    d = idx[:-1, 1:].ravel()
    faces = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    return st, faces.astype(np.int64)


def cylinder_patch(*, radius: float = 200.0, height: float = 300.0, angle: float = 180.0,
                   n_around: int = 60, n_along: int = 20) -> tuple[np.ndarray, np.ndarray]:
    """Part of a cylinder, triangulated along its rulings (exactly developable).

    Parameters
    ----------
    radius, height : float
        mm.
    angle : float
        Angle swept around the axis, degrees (< 360).
    n_around, n_along : int
        Cells around and along the axis.

    Notes
    -----
    The flat pattern is a rectangle ``radians(angle) * radius`` by ``height``.
    """
    st, f = grid_mesh(n_around, n_along)
    phi = st[:, 0] * np.radians(angle)
    v = np.column_stack([radius * np.cos(phi), radius * np.sin(phi), st[:, 1] * height])
    return v, f


def cone_patch(*, r_bottom: float = 250.0, r_top: float = 100.0, height: float = 300.0,
               angle: float = 270.0, n_around: int = 60, n_along: int = 20) -> tuple[np.ndarray, np.ndarray]:
    """Part of a cone frustum, triangulated along its rulings (exactly developable).

    Parameters
    ----------
    r_bottom, r_top, height : float
        Radii at ``z = 0`` and ``z = height``, mm.
    angle : float
        Angle swept around the axis, degrees (< 360).
    n_around, n_along : int
        Cells around and along the rulings.
    """
    st, f = grid_mesh(n_around, n_along)
    phi = st[:, 0] * np.radians(angle)
    r = r_bottom + (r_top - r_bottom) * st[:, 1]
    v = np.column_stack([r * np.cos(phi), r * np.sin(phi), st[:, 1] * height])
    return v, f


def torus_patch(*, major: float = 200.0, minor: float = 80.0, around: float = 90.0, tube: float = 240.0,
                n_faces: int = 10_000) -> tuple[np.ndarray, np.ndarray]:
    """A patch of a torus spanning its outer (K > 0) and inner (K < 0) sides.

    Parameters
    ----------
    major, minor : float
        Radius of the centre circle and of the tube, mm.
    around : float
        Angle swept around the torus axis, degrees.
    tube : float
        Angle swept around the tube, degrees, centred on the outside.
    n_faces : int
        Approximate number of triangles.
    """
    length_u = np.radians(around) * (major + minor)
    length_v = np.radians(tube) * minor
    n_u = max(1, round(np.sqrt(n_faces / 2 * length_u / length_v)))
    n_v = max(1, round(n_faces / (2 * n_u)))
    st, f = grid_mesh(n_u, n_v)
    phi = (st[:, 0] - 0.5) * np.radians(around)
    theta = (st[:, 1] - 0.5) * np.radians(tube)
    ring = major + minor * np.cos(theta)
    v = np.column_stack([ring * np.cos(phi), ring * np.sin(phi), minor * np.sin(theta)])
    return v, f
