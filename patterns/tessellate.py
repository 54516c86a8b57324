"""CAD faces to triangle meshes, with build123d (OpenCascade) tessellation.

build123d is imported only when a CAD object is tessellated (the import takes
seconds).
"""

from __future__ import annotations

import numpy as np

from .errors import CadError, InputError
from .load import drop_unused
from .mesh import face_areas

__all__ = ["tessellate_face"]


def tessellate_face(face, *, tolerance: float = 0.05, angular_tolerance: float = 0.1) -> tuple[np.ndarray, np.ndarray]:
    """Triangulate one build123d ``Face``.

    Parameters
    ----------
    face : build123d.Face
        Any surface type; its unit is the model's (mm in build123d).
    tolerance : float
        Largest distance from the triangles to the true surface (chordal
        deviation), in the model's unit; > 0.
    angular_tolerance : float
        Largest angle between neighbouring triangles' normals, radians; > 0.

    Returns
    -------
    vertices : (n, 3) float64
    faces : (m, 3) int64
        Wound with the face's outward orientation.  Zero-area triangles, which
        OpenCascade puts at the poles of spheres and cones, are removed, and the
        vertices they leave unused dropped.

    Raises
    ------
    InputError
        Not a build123d Face, or a tolerance that is not positive.
    CadError
        The face could not be tessellated.
    """
    import build123d  # heavy; only when CAD is used

    if not isinstance(face, build123d.Face):
        raise InputError(f"expected a build123d Face, got {type(face).__name__}")
    if not (tolerance > 0 and angular_tolerance > 0):
        raise InputError(f"tolerances must be positive, got {tolerance!r} and {angular_tolerance!r}")
    try:
        points, triangles = face.tessellate(tolerance, angular_tolerance)
    except Exception as exc:  # noqa: BLE001 - OpenCascade raises many kinds
        raise CadError(f"tessellation of the face failed ({exc})") from None
    if not triangles:
        raise CadError("tessellation of the face produced no triangles")
    vertices = np.array([(p.X, p.Y, p.Z) for p in points], dtype=np.float64)
    faces = np.asarray(triangles, dtype=np.int64)
    faces = faces[face_areas(vertices, faces) > 0]
    vertices, faces, _ = drop_unused(vertices, faces)
    return vertices, faces
