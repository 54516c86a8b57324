"""patterns.pieces.arcs: arcs and lines fitted to outlines, against the exact curves."""

import numpy as np
import pytest
import shapely

from patterns.pieces.arcs import arc_points, fit_arcs


def test_a_sampled_circle_becomes_a_few_arcs_on_the_circle():
    r, n = 50.0, 400
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    loop = np.column_stack([r * np.cos(t), r * np.sin(t)])
    fitted = fit_arcs(loop, 0.01)
    assert len(fitted) <= 4 and np.all(fitted[:, 2] > 0)  # counter-clockwise arcs only
    dense = arc_points(fitted, step=0.05)
    np.testing.assert_allclose(np.hypot(dense[:, 0], dense[:, 1]), r, atol=0.01)
    # the bulges add up to one full turn: sum of sweeps = 2 pi
    assert (4 * np.arctan(fitted[:, 2])).sum() == pytest.approx(2 * np.pi, rel=1e-9)


def test_a_square_is_four_lines_through_its_corners():
    side = np.linspace(0, 100, 21)[:-1]
    loop = np.concatenate([np.column_stack([side, 0 * side]), np.column_stack([100 + 0 * side, side]),
                           np.column_stack([100 - side, 100 + 0 * side]), np.column_stack([0 * side, 100 - side])])
    fitted = fit_arcs(loop, 0.01)
    assert len(fitted) == 4 and np.all(fitted[:, 2] == 0)
    assert {tuple(p) for p in fitted[:, :2]} == {(0.0, 0.0), (100.0, 0.0), (100.0, 100.0), (0.0, 100.0)}


@pytest.mark.parametrize("tolerance", [0.01, 0.1, 1.0])
def test_the_fit_stays_within_its_tolerance_both_ways(tolerance):
    """A wavy outline: every original point lies within the tolerance of the fitted contour, and
    every point of the fitted contour within the tolerance (plus one chord's sag) of the outline."""
    t = np.linspace(0, 2 * np.pi, 600, endpoint=False)
    rad = 80 + 6 * np.sin(5 * t)
    loop = np.column_stack([rad * np.cos(t), rad * np.sin(t)])
    fitted = fit_arcs(loop, tolerance)
    contour = shapely.LinearRing(arc_points(fitted, step=tolerance / 4))
    original = shapely.LinearRing(loop)
    assert max(contour.distance(shapely.Point(p)) for p in loop) <= tolerance * 1.01
    sag = np.max(np.linalg.norm(np.diff(loop, axis=0), axis=1)) ** 2 / (8 * rad.min())
    dense = arc_points(fitted, step=tolerance / 4)
    assert max(original.distance(shapely.Point(p)) for p in dense[::7]) <= tolerance + sag + 1e-9
    assert len(fitted) < len(loop) / 4  # far fewer entities than points
