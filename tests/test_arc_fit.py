"""Issue 34: ``arcs=True`` fits true circles at the default tolerance, and stays within it elsewhere.

Checked against independent references: the CAD values (the README's box with an R20 hole, the
hopper's developed cone), analytic curves (circles, a rounded square, an ellipse) and exact
distances to them -- not against the fitter's own arithmetic.
"""

from math import hypot, pi

import build123d as bd
import ezdxf
import numpy as np
import pytest

import patterns
from patterns.pieces.arcs import arc_points, fit_arcs

from .conftest import SAMPLES

TOL = 0.01  # mm: PieceOptions.arc_tolerance's default


def segments(rows):
    """``(radius, sweep, centre)`` of every segment of a closed bulged polyline (radius inf: a line)."""
    rows = np.asarray(rows, dtype=np.float64)
    out = []
    for k in range(len(rows)):
        a, b, bulge = rows[k, :2], rows[(k + 1) % len(rows), :2], rows[k, 2]
        if bulge == 0:
            out.append((np.inf, 0.0, None))
            continue
        sweep = 4 * np.arctan(bulge)
        chord = hypot(*(b - a))
        radius = chord / (2 * abs(np.sin(sweep / 2)))
        normal = np.array([a[1] - b[1], b[0] - a[0]]) / chord
        centre = 0.5 * (a + b) + normal * np.sign(bulge) * np.sqrt(max(radius**2 - chord**2 / 4, 0.0))
        out.append((radius, sweep, centre))
    return out


def points_to_contour(points, fitted):
    """Largest distance of ``points`` from the fitted contour, exactly: to each line segment, or to each
    arc (to its circle where the point lies within its sweep, else to its nearer end)."""
    points = np.asarray(points, dtype=np.float64)
    rows = np.asarray(fitted, dtype=np.float64)
    best = np.full(len(points), np.inf)
    for k, (radius, sweep, centre) in enumerate(segments(rows)):
        a, b = rows[k, :2], rows[(k + 1) % len(rows), :2]
        ends = np.minimum(np.hypot(*(points - a).T), np.hypot(*(points - b).T))
        if np.isinf(radius):
            d = b - a
            u = np.clip((points - a) @ d / (d @ d), 0, 1)
            dist = np.hypot(*(points - a - u[:, None] * d).T)
        else:
            rel = points - centre
            start = np.arctan2(*(a - centre)[::-1])
            turned = np.mod((np.arctan2(rel[:, 1], rel[:, 0]) - start) * np.sign(sweep), 2 * pi)
            dist = np.where(turned <= abs(sweep), np.abs(np.hypot(*rel.T) - radius), ends)
        best = np.minimum(best, np.minimum(dist, ends))
    return float(best.max())


def ellipse_distance(points, a, b):
    """Exact distance of points (near it) to the ellipse x = a cos t, y = b sin t: Newton on t."""
    x, y = points[:, 0], points[:, 1]
    t = np.arctan2(y / b, x / a)
    for _ in range(30):
        c, s = np.cos(t), np.sin(t)
        f = (a * a - b * b) * s * c - x * a * s + y * b * c  # d/dt of half the squared distance, negated
        df = (a * a - b * b) * (c * c - s * s) - x * a * c - y * b * s
        t = t - f / df
    return np.hypot(x - a * np.cos(t), y - b * np.sin(t))


def circle(radius, n, start=0.0):
    t = start + np.linspace(0, 2 * pi, n, endpoint=False)
    return np.column_stack([radius * np.cos(t), radius * np.sin(t)])


def rounded_square(side, r, step, side_step=None):
    """Points of a ``side`` square from (0, 0) with corners of radius ``r``, counter-clockwise, about
    ``step`` apart (``side_step`` on the straight sides)."""
    straight = side - 2 * r
    k = max(1, int(np.ceil(straight / (side_step or step))))
    m = max(2, int(np.ceil(r * pi / 2 / step)))
    pts = []
    for start, direction, centre, a0 in [((r, 0), (1, 0), (side - r, r), -pi / 2),
                                         ((side, r), (0, 1), (side - r, side - r), 0.0),
                                         ((side - r, side), (-1, 0), (r, side - r), pi / 2),
                                         ((0, side - r), (0, -1), (r, r), pi)]:
        pts.append(np.asarray(start) + np.outer(np.arange(k) / k * straight, direction))
        t = a0 + np.linspace(0, pi / 2, m, endpoint=False)
        pts.append(np.column_stack([centre[0] + r * np.cos(t), centre[1] + r * np.sin(t)]))
    return np.vstack(pts)


def rounded_square_distance(points, side, r):
    """Exact distance of points to the rounded square's outline: |distance to the inner square - r|."""
    inner = np.clip(points, r, side - r)
    return np.abs(np.hypot(*(points - inner).T) - r)


# -- the README's box with a hole ------------------------------------------------------------------


@pytest.fixture(scope="module")
def box_dxf(tmp_path_factory):
    pattern = patterns.flatten(patterns.load(bd.Box(200, 100, 50) - bd.Cylinder(20, 50)))
    path = tmp_path_factory.mktemp("box") / "box.dxf"
    patterns.write(pattern, path, arcs=True)  # at the default arc_tolerance
    return ezdxf.readfile(path)


def test_the_box_holes_are_arcs_of_radius_20_with_no_straight_flat(box_dxf):
    msp = box_dxf.modelspace()
    holes = []
    for e in msp.query('LWPOLYLINE[layer=="CUT"]'):
        rows = np.array(e.get_points("xyb"))
        if np.ptp(rows[:, :2], axis=0).max() < 45:  # the R20 hole, not a face
            holes.append(segments(rows))
    circles = list(msp.query('CIRCLE[layer=="CUT"]'))
    assert len(holes) + len(circles) == 2  # top and bottom faces
    for c in circles:
        assert c.dxf.radius == pytest.approx(20.0, abs=TOL)
    for hole in holes:
        radii = np.array([r for r, _, _ in hole])
        assert np.all(np.isfinite(radii))  # no straight segment on the hole
        np.testing.assert_allclose(radii, 20.0, atol=TOL)
        centres = np.array([c for _, _, c in hole])
        assert np.ptp(centres, axis=0).max() <= TOL  # one circle, not arcs about different centres
        sweeps = np.array([s for _, s, _ in hole])
        assert abs(sweeps.sum()) == pytest.approx(2 * pi, abs=1e-9)  # once round
        length = float((radii * np.abs(sweeps)).sum())
        assert length == pytest.approx(2 * pi * 20.0, abs=2 * pi * TOL)


def test_the_box_straight_edges_stay_straight(box_dxf):
    """Every other cut contour is a rectangle of four straight segments: the faces, and the hole's
    wall developed to 2 pi 20 by 50 mm."""
    sizes = []
    for e in box_dxf.modelspace().query('LWPOLYLINE[layer=="CUT"]'):
        rows = np.array(e.get_points("xyb"))
        if np.ptp(rows[:, :2], axis=0).max() < 45:
            continue
        assert len(rows) == 4 and np.all(rows[:, 2] == 0)
        sizes.append(tuple(sorted(np.ptp(rows[:, :2], axis=0))))
    wall = [s for s in sizes if s[1] == pytest.approx(2 * pi * 20, abs=TOL)]
    assert len(wall) == 1 and wall[0][0] == pytest.approx(50.0, abs=1e-6)


def test_the_developed_cone_is_two_arcs_of_its_analytic_radii(tmp_path):
    """The hopper (radius 100 to 300 over 400 mm), meshed at the default chord tolerance: its blank
    is two arcs of radii R/sin a about the apex and two straight edges."""
    r1, r2, h = 100.0, 300.0, 400.0
    sin_a = (r2 - r1) / hypot(r2 - r1, h)
    path = tmp_path / "hopper.dxf"
    patterns.write(patterns.flatten(patterns.load(SAMPLES / "hopper.step")), path, arcs=True)
    (cut,) = ezdxf.readfile(path).modelspace().query('LWPOLYLINE[layer=="CUT"]')
    segs = segments(np.array(cut.get_points("xyb")))
    radii = sorted(r for r, _, _ in segs if np.isfinite(r))
    assert len(segs) == 4 and len(radii) == 2
    assert radii == pytest.approx([r1 / sin_a, r2 / sin_a], abs=TOL)
    for r, sweep, _ in segs:
        if np.isfinite(r):
            assert abs(sweep) == pytest.approx(2 * pi * sin_a, abs=TOL / r)


# -- fit_arcs on analytic curves -------------------------------------------------------------------


@pytest.mark.parametrize("radius, n", [(20.0, 45), (20.0, 17), (5.0, 24), (20.0, 360), (500.0, 200), (0.5, 40)])
@pytest.mark.parametrize("start", [0.0, 0.37])
def test_points_on_a_circle_are_arcs_of_that_circle(radius, n, start):
    """However coarse the polygon (its chords sag by up to 0.6 mm here), its points lie on the circle,
    so the fit is arcs of that radius all the way round: no straight flat where the greedy run ends."""
    loop = circle(radius, n, start)
    segs = segments(fit_arcs(loop, TOL))
    radii = np.array([r for r, _, _ in segs])
    assert np.all(np.isfinite(radii))
    np.testing.assert_allclose(radii, radius, atol=TOL)
    assert sum(s for _, s, _ in segs) == pytest.approx(2 * pi, abs=1e-9)


@pytest.mark.parametrize("n", [45, 90, 720])
def test_noisy_points_on_a_circle_are_still_arcs_of_it(n):
    """Points scattered by a quarter of the tolerance off the circle (a flattening's noise)."""
    rng = np.random.default_rng(n)
    loop = circle(20.0, n) * (1 + rng.uniform(-0.25, 0.25, size=(n, 1)) * TOL / 20.0)
    fitted = fit_arcs(loop, TOL)
    radii = np.array([r for r, _, _ in segments(fitted)])
    assert np.all(np.isfinite(radii)) and len(fitted) <= 6
    np.testing.assert_allclose(radii, 20.0, atol=TOL)
    assert points_to_contour(loop, fitted) <= TOL * (1 + 1e-6)


@pytest.mark.parametrize("step", [0.5, 2.0, 5.0])
@pytest.mark.parametrize("noise", [0.0, 0.25])
def test_a_rounded_square_stays_within_the_tolerance_of_its_points(step, noise):
    """A rounded square (100 mm, corners R10) sampled as points, some noisy: every input point lies
    within the tolerance of the output, the output near the true outline, the sides straight."""
    side, r = 100.0, 10.0
    loop = rounded_square(side, r, step)
    np.testing.assert_allclose(rounded_square_distance(loop, side, r), 0, atol=1e-9)  # the reference
    loop = loop + np.random.default_rng(7).uniform(-noise * TOL, noise * TOL, size=loop.shape)
    fitted = fit_arcs(loop, TOL)
    assert points_to_contour(loop, fitted) <= TOL * (1 + 1e-6)  # measured
    dense = arc_points(fitted, step=0.01)
    assert rounded_square_distance(dense, side, r).max() <= TOL * (1 + noise) + 1e-6
    assert {tuple(p) for p in fitted[:, :2]} <= {tuple(p) for p in loop}  # no point moves
    lines = [s for s in segments(fitted) if not np.isfinite(s[0])]
    assert len(lines) >= 4 and len(fitted) <= 12


def test_a_rounded_square_with_one_chord_per_side_keeps_its_sides_straight():
    """Each side one 80 mm chord between densely sampled corners: three points are always on some
    circle, but a long chord beside a curve is a straight edge, not an arc bulging off it."""
    side, r = 100.0, 10.0
    loop = rounded_square(side, r, 1.0, side_step=100.0)
    assert np.hypot(*np.diff(loop, axis=0).T).max() > 79  # the sides are single chords
    fitted = fit_arcs(loop, TOL)
    assert points_to_contour(loop, fitted) <= TOL * (1 + 1e-6)
    assert rounded_square_distance(arc_points(fitted, step=0.01), side, r).max() <= TOL + 1e-6


def test_a_polygon_keeps_its_corners():
    """An octagon given by its corners only: turns of 45 degrees are corners, not a coarse circle."""
    loop = circle(50.0, 8)
    fitted = fit_arcs(loop, TOL)
    assert len(fitted) == 8 and np.all(fitted[:, 2] == 0)


@pytest.mark.parametrize("tolerance", [0.01, 0.1])
@pytest.mark.parametrize("n", [180, 2000])
def test_an_ellipse_stays_within_the_tolerance(n, tolerance):
    """An ellipse (100 by 40 mm; no arc is exact on it) sampled coarsely or densely: every point lies
    within the tolerance of the fit, and the fit within it of the true ellipse."""
    t = np.linspace(0, 2 * pi, n, endpoint=False)
    loop = np.column_stack([100 * np.cos(t), 40 * np.sin(t)])
    fitted = fit_arcs(loop, tolerance)
    assert points_to_contour(loop, fitted) <= tolerance * (1 + 1e-6)
    np.testing.assert_allclose(ellipse_distance(loop, 100, 40), 0, atol=1e-9)  # the reference
    dense = arc_points(fitted, step=tolerance / 4)
    assert ellipse_distance(dense, 100, 40).max() <= 1.01 * tolerance  # measured: at most 0.998
    assert len(fitted) <= n / 5 and np.all(fitted[:, 2] != 0)  # arcs, and far fewer than the points
