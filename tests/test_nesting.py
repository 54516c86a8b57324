"""patterns.nesting: panels on a roll, checked with shapely on the placed outlines."""

import build123d as bd
import numpy as np
import pytest
import shapely

import patterns
from patterns.errors import LayoutError


@pytest.fixture(scope="module")
def plates():
    """Six flat rectangles (a box's faces): 200x100, 200x50, 100x50, two of each."""
    return patterns.flatten(patterns.load(bd.Box(200, 100, 50), max_edge=25))


def _outlines(pattern):
    return [shapely.Polygon(flat.uv[flat.loops[0]]) for flat in pattern.panels]


@pytest.mark.parametrize(("width", "gap"), [(450.0, 10.0), (230.0, 5.0)])
def test_placed_panels_keep_the_gap_and_the_roll(plates, width, gap):
    nest = plates.layout(width=width, gap=gap)
    polys = _outlines(nest.pattern)
    for i in range(len(polys)):
        for j in range(i + 1, len(polys)):
            assert polys[i].distance(polys[j]) >= gap - 1e-6
    x = np.concatenate([np.asarray(p.exterior.coords)[:, 0] for p in polys])
    y = np.concatenate([np.asarray(p.exterior.coords)[:, 1] for p in polys])
    assert x.min() >= -1e-6 and x.max() <= width + 1e-6
    assert nest.length == pytest.approx(y.max() - min(0.0, y.min()), abs=1e-6)
    area = sum(p.area for p in polys)
    assert area == pytest.approx(2 * (200 * 100 + 200 * 50 + 100 * 50), rel=1e-9)  # nothing rescaled
    assert nest.efficiency == pytest.approx(area / (width * nest.length), rel=1e-9)
    assert patterns.check(nest.pattern).ok  # the report's own overlap test agrees


def test_a_panel_wider_than_the_roll_is_refused(plates):
    with pytest.raises(LayoutError, match="wider than"):
        plates.layout(width=40.0, allow_rotation=False)


def test_the_grain_stays_along_the_roll(plates):
    """respect_grain: panels turn by 0 or 180 degrees only."""
    nest = plates.layout(width=450.0, respect_grain=True)
    for flat in nest.pattern.panels:
        angle = flat.placement[0] % np.pi
        assert min(angle, np.pi - angle) < 1e-9


def test_four_equal_rectangles_pack_two_by_two():
    """Four 100 x 50 rectangles on a 211 mm roll with a 10 mm gap: two fit side by side, so the
    shortest marker is two rows, 50 + 10 + 50 = 110 mm long.  The nester keeps 0.5 mm more than
    the gap (its collision shapes are simplified within 0.25 mm and widened by as much), so two
    rows take at most 110.5 mm, and three rows (171 mm) would mean a worse search."""
    from patterns.reading import mesh_model

    x, y = np.meshgrid(np.linspace(0, 100, 5), np.linspace(0, 50, 3))
    grid = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    quads = [(r * 5 + c, r * 5 + c + 1, (r + 1) * 5 + c + 1, (r + 1) * 5 + c) for r in range(2) for c in range(4)]
    tri = np.array([t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))])
    v = np.vstack([grid + [0, 0, 300.0 * k] for k in range(4)])
    f = np.vstack([tri + len(grid) * k for k in range(4)])
    pattern = patterns.flatten(mesh_model(v, f, name="rects"), method="isometric", grain=(0, 1, 0))  # axis-aligned
    nest = pattern.layout(width=211.0, gap=10.0, allow_rotation=False, step=1.0)
    assert 110.0 <= nest.length <= 110.5 + 1e-6
    assert nest.efficiency == pytest.approx(4 * 100 * 50 / (211.0 * nest.length), rel=1e-9)
