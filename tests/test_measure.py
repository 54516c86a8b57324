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
    assert len(measure.folded_faces(uv, f)) == len(f)
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


def _svd_stretches(v, f, uv):
    """Principal stretches (m, 2), descending, by an SVD of each triangle's 2x2 map (computed here)."""
    out = np.empty((len(f), 2))
    for t, (a, b, c) in enumerate(f):
        e1, e2 = v[b] - v[a], v[c] - v[a]
        x = e1 / np.linalg.norm(e1)
        y = e2 - (e2 @ x) * x
        y /= np.linalg.norm(y)
        local = np.array([[e1 @ x, e2 @ x], [e1 @ y, e2 @ y]])  # columns: the edges in the triangle's frame
        flat = np.column_stack([uv[b] - uv[a], uv[c] - uv[a]])
        out[t] = np.linalg.svd(flat @ np.linalg.inv(local), compute_uv=False)
    return out


def test_the_distortion_summary_against_independent_numbers():
    """Every field of Distortion recomputed here from an SVD per triangle and plain edge lengths."""
    rng = np.random.default_rng(11)
    v, f = surfaces.spherical_cap(radius=100.0, half_angle=40.0, n_faces=400)
    uv = v[:, :2] * [1.03, 0.98] + rng.normal(scale=0.2, size=(len(v), 2))  # a rough, fold-free layout
    _, _, conn = validate_mesh(v, f)
    d = measure.distortion(v, f, uv, loops=conn.loops)
    s = _svd_stretches(v, f, uv)
    p = v[f]
    area = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
    w = area / area.sum()
    assert d.strain_rms == pytest.approx(np.sqrt(0.5 * w @ ((s - 1) ** 2).sum(axis=1)), rel=1e-9)
    assert d.strain_max == pytest.approx(np.abs(s - 1).max(), rel=1e-9)
    assert d.symmetric_dirichlet == pytest.approx(w @ (s**2 + s**-2).sum(axis=1), rel=1e-9)
    order = np.argsort(s[:, 1])
    p1 = s[order, 1][np.searchsorted(np.cumsum(area[order]), 0.01 * area.sum())]
    assert d.stretch_p1 == pytest.approx(p1, rel=1e-9)
    assert d.stretch_min == pytest.approx(s[:, 1].min(), rel=1e-9)
    assert d.stretch_max == pytest.approx(s[:, 0].max(), rel=1e-9)
    edges = {tuple(sorted(e)) for t in f for e in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0]))}
    e = np.array(sorted(edges))
    ratio = np.linalg.norm(uv[e[:, 1]] - uv[e[:, 0]], axis=1) / np.linalg.norm(v[e[:, 1]] - v[e[:, 0]], axis=1)
    assert d.edge_strain_rms == pytest.approx(np.sqrt(np.mean((ratio - 1) ** 2)), rel=1e-9)
    assert d.edge_strain_max == pytest.approx(np.abs(ratio - 1).max(), rel=1e-9)
    assert d.area_3d == pytest.approx(area.sum(), rel=1e-12)
    q = uv[f]
    signed = 0.5 * ((q[:, 1, 0] - q[:, 0, 0]) * (q[:, 2, 1] - q[:, 0, 1])
                    - (q[:, 1, 1] - q[:, 0, 1]) * (q[:, 2, 0] - q[:, 0, 0]))
    assert d.area_flat == pytest.approx(signed.sum(), rel=1e-12) and d.n_folded == 0 == np.sum(signed <= 0)
    ring = [np.r_[loop, loop[:1]] for loop in conn.loops]
    assert d.boundary_3d == pytest.approx(sum(np.linalg.norm(np.diff(v[r], axis=0), axis=1).sum() for r in ring))
    assert d.boundary_flat == pytest.approx(sum(np.linalg.norm(np.diff(uv[r], axis=0), axis=1).sum() for r in ring))
    # one triangle folded: counted, and the symmetric Dirichlet energy is infinite
    folded = uv.copy()
    tri = f[len(f) // 2]
    folded[tri[0]] = folded[tri[1]] + folded[tri[2]] - folded[tri[0]]  # reflected across the opposite side
    df = measure.distortion(v, f, folded)
    assert np.isnan(df.boundary_3d) and np.isnan(df.boundary_flat)  # no loops given: not measured
    q = folded[f]
    signed = ((q[:, 1, 0] - q[:, 0, 0]) * (q[:, 2, 1] - q[:, 0, 1]) - (q[:, 1, 1] - q[:, 0, 1]) * (q[:, 2, 0] - q[:, 0, 0]))
    assert df.n_folded == np.sum(signed <= 0) >= 1 and df.symmetric_dirichlet == float("inf")


@pytest.mark.parametrize(("sx", "sy", "angle"), [(1.05, 1.0, 0.0), (1.0, 0.95, np.pi / 2), (1.0, 1.05, np.pi / 2),
                                                 (0.97, 1.0, 0.0)])
def test_dominant_strain_direction_is_the_axis_it_acts_along(flat_disk, sx, sy, angle):
    """A plane stretched (or squeezed) along x or y: the dominant strain's direction is that axis."""
    v, f = flat_disk
    ts = measure.triangle_strains(v, f, v[:, :2] * [sx, sy])
    np.testing.assert_allclose(ts.dominant, (sx - 1) if sx != 1 else (sy - 1), atol=1e-12)
    dist = np.minimum(np.abs(ts.direction - angle), np.pi - np.abs(ts.direction - angle))
    assert np.all(dist < 1e-9)
    assert not ts.direction.flags.writeable and not ts.stretch.flags.writeable


def test_folded_means_not_positive_at_any_size():
    """A flat triangle counts as folded when its signed area is not positive -- zero included
    (collapsed) -- whatever its size: a mesh of 0.01 mm triangles laid flat unchanged has none."""
    x, y = np.meshgrid(np.linspace(0.0, 0.05, 6), np.linspace(0.0, 0.05, 6))
    v = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    k = np.arange(30).reshape(5, 6)[:, :5].ravel()
    f = np.vstack([np.column_stack([k, k + 1, k + 7]), np.column_stack([k, k + 7, k + 6])])
    uv = v[:, :2].copy()
    assert measure.distortion(v, f, uv).n_folded == 0  # triangles of 5e-5 mm^2, all positive
    collapsed = uv.copy()
    collapsed[7] = (collapsed[0] + collapsed[1]) / 2  # vertex 7 onto the side 0-1: triangle (0, 1, 7) collapses
    sa = 0.5 * ((collapsed[f[:, 1]] - collapsed[f[:, 0]])[:, 0] * (collapsed[f[:, 2]] - collapsed[f[:, 0]])[:, 1]
                - (collapsed[f[:, 1]] - collapsed[f[:, 0]])[:, 1] * (collapsed[f[:, 2]] - collapsed[f[:, 0]])[:, 0])
    assert np.any(sa == 0.0)
    assert measure.distortion(v, f, collapsed).n_folded == int(np.count_nonzero(sa <= 0.0))
    np.testing.assert_array_equal(measure.folded_faces(collapsed, f), np.flatnonzero(sa <= 0.0))


def test_no_strain_is_an_isometry_read_only():
    """What an exact development reports: two stretches of 1 per triangle, strains 0, the 3D areas as
    weights -- and, like every TriangleStrain, arrays nobody can change afterwards."""
    v = np.array([[0, 0, 0], [4, 0, 0], [0, 3, 0], [0, 0, 5]], dtype=float)
    f = np.array([[0, 1, 2], [0, 1, 3]])
    ts = measure.no_strain(v, f)
    np.testing.assert_array_equal(ts.stretch, np.ones((2, 2)))
    np.testing.assert_array_equal(ts.strain, np.zeros((2, 2)))
    np.testing.assert_array_equal(ts.area_3d, [6.0, 10.0])
    for name in ("stretch", "strain", "dominant", "direction", "area_change", "area_3d"):
        with pytest.raises(ValueError, match="read-only"):
            getattr(ts, name)[0] = 7.0


@pytest.mark.parametrize("angle", [0.0, 0.7, -2.5, np.pi])
def test_best_turn_recovers_a_known_rotation_and_never_mirrors(angle):
    """Points turned by a known angle (and nudged) come back with that angle; their mirror image gives a
    turn, not a reflection (the blank's faces and the pinned start are placed by it)."""
    rng = np.random.default_rng(5)
    p = rng.normal(size=(12, 2))
    p -= p.mean(axis=0)
    c, s = np.cos(angle), np.sin(angle)
    q = np.column_stack([p[:, 0] * c - p[:, 1] * s, p[:, 0] * s + p[:, 1] * c])
    turn = measure.best_turn(p, q)
    assert abs(np.angle(np.exp(1j * (turn - angle)))) < 1e-12
    mirrored = p * [-1.0, 1.0]
    t = measure.best_turn(p, mirrored)
    residual = lambda a: np.linalg.norm(p @ np.array([[np.cos(a), np.sin(a)], [-np.sin(a), np.cos(a)]]) - mirrored)
    assert residual(t) <= min(residual(a) for a in np.linspace(-np.pi, np.pi, 3601)) + 1e-9
