"""Corners where two bends meet: the square corner SolidWorks draws, the corner reliefs, and contour faults.

A tray whose four walls are folded up from a base meets at four closed corners: the two bend zones at
each end in a mitre (the model's curved edges).  The references are independent of the corner code:
the blank's size from the flange-plus-allowance sum, the perimeter of a rectilinear outline (that of
its bounding box), the relief shapes built from the bend lines and allowances (shapely), and
SolidWorks' own flat patterns of two real parts (``../shared/sheetmetal``).
"""

from __future__ import annotations

from pathlib import Path

import build123d as bd
import numpy as np
import pytest
import shapely

import patterns
from patterns.curves import Line

SHEETMETAL = Path(__file__).resolve().parent.parent.parent / "shared" / "sheetmetal"
W, D, H, T, R, K = 200.0, 150.0, 30.0, 2.0, 3.0, 0.44
ALLOWANCE = np.pi / 2 * (R + K * T)  # 90 degree bends, K from the inside


def _tray(tmp_path_factory, overshoot=0.0):
    """A tray: a W x D base, walls H high (outside), 2 mm sheet, inside radius 3; each corner closed by a
    0.1 mm mitre slit from the outside corner to where the bends begin, as a closed corner is modelled
    (``overshoot`` mm further: a slit that nicks the base)."""
    box = bd.Box(W, D, H, align=(bd.Align.CENTER, bd.Align.CENTER, bd.Align.MIN))
    box = bd.fillet(box.edges().filter_by(bd.Plane.XY).group_by(bd.Axis.Z)[0], radius=R + T)
    shell = bd.offset(box, amount=-T, openings=[box.faces().sort_by(bd.Axis.Z)[-1]])
    margin = 3 * T
    slit = bd.Pos(-margin, 0, 0) * bd.Box((R + T) * np.sqrt(2) + margin + overshoot, 0.1, 3 * H,
                                          align=(bd.Align.MIN, bd.Align.CENTER, bd.Align.CENTER))
    for sx in (1, -1):
        for sy in (1, -1):
            shell -= bd.Pos(sx * W / 2, sy * D / 2, H / 2) * bd.Rot(0, 0, np.degrees(np.arctan2(-sy, -sx))) * slit
    path = tmp_path_factory.mktemp("tray") / "tray.step"
    bd.export_step(shell, str(path))
    faces = shell.faces()
    inside = max((i for i, f in enumerate(faces) if f.geom_type == bd.GeomType.PLANE and abs(f.center().Z - T) < 1e-6),
                 key=lambda i: faces[i].area)  # the base's inside face: every wall's inside skin is developed
    return path, inside


@pytest.fixture(scope="module")
def tray(tmp_path_factory):
    return _tray(tmp_path_factory)


def _unfold(tray, relief):
    path, inside = tray
    return patterns.unfold(path, k_factor=K, fixed_face=inside, corner_relief=relief)


def test_closed_corners_are_square_as_solidworks_draws_them(tray):
    blank = _unfold(tray, "none")
    w, d = (W - 2 * (R + T)) + 2 * ALLOWANCE + 2 * (H - R - T), (D - 2 * (R + T)) + 2 * ALLOWANCE + 2 * (H - R - T)
    assert blank.size == pytest.approx((w, d), abs=1e-6)  # base + 2 bends + 2 walls, inside skin
    assert all(isinstance(p, Line) for p in blank.outline.pieces)  # no curved tongue left at any corner
    assert len(blank.outline.pieces) == 12  # four sides, four square notches of two edges each
    # a rectilinear outline with only inward notches is as long as its bounding box
    assert blank.perimeter == pytest.approx(2 * (w + d), abs=1e-6)
    assert blank.ok and not [f for f in blank.findings if f.code in (patterns.Code.OUTLINE_CUSP, patterns.Code.SLIVER)]


def test_as_modelled_keeps_the_tongues_and_every_relief_is_cut_where_the_bends_cross(tray):
    square = _unfold(tray, "none")
    modelled = _unfold(tray, "as-modelled")
    assert modelled.perimeter > square.perimeter + 4 * 5.0  # a tongue of several mm at each corner
    blank = square.outline.polygon
    centres = _crossings(square)
    assert len(centres) == 4
    half = ALLOWANCE / 2
    squares = shapely.union_all([shapely.box(*(c - half), *(c + half)) for c in centres])
    circles = shapely.union_all([shapely.Point(c).buffer(half * np.sqrt(2), quad_segs=512) for c in centres])
    rect = _unfold(tray, "rectangular")
    cut = blank.difference(rect.outline.polygon)
    assert cut.area == pytest.approx(blank.intersection(squares).area, abs=1e-6)  # the crossing squares, no more
    assert cut.symmetric_difference(blank.intersection(squares)).area < 1e-6
    rnd = _unfold(tray, "round")
    assert sum(isinstance(p, patterns.curves.Arc) for p in rnd.outline.pieces) == 4
    cut = blank.difference(shapely.Polygon(rnd.outline.points(1e-5)))
    assert cut.area == pytest.approx(blank.intersection(circles).area, rel=1e-4)  # the circle, sampled finely
    tear = _unfold(tray, "tear")
    assert square.area - 4 * ALLOWANCE ** 2 < tear.area < square.area  # a V taken out, less than the squares
    # every relief's outline passes through the inside corner of the base (a corner of a crossing square)
    for relief in (rect, tear):
        pts = np.vstack([p.points() for p in relief.outline.pieces])
        for c in centres:
            square_corners = c + half * np.array([[1, 1], [1, -1], [-1, 1], [-1, -1]])
            assert np.min(np.linalg.norm(pts[:, None] - square_corners[None], axis=2)) < 1e-6
    for relief in (rect, rnd, tear):  # a relief is a relief: no bend of a relieved corner is said to tear
        assert not [f for f in relief.findings if f.code is patterns.Code.MISSING_RELIEF]
    for b in rect.bends:  # bend lines stop at the relief: none runs into the cut square
        assert shapely.LineString(b.line).difference(rect.outline.polygon).length < 1e-6


def test_a_corner_developed_as_modelled_on_a_real_part_is_a_cusp_naming_its_face():
    if not SHEETMETAL.is_dir():
        pytest.skip(f"{SHEETMETAL} is absent (the shared SolidWorks parts)")
    blank = patterns.unfold(SHEETMETAL / "MMP.00.00.00.002_Back_panel.STEP", k_factor=0.47,
                            corner_relief="as-modelled")
    cusps = [f for f in blank.findings if f.code is patterns.Code.OUTLINE_CUSP]
    assert len(cusps) == 4  # one at each corner where two bends meet
    assert all("face " in f.message and "degrees" in f.message for f in cusps)
    square = patterns.unfold(SHEETMETAL / "MMP.00.00.00.002_Back_panel.STEP", k_factor=0.47)
    assert not [f for f in square.findings if f.code is patterns.Code.OUTLINE_CUSP]


def test_an_unknown_corner_relief_is_refused_naming_the_choices(tray):
    with pytest.raises(patterns.InputError, match="corner_relief must be one of none, rectangular, round, tear"):
        _unfold(tray, "square")


def test_a_mitre_that_nicks_the_base_still_closes_square(tmp_path_factory, tray):
    """The slit 0.03 mm too long cuts a sliver of the base between the two bend ends: the corner is the same."""
    nicked = _tray(tmp_path_factory, overshoot=0.03)
    blank, square = _unfold(nicked, "none"), _unfold(tray, "none")
    assert all(isinstance(p, Line) for p in blank.outline.pieces) and len(blank.outline.pieces) == 12
    assert blank.perimeter == pytest.approx(square.perimeter, abs=1e-6)
    rect = _unfold(nicked, "rectangular")
    assert blank.area - rect.area == pytest.approx(square.area - _unfold(tray, "rectangular").area, abs=0.1)


def test_a_strip_narrower_than_half_the_thickness_is_a_sliver(tmp_path):
    """A 2 mm plate with two slots 0.6 mm apart: the web between them is a sliver (narrower than 1 mm)."""
    plate = bd.Box(100, 60, 2) - bd.Pos(-10.3, 0, 0) * bd.Box(20, 10, 4) - bd.Pos(10.3, 0, 0) * bd.Box(20, 10, 4)
    blank = patterns.unfold(plate)
    (sliver,) = [f for f in blank.findings if f.code is patterns.Code.SLIVER]
    assert abs(sliver.points[0][0] - blank.outline.polygon.centroid.x) < 0.3 + 1e-6  # in the web, mid-plate
    assert sliver.severity is patterns.Severity.NOTE and blank.ok
    wide = patterns.unfold(bd.Box(100, 60, 2) - bd.Pos(-11, 0, 0) * bd.Box(20, 10, 4)
                           - bd.Pos(11, 0, 0) * bd.Box(20, 10, 4))  # a 2 mm web: no sliver
    assert not [f for f in wide.findings if f.code is patterns.Code.SLIVER]


def test_contours_that_touch_are_an_error():
    """A cut contour that crosses itself (a bow tie) is an ``outline-touches-itself`` error naming the part."""
    from patterns.curves import Loop
    from patterns.sheetmetal.contour import contour_faults

    bow = Loop.of_points(np.array([[0.0, 0.0], [10.0, 10.0], [10.0, 0.0], [0.0, 10.0]]))
    square = Loop.of_points(np.array([[-5.0, -5.0], [20.0, -5.0], [20.0, 20.0], [-5.0, 20.0]]))
    found = contour_faults([(square, (0,) * 4), (bow, (1,) * 4)], 1.0, "bow")
    (touch,) = [f for f in found if f.code is patterns.Code.OUTLINE_TOUCHES_ITSELF]
    assert touch.error and touch.message.startswith("bow: the cut contours touch or cross")
    assert not contour_faults([(square, (0,) * 4)], 1.0, "square")


def test_of_two_equal_sides_the_one_the_walls_rise_from_is_fixed(tray):
    """The base's two faces have one area; the inside one is fixed whatever order the file lists them in
    (from the outside, the 0.1 mm mitres' outside skins overlap: flanges-overlap)."""
    path, inside = tray
    blank = patterns.unfold(path, k_factor=K)
    assert blank.fixed_face == inside and blank.ok
    assert {b.direction for b in blank.bends} == {"up"}  # the walls rise towards the viewer
    faces = bd.import_step(str(path)).faces()
    outside = max((i for i, f in enumerate(faces) if f.geom_type == bd.GeomType.PLANE and abs(f.center().Z) < 1e-6),
                  key=lambda i: faces[i].area)
    assert faces[outside].area == pytest.approx(faces[inside].area, rel=1e-9)
    other = patterns.unfold(path, k_factor=K, fixed_face=outside)
    overlaps = [f for f in other.findings if f.code is patterns.Code.FLANGES_OVERLAP]
    assert not other.ok and len(overlaps) == 4  # each corner's two mitred outside skins


def _crossings(blank) -> list:
    """The points where two of the blank's bend lines cross (the tray's four corners)."""
    lines, out = [b.line for b in blank.bends], []
    for i in range(len(lines)):
        for j in range(i + 1, len(lines)):
            (p, q), (r, s) = lines[i], lines[j]
            m = np.column_stack([q - p, r - s])
            if abs(np.linalg.det(m)) > 1e-6:
                a, _ = np.linalg.solve(m, r - p)
                out.append(p + a * (q - p))
    return out


@pytest.mark.parametrize("size", [1.0, 10.0, 20.0])
def test_a_sized_relief_is_the_square_or_circle_of_that_size_about_the_bend_lines_crossing(tray, size):
    """SolidWorks' corner relief "centred on bend lines": the closed-corner blank less a square of side
    ``size`` (a circle of diameter ``size``) about each crossing of two bend lines, built with shapely."""
    square = _unfold(tray, "none")
    centres = _crossings(square)
    assert len(centres) == 4
    path, inside = tray
    rect = patterns.unfold(path, k_factor=K, fixed_face=inside, corner_relief="rectangular", corner_relief_size=size)
    ref = square.outline.polygon.difference(shapely.union_all(
        [shapely.box(*(c - size / 2), *(c + size / 2)) for c in centres]))
    assert rect.area == pytest.approx(ref.area, abs=1e-6)
    assert rect.outline.polygon.symmetric_difference(ref).area < 1e-6
    by_ratio = patterns.unfold(path, k_factor=K, fixed_face=inside, corner_relief="rectangular",
                               corner_relief_ratio=size / T)  # the same size, as a multiple of the thickness
    assert by_ratio.area == pytest.approx(rect.area, abs=1e-9)
    rnd = patterns.unfold(path, k_factor=K, fixed_face=inside, corner_relief="round", corner_relief_size=size)
    ref = square.outline.polygon.difference(shapely.union_all(
        [shapely.Point(c).buffer(size / 2, quad_segs=512) for c in centres]))
    assert sum(isinstance(p, patterns.curves.Arc) for p in rnd.outline.pieces) == 4
    assert rnd.area == pytest.approx(ref.area, rel=1e-7)  # the circle sampled finely
    for blank in (rect, rnd):
        assert blank.ok and not [f for f in blank.findings if f.code is patterns.Code.RELIEF_NOT_DRAWN]


def test_a_relief_too_small_to_reach_the_flanges_is_drawn_closed_and_said(tray):
    """0.2 mm about a crossing that lies 0.118 mm inside the closed corner's notch: no flange edge is reached."""
    path, inside = tray
    square = _unfold(tray, "none")
    edge = min(square.outline.polygon.exterior.distance(shapely.Point(c)) for c in _crossings(square))
    assert 0.1 < edge  # the square of 0.2 mm does not reach the outline
    small = patterns.unfold(path, k_factor=K, fixed_face=inside, corner_relief="rectangular", corner_relief_size=0.2)
    assert small.area == pytest.approx(square.area, abs=1e-9)
    said = [f for f in small.findings if f.code is patterns.Code.RELIEF_NOT_DRAWN]
    assert len(said) == 1 and len(said[0].points) == 4 and "4 corners drawn closed" in said[0].message


def test_a_relief_size_is_refused_without_a_relief_that_has_one_or_given_twice(tray):
    path, inside = tray
    for relief in ("none", "tear", "as-modelled"):
        with pytest.raises(patterns.InputError, match=rf"corner_relief_size sizes a rectangular or round corner "
                                                      rf"relief; corner_relief is '{relief}', which has no size"):
            patterns.unfold(path, corner_relief=relief, corner_relief_size=5)
    with pytest.raises(patterns.InputError, match="corner_relief_size and corner_relief_ratio both size"):
        patterns.unfold(path, corner_relief="round", corner_relief_size=5, corner_relief_ratio=2)
    with pytest.raises(patterns.InputError, match="corner_relief_size must be"):
        patterns.unfold(path, corner_relief="round", corner_relief_size=0)
