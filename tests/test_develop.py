"""patterns.flattening.develop: exact developments of planes, cylinders and cones against their
analytic formulas, and the neutral surface of a sheet."""

import re

import numpy as np
import pytest

import patterns
from patterns.errors import InputError
from patterns.flattening.develop import develop, neutral_offset, offset_points
from patterns.measure import signed_areas
from patterns.model import Surface, SurfaceKind

X, Y, Z = np.eye(3)


def _surface(kind, **extra):
    return Surface(kind=kind, origin=np.zeros(3), x_dir=X, y_dir=Y, axis=Z, **extra)


def test_a_plane_develops_to_its_own_frame():
    plane = Surface(kind=SurfaceKind.PLANE, origin=np.array([1.0, 2.0, 3.0]), x_dir=Y, y_dir=-X, axis=Z)
    pts = np.array([[1.0, 2.0, 3.0], [1.0, 7.0, 3.0], [-3.0, 2.0, 3.0]])
    np.testing.assert_allclose(develop(plane, pts), [[0, 0], [5, 0], [0, 4]], atol=1e-12)


def test_a_cylinder_unrolls_to_radius_times_angle():
    r = 40.0
    u = np.linspace(0.1, 4.0, 9)
    v = np.linspace(-5.0, 30.0, 9)
    pts = np.column_stack([r * np.cos(u), r * np.sin(u), v])
    uv = develop(_surface(SurfaceKind.CYLINDER, radius=r), pts)
    np.testing.assert_allclose(uv[:, 0] - uv[0, 0], r * (u - u[0]), rtol=1e-12)
    np.testing.assert_allclose(uv[:, 1], v, atol=1e-12)


def test_a_cone_unrolls_to_an_annular_sector():
    """Cone of half-angle a with reference radius R at height 0: a point at angle u and height h
    lies at distance s = (R + h tan a) / sin a from the apex, at angle u sin a in the sector."""
    a, big_r = np.radians(30.0), 50.0
    u = np.linspace(0.0, 5.0, 7)
    h = np.linspace(0.0, 40.0, 7)
    rr = big_r + h * np.tan(a)
    pts = np.column_stack([rr * np.cos(u), rr * np.sin(u), h])
    uv = develop(_surface(SurfaceKind.CONE, radius=big_r, semi_angle=a), pts)
    s = rr / np.sin(a)
    np.testing.assert_allclose(np.hypot(uv[:, 0], uv[:, 1]), s, rtol=1e-12)
    angles = np.unwrap(np.arctan2(uv[:, 1], uv[:, 0]))
    np.testing.assert_allclose(angles - angles[0], (u - u[0]) * np.sin(a), atol=1e-12)


def test_the_seam_side_is_chosen_by_the_parameter():
    """The same 3D point on both sides of a cylinder's seam line: the parameter says which end."""
    r = 10.0
    pts = np.array([[r, 0.0, 0.0], [r, 0.0, 0.0]])
    uv = develop(_surface(SurfaceKind.CYLINDER, radius=r), pts, param=np.array([[0.0, 0.0], [2 * np.pi, 0.0]]))
    assert uv[1, 0] - uv[0, 0] == pytest.approx(2 * np.pi * r, rel=1e-12)


@pytest.mark.parametrize(("reference", "expected"), [("inside", 0.88), ("outside", -1.12), ("mid", -0.12)])
def test_the_neutral_surface_lies_k_t_from_the_inside_skin(reference, expected):
    """t = 2 mm, K = 0.44: the neutral surface is 0.88 mm from the inside skin."""
    assert neutral_offset(2.0, 0.44, reference) == pytest.approx(expected, abs=1e-12)


@pytest.mark.parametrize(("kwargs", "words"), [
    ({"thickness": -1.0}, "thickness (mm) must be a number >= 0, got -1.0"),
    ({"k_factor": 1.5}, "k_factor must be a number between 0 and 1, got 1.5"),
    ({"reference": "middle"}, "reference must be one of inside, outside, mid, got 'middle'")])
def test_bad_sheet_options_are_refused(kwargs, words):
    """One line naming the part (``name``, default "pattern") and what is wrong."""
    args = {"thickness": 2.0, "k_factor": 0.5, "reference": "mid", **kwargs}
    with pytest.raises(InputError, match="^" + re.escape(f"bracket: {words}") + "$"):
        neutral_offset(args["thickness"], args["k_factor"], args["reference"], name="bracket")
    with pytest.raises(InputError, match="^" + re.escape(f"pattern: {words}") + "$"):
        neutral_offset(args["thickness"], args["k_factor"], args["reference"])


def test_an_exact_development_says_so_and_runs_counter_clockwise_at_any_size():
    """Every face of a 1 x 0.5 x 0.2 mm box (0.1 to 0.5 mm^2) is developed exactly: method "exact",
    no grower's seed (-1), started from the analytic development, every triangle counter-clockwise."""
    import build123d as bd

    pattern = patterns.flatten(patterns.load(bd.Box(1, 0.5, 0.2)))
    assert sorted(round(f.area, 9) for f in pattern.panels) == [0.1, 0.1, 0.2, 0.2, 0.5, 0.5]
    for flat in pattern.panels:
        result = flat.flattening
        assert (result.method, result.seed_face, result.start) == ("exact", -1, "analytic")
        assert np.all(signed_areas(flat.uv, flat.faces) > 0)


@pytest.mark.parametrize("offset", [1.5, 1.0, -2.0])
def test_offsetting_a_cylinder_moves_points_radially(offset):
    r = 40.0
    u = np.linspace(0.0, 3.0, 5)
    pts = np.column_stack([r * np.cos(u), r * np.sin(u), np.arange(5.0)])
    moved = offset_points(_surface(SurfaceKind.CYLINDER, radius=r), pts, offset)
    np.testing.assert_allclose(np.hypot(moved[:, 0], moved[:, 1]), r + offset, rtol=1e-12)
    np.testing.assert_allclose(moved[:, 2], pts[:, 2], atol=1e-12)


@pytest.mark.parametrize(("apex", "samples", "tol"), [((0.0, 0.0, 0.0), None, 1e-7),
                                                     ((30.0, -20.0, 50.0), 61, 1e-9)])
def test_a_general_cone_unrolls_by_its_directrix(apex, samples, tol):
    """A right circular cone given as a general cone (apex and a sampled directrix, as a
    square-to-round transition's corner faces are): the same polar development as the analytic
    cone, between the directrix's samples too -- with the apex anywhere, and the directrix
    sampled unevenly (61 samples at random spacing: each point's angle is interpolated between
    two unequal steps)."""
    a, height = np.radians(25.0), 200.0
    if samples is None:
        u = np.linspace(0.0, 2 * np.pi / 3, 2001)
    else:
        u = np.sort(np.r_[0.0, np.random.default_rng(7).uniform(0.0, 2 * np.pi / 3, samples - 2), 2 * np.pi / 3])
    rim = height * np.tan(a)
    apex = np.asarray(apex)
    directrix = apex + np.column_stack([rim * np.cos(u), rim * np.sin(u), np.full(len(u), height)])
    cone = Surface(kind=SurfaceKind.GENERAL_CONE, origin=apex, x_dir=np.zeros(3), y_dir=np.zeros(3),
                   axis=np.zeros(3), directrix=directrix)
    rng = np.random.default_rng(4)
    pu = rng.uniform(0.01, 2 * np.pi / 3 - 0.01, 40)  # between samples
    h = rng.uniform(20.0, 190.0, 40)
    if samples is not None:  # on the sampled (polyhedral) cone: between two directrix points, linearly
        k = np.clip(np.searchsorted(u, pu) - 1, 0, len(u) - 2)
        w = (pu - u[k]) / (u[k + 1] - u[k])
        ring = (1 - w)[:, None] * directrix[k] + w[:, None] * directrix[k + 1] - apex
        pts = apex + ring * (h / height)[:, None]
        # Its development, by hand: distance from the apex, and the angle the cone's own sector
        # gives (the chord angles of the directrix seen from the apex, summed), interpolated by
        # the angle within the step.
        d = (directrix - apex) / np.linalg.norm(directrix - apex, axis=1)[:, None]
        steps = np.arccos(np.clip((d[1:] * d[:-1]).sum(axis=1), -1, 1))
        theta = np.r_[0.0, np.cumsum(steps)]
        r = ring / np.linalg.norm(ring, axis=1)[:, None]
        within = np.arccos(np.clip((r * d[k]).sum(axis=1), -1, 1))
        expect_s, expect_angle = np.linalg.norm(pts - apex, axis=1), theta[k] + within
        # and on the directrix's own lines, its first and last included: the angle turned so far
        on = apex + (directrix - apex) * rng.uniform(0.1, 0.95, len(u))[:, None]
        pts = np.vstack([pts, on])
        expect_s, expect_angle = np.r_[expect_s, np.linalg.norm(on - apex, axis=1)], np.r_[expect_angle, theta]
    else:
        pts = apex + np.column_stack([h * np.tan(a) * np.cos(pu), h * np.tan(a) * np.sin(pu), h])
        expect_s, expect_angle = h / np.cos(a), pu * np.sin(a)
    uv = develop(cone, np.vstack([apex, pts]))
    np.testing.assert_allclose(uv[0], 0.0, atol=1e-12)  # the apex
    np.testing.assert_allclose(np.hypot(uv[1:, 0], uv[1:, 1]), expect_s, rtol=1e-12)
    angle = np.arctan2(uv[1:, 1], uv[1:, 0])  # from the directrix's first line (all within half a turn)
    np.testing.assert_allclose(angle, expect_angle, atol=tol)


def test_offsetting_small_triangles_moves_by_the_offset_along_the_normal():
    """A fine freeform mesh (triangles well under 1 mm^2): every vertex moves by exactly the
    offset, along the unit normal of the surface (a sphere: radially)."""
    from patterns import surfaces
    from patterns.flattening.develop import offset_along_normals
    from patterns.mesh import validate_mesh
    from patterns.model import Panel

    v, f = surfaces.spherical_cap(radius=5.0, half_angle=40.0, n_faces=2000)  # areas ~0.01 mm^2
    v, f, conn = validate_mesh(v, f)
    moved = offset_along_normals(Panel("cap", v, f, conn.loops), 0.3)
    np.testing.assert_allclose(np.linalg.norm(moved - v, axis=1), 0.3, rtol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(v, axis=1), 5.0, rtol=1e-9)  # the cap's sphere: centred at 0
    np.testing.assert_allclose(np.linalg.norm(moved, axis=1), 5.3, rtol=1e-3)  # outwards, about radially
