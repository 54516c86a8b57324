"""build123d faces, tessellated and flattened: real CAD, real OpenCascade."""

import numpy as np
import pytest

import patterns
from patterns.errors import InputError
from patterns.tessellate import tessellate_face

bd = pytest.importorskip("build123d")


def test_cylinder_side_unrolls_to_its_rectangle():
    side = next(f for f in bd.Cylinder(100, 200).faces() if f.geom_type == bd.GeomType.CYLINDER)
    v, f = tessellate_face(side, tolerance=0.01)
    r = patterns.flatten_mesh(v, f)
    assert r.one_to_one
    assert r.distortion.edge_strain_max < 1e-9  # OpenCascade meshes a cylinder along its rulings
    width, height = np.ptp(r.uv @ _principal_axes(r.uv), axis=0)
    # The seam is cut: a rectangle of the (chordal) circumference by the height.
    assert sorted([width, height]) == pytest.approx(sorted([2 * np.pi * 100, 200]), rel=2e-4)
    assert r.distortion.area_flat == pytest.approx(side.area, rel=2e-4)


def test_freeform_face_flattens_like_the_mesh_dish():
    """A B-spline patch through the 600x54 paraboloid (400 mm square part of it):
    its coarse CAD tessellation flattens one-to-one with the dish's strain."""
    grid = np.linspace(-200.0, 200.0, 7)
    points = [[bd.Vector(x, y, 54.0 * ((x / 300) ** 2 + (y / 300) ** 2)) for y in grid] for x in grid]
    face = bd.Face.make_surface_from_array_of_points(points)
    v, f = tessellate_face(face, tolerance=0.01)
    grown = patterns.flatten_mesh(v, f, method="isometric")
    assert grown.one_to_one
    assert 0.005 < grown.distortion.edge_strain_rms < 0.015  # measured 0.0097
    assert grown.distortion.area_3d == pytest.approx(face.area, rel=1e-3)
    relaxed = patterns.flatten_mesh(v, f)
    assert relaxed.one_to_one
    assert relaxed.distortion.edge_strain_rms < 0.5 * grown.distortion.edge_strain_rms  # measured 0.0030


def test_not_a_face():
    with pytest.raises(InputError, match="expected a build123d Face"):
        tessellate_face(bd.Box(1, 1, 1))
    with pytest.raises(InputError, match="positive"):
        tessellate_face(bd.Box(1, 1, 1).faces()[0], tolerance=-1)


def _principal_axes(uv):
    c = uv - uv.mean(axis=0)
    return np.linalg.eigh(c.T @ c)[1]
