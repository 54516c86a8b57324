"""Distortion measures, checked on maps whose stretches are known and against
an independent per-triangle SVD."""

import numpy as np
import pytest

from patterns import measure, surfaces
from patterns.mesh import validate_mesh


@pytest.fixture(scope="module")
def flat_disk():
    p, f = surfaces.disk_mesh(600)
    v = np.column_stack([p * 100.0, np.zeros(len(p))])
    return v, f


def test_identity_has_no_distortion(flat_disk):
    v, f = flat_disk
    uv = v[:, :2].copy()
    d = measure.distortion(v, f, uv, loops=validate_mesh(v, f)[2].loops)
    assert d.edge_strain_max < 1e-14
    assert d.stretch_min == pytest.approx(1.0, abs=1e-12)
    assert d.stretch_max == pytest.approx(1.0, abs=1e-12)
    assert d.area_ratio == pytest.approx(1.0, abs=1e-12)
    assert d.n_folded == 0
    assert d.boundary_flat == pytest.approx(d.boundary_3d, rel=1e-14)


@pytest.mark.parametrize(("sx", "sy"), [(2.0, 2.0), (1.5, 1.0), (0.5, 1.25)])
def test_axis_stretch_gives_those_principal_stretches(flat_disk, sx, sy):
    v, f = flat_disk
    theta = 0.7  # rotate after stretching: stretches do not change
    rot = np.array([[np.cos(theta), -np.sin(theta)], [np.sin(theta), np.cos(theta)]])
    uv = (v[:, :2] * [sx, sy]) @ rot.T
    sigma = measure.principal_stretches(v, f, uv)
    np.testing.assert_allclose(sigma[:, 0], max(sx, sy), rtol=1e-12)
    np.testing.assert_allclose(sigma[:, 1], min(sx, sy), rtol=1e-12)
    np.testing.assert_allclose(measure.area_ratio(v, f, uv), sx * sy, rtol=1e-12)
    if sx == sy:
        np.testing.assert_allclose(measure.edge_strain(v, f, uv), abs(sx - 1), rtol=1e-12)


def test_mirror_image_folds_every_triangle(flat_disk):
    v, f = flat_disk
    uv = v[:, :2] * [-1.0, 1.0]
    assert len(measure.folded_faces(f, uv)) == len(f)
    d = measure.distortion(v, f, uv)
    assert d.n_folded == len(f)
    assert d.edge_strain_max < 1e-14  # lengths are kept: folding is not strain
    assert d.area_ratio == pytest.approx(-1.0)


def test_stretches_match_an_independent_svd_on_a_curved_surface():
    v, f = surfaces.paraboloid_dish(n_faces=800)
    rng = np.random.default_rng(3)
    uv = v[:, :2] + rng.normal(scale=2.0, size=(len(v), 2))
    sigma = measure.principal_stretches(v, f, uv)
    # Independent: 3D basis by Gram-Schmidt, Jacobian by solving, numpy SVD.
    for t in range(0, len(f), 37):
        p = v[f[t]]
        e1, e2 = p[1] - p[0], p[2] - p[0]
        x = e1 / np.linalg.norm(e1)
        y = e2 - (e2 @ x) * x
        y /= np.linalg.norm(y)
        local = np.array([[e1 @ x, e2 @ x], [e1 @ y, e2 @ y]])
        flat = np.column_stack([uv[f[t, 1]] - uv[f[t, 0]], uv[f[t, 2]] - uv[f[t, 0]]])
        jac = flat @ np.linalg.inv(local)
        np.testing.assert_allclose(sigma[t], np.linalg.svd(jac, compute_uv=False), rtol=1e-9)


def test_local_coordinates_are_an_isometric_copy():
    v, f = surfaces.spherical_cap(n_faces=500)
    z = measure.local_coordinates(v, f)
    for k in range(3):
        a, b = k, (k + 1) % 3
        l3 = np.linalg.norm(v[f[:, b]] - v[f[:, a]], axis=1)
        np.testing.assert_allclose(np.abs(z[:, b] - z[:, a]), l3, rtol=1e-12)
    # Counter-clockwise, as the 3D triangles are about their normals.
    assert np.all(np.imag(np.conj(z[:, 1]) * z[:, 2]) > 0)


def test_boundary_lengths_of_a_square():
    v = np.array([[0, 0, 0], [2, 0, 0], [2, 3, 0], [0, 3, 0]], float)
    uv = v[:, :2] * 2
    out = measure.boundary_lengths(v, uv, [np.array([0, 1, 2, 3])])
    np.testing.assert_allclose(out, [[10.0, 20.0]])
