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


def _rectangles(sizes, name="rects"):
    """Flat rectangles ``(width along x, height along y)`` mm, as panels with their grain along +Y."""
    from patterns.reading import mesh_model

    vs, fs, offset = [], [], 0
    for k, (w, h) in enumerate(sizes):
        x, y = np.meshgrid(np.linspace(0, w, 5), np.linspace(0, h, 3))
        grid = np.column_stack([x.ravel(), y.ravel(), np.full(x.size, 500.0 * k)])
        quads = [(r * 5 + c, r * 5 + c + 1, (r + 1) * 5 + c + 1, (r + 1) * 5 + c) for r in range(2) for c in range(4)]
        tri = np.array([t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))])
        vs.append(grid)
        fs.append(tri + offset)
        offset += len(grid)
    return patterns.flatten(mesh_model(np.vstack(vs), np.vstack(fs), name=name), method="isometric",
                            grain=(0, 1, 0))


def test_four_equal_rectangles_pack_two_by_two():
    """Four 100 x 50 rectangles on a 211 mm roll with a 10 mm gap: two fit side by side, so the
    shortest marker is two rows, 50 + 10 + 50 = 110 mm long.  The nester keeps 0.5 mm more than
    the gap (its collision shapes are simplified within 0.25 mm and widened by as much), so two
    rows take at most 110.5 mm, and three rows (171 mm) would mean a worse search."""
    pattern = _rectangles([(100.0, 50.0)] * 4)
    nest = pattern.layout(width=211.0, gap=10.0, allow_rotation=False, step=1.0)
    assert 110.0 <= nest.length <= 110.5 + 1e-6
    assert nest.efficiency == pytest.approx(4 * 100 * 50 / (211.0 * nest.length), rel=1e-9)


def test_a_long_panel_is_turned_across_only_when_the_grain_may_turn():
    """A 300 x 40 panel on a 100 mm roll fits only turned by 90 degrees: allowed without the
    grain, refused with it (the grain must stay along the roll) or without rotation."""
    pattern = _rectangles([(300.0, 40.0)])
    nest = pattern.layout(width=100.0, respect_grain=False)
    (flat,) = nest.pattern.panels
    turned = flat.placement[0] % np.pi
    assert abs(turned - np.pi / 2) < 1e-9
    assert np.ptp(flat.uv[:, 0]) == pytest.approx(40.0, abs=1e-6) and nest.length == pytest.approx(300.0, abs=1e-6)
    for kwargs in ({"respect_grain": True}, {"respect_grain": False, "allow_rotation": False}):
        with pytest.raises(LayoutError, match="wider than the 100 mm roll"):
            pattern.layout(width=100.0, **kwargs)


def test_the_margin_is_kept_around_each_outline():
    """A margin (a seam allowance added later) keeps the outlines gap + 2 x margin apart."""
    nest = _rectangles([(100.0, 50.0)] * 3).layout(width=400.0, gap=10.0, margin=5.0)
    polys = _outlines(nest.pattern)
    assert min(polys[i].distance(polys[j]) for i in range(3) for j in range(i + 1, 3)) >= 20.0 - 1e-6
    x = np.concatenate([np.asarray(p.exterior.coords)[:, 0] for p in polys])
    assert x.min() >= 5.0 - 1e-6 and x.max() <= 400.0 - 5.0 + 1e-6  # the margin inside the roll too


@pytest.mark.parametrize(("kwargs", "words"), [({"width": 0.0}, "width"), ({"width": 100.0, "gap": -1.0}, "gap"),
                                               ({"width": 100.0, "margin": -1.0}, "margin"),
                                               ({"width": 100.0, "step": 0.0}, "step")])
def test_bad_layout_options(plates, kwargs, words):
    """One line naming the pattern and the option."""
    from patterns.errors import InputError

    with pytest.raises(InputError, match=rf"^{plates.name}: {words} \(mm\) must"):
        plates.layout(**kwargs)


def test_small_numbers_are_options_not_errors(plates):
    """Sub-millimetre widths and gaps are numbers like any other: a 0.5 mm roll is too narrow
    for the panels (a LayoutError), a 0.5 mm gap is kept."""
    from patterns.errors import InputError

    with pytest.raises(LayoutError, match="wider than"):
        plates.layout(width=0.5)
    nest = plates.layout(width=450.0, gap=0.5)
    polys = _outlines(nest.pattern)
    assert min(polys[i].distance(polys[j]) for i in range(len(polys)) for j in range(i + 1, len(polys))) >= 0.5 - 1e-6
    with pytest.raises(InputError, match="layout\\(\\) takes a patterns.Pattern"):
        patterns.layout(type("Almost", (), {"panels": (), "name": "x"})(), width=100.0)


def test_the_orientations_tried():
    from patterns.nesting import _orientations

    assert _orientations(True, True) == [0.0, np.pi]  # grain kept: turned end for end at most
    assert _orientations(False, True) == [0.0] and _orientations(False, False) == [0.0]
    assert _orientations(True, False) == [0.0, 0.5 * np.pi, np.pi, 1.5 * np.pi]


def test_the_defaults_are_those_documented(plates):
    """gap 10 mm, no margin, rotation allowed, grain kept: the same marker as asked for in full."""
    default = patterns.layout(plates, width=450.0)  # the function's own defaults
    explicit = plates.layout(width=450.0, gap=10.0, margin=0.0, allow_rotation=True, respect_grain=True)
    assert [f.placement for f in default.pattern.panels] == [f.placement for f in explicit.pattern.panels]
    assert default.width == 450.0 and default.length == explicit.length
    for other in ({"gap": 11.0}, {"margin": 1.0}, {"respect_grain": False}):
        changed = plates.layout(width=450.0, **other)
        assert [f.placement for f in changed.pattern.panels] != [f.placement for f in default.pattern.panels]


def test_a_panel_laid_askew_is_squared_up_and_placed_where_its_outline_is():
    """Without the grain, a rectangle drawn at 30 degrees is turned square to the roll first: the
    placed outline, read from the placed panel, is axis-aligned, inside the roll, and the length is
    its top."""
    from patterns.reading import mesh_model

    c, s = np.cos(np.radians(30)), np.sin(np.radians(30))
    x, y = np.meshgrid(np.linspace(0, 120, 7), np.linspace(0, 40, 3))
    pts = np.column_stack([x.ravel(), y.ravel()]) @ np.array([[c, s], [-s, c]])
    quads = [(r * 7 + k, r * 7 + k + 1, (r + 1) * 7 + k + 1, (r + 1) * 7 + k) for r in range(2) for k in range(6)]
    tri = np.array([t for a, b, cc, d in quads for t in ((a, b, cc), (a, cc, d))])
    pattern = patterns.flatten(mesh_model(np.column_stack([pts, np.zeros(len(pts))]), tri, name="askew"),
                               method="isometric")
    nest = pattern.layout(width=200.0, respect_grain=False, allow_rotation=False)
    (poly,) = _outlines(nest.pattern)
    x0, y0, x1, y1 = poly.bounds
    assert poly.area == pytest.approx(120 * 40, rel=1e-9)
    assert (x1 - x0) * (y1 - y0) == pytest.approx(120 * 40, rel=1e-6)  # squared up: its box is itself
    assert x0 >= -1e-6 and x1 <= 200.0 + 1e-6 and y0 >= -1e-6
    assert nest.length == pytest.approx(y1, abs=1e-6) and nest.width == 200.0
