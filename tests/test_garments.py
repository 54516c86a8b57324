"""Garments and soft goods: grain, matching notches, nesting."""


import build123d as bd
import ezdxf
import numpy as np
import pytest
import shapely
import shapely.affinity

import patterns
from patterns import surfaces  # noqa: F401  (patterns.surfaces below)
from patterns.errors import InputError
from patterns.measure import flat_direction
from patterns.pieces.notches import notch_positions
from patterns.samples import cup, duct_transition, hopper, hull_panel

from .conftest import SAMPLES
from .helpers import drawing_shift


@pytest.fixture(scope="module")
def cup_pattern():
    # flatten's default tolerance (1e-6) relaxes to convergence: mating seams' flat
    # lengths are then within 0.1 % (measured 0.091-0.096 %; 0.063-0.129 % at 1e-4).
    return patterns.flatten(patterns.load(SAMPLES / "cup.step"))


def test_grain_points_up_on_every_panel():
    model = patterns.load(SAMPLES / "cup.step")
    for grain in [(0, 0, 1), (1, 0, 0), (1, 1, 0.5)]:
        pattern = patterns.flatten(model, grain=grain)
        d = np.asarray(grain, float) / np.linalg.norm(grain)
        for flat in pattern.panels:
            up = flat_direction(flat.vertices, flat.faces, flat.uv, d)
            assert up == pytest.approx([0.0, 1.0], abs=1e-9)
            assert flat.flattening.one_to_one
    # A rotation only: lengths, areas and strain unchanged.
    plain = patterns.flatten(model)
    turned = patterns.flatten(model, grain=(1, 0, 0))
    for a, b in zip(plain.panels, turned.panels):
        assert b.area == pytest.approx(a.area, rel=1e-12)
        assert b.flattening.distortion.edge_strain_rms == pytest.approx(a.flattening.distortion.edge_strain_rms,
                                                                         rel=1e-9)
    # Per panel; panels not named keep their orientation.
    per = patterns.flatten(model, grain={"face0": (0, 0, 1)})
    assert np.array_equal(per.panels[1].uv, plain.panels[1].uv)
    with pytest.raises(InputError, match="does not have"):
        patterns.flatten(model, grain={"nope": (0, 0, 1)})
    with pytest.raises(InputError, match="non-zero"):
        patterns.flatten(model, grain=(0, 0, 0))


def test_matching_notches_are_at_equal_3d_arc_length(cup_pattern, tmp_path):
    for fs in cup_pattern.seams:
        sides = [notch_positions(fs, k, cup_pattern.panels[fs.seam.panels[k]].uv, 20.0) for k in (0, 1)]
        s0 = np.array([x[0] for x in sides[0]])
        s1 = np.array([x[0] for x in sides[1]])
        np.testing.assert_allclose(s0, s1, atol=0.1)  # mm of 3D seam length
        assert s0[0] == 0.0 and s0[-1] == pytest.approx(fs.seam.polyline_length)
        assert np.all(np.diff(s0[:-1]) == pytest.approx(20.0))
        # Each notch sits on its panel's flat seam line, at the same 3D arc length
        # measured along the seam's points (an independent interpolation).
        for k in (0, 1):
            uv = cup_pattern.panels[fs.seam.panels[k]].uv[fs.seam.vertices[k]]
            c3 = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff(fs.seam.points, axis=0), axis=1))])
            expect = np.column_stack([np.interp(s0, c3, uv[:, 0]), np.interp(s0, c3, uv[:, 1])])
            np.testing.assert_allclose([x[1] for x in sides[k]], expect, atol=1e-9)
        # The sewn lengths (each side's flat seam) match within 0.1 %.
        assert abs(fs.mismatch) / np.mean(fs.flat_lengths) < 1e-3
    # In the file: slits or V notches on NOTCH, both panels of every seam.
    path = tmp_path / "cup.dxf"
    patterns.write(cup_pattern, path, seam_allowance=10, notch_spacing=20.0)
    slits = ezdxf.readfile(path).modelspace().query('LINE[layer=="NOTCH"]')
    per_side = [len(notch_positions(fs, 0, cup_pattern.panels[fs.seam.panels[0]].uv, 20.0)) for fs in cup_pattern.seams]
    assert len(slits) == 2 * sum(per_side)
    path_v = tmp_path / "cup_v.dxf"
    patterns.write(cup_pattern, path_v, seam_allowance=10, notch_spacing=20.0, notch_style="v")
    assert len(ezdxf.readfile(path_v).modelspace().query('LINE[layer=="NOTCH"]')) == 4 * sum(per_side)
    astm = tmp_path / "cup_astm.dxf"
    patterns.write(cup_pattern, astm, profile="astm", seam_allowance=10, notch_spacing=20.0, notch_style="v")
    doc = ezdxf.readfile(astm)
    points = [p for block in doc.blocks for p in block.query("POINT") if p.dxf.layer == "4"]
    assert len(points) == 2 * sum(per_side) and all(p.dxf.thickness == pytest.approx(10.0) for p in points)
    with pytest.raises(InputError, match="notch_style"):
        patterns.write(cup_pattern, tmp_path / "x.dxf", notch_style="castle")


@pytest.mark.slow
def test_nesting_ten_panels_on_a_roll():
    shape = bd.Compound([cup(), bd.Pos(1000, 0, 0) * duct_transition(), bd.Pos(-2000, 0, 0) * hopper(),
                         bd.Pos(0, 3000, 0) * hull_panel()])
    pattern = patterns.flatten(patterns.load(shape))
    assert len(pattern.panels) == 10
    result = patterns.layout(pattern, width=1500, gap=10, rotations="quarter", time_limit=3)
    polys = [shapely.Polygon(p.outline.points()) for p in result.pieces]
    for i, a in enumerate(polys):
        x0, y0, x1, y1 = a.bounds
        assert x0 >= -1e-6 and x1 <= 1500 + 1e-6 and y0 >= -1e-6
        for b in polys[i + 1:]:
            assert a.distance(b) >= 10.0 - 1e-6  # the gap, checked with shapely
    laid = pattern.placed([(p.placement.angle, p.placement.dx, p.placement.dy) for p in result.pieces])
    assert patterns.check(laid).ok  # the report's overlap checks agree, on the panels placed as the pieces
    top = max(p.bounds[3] for p in polys)
    assert result.length == pytest.approx(top)
    assert result.efficiency == pytest.approx(sum(p.area for p in polys) / (1500 * top))
    # (How short the marker is against bounding boxes on shelves is the nesting benchmark's number.)
    # Rotation is only by the grain when asked to keep it: +Y stays +Y or turns to -Y.
    kept = patterns.layout(pattern, width=1500, gap=10, rotations="grain", time_limit=3)
    for piece in kept.pieces:
        assert piece.placement.angle in (0.0, pytest.approx(np.pi))


def test_nesting_errors():
    pattern = patterns.flatten(patterns.load(SAMPLES / "hull_panel.step"))
    with pytest.raises(patterns.LayoutError, match="wider than the 300 mm roll"):
        patterns.layout(pattern, width=300)
    with pytest.raises(InputError, match="width"):
        patterns.layout(pattern, width=-5)
    with pytest.raises(InputError, match="gap"):
        patterns.layout(pattern, width=2000, gap=-1)


def test_max_strain_options():
    model = patterns.load(SAMPLES / "cup.step")
    with pytest.raises(InputError, match="max_strain"):
        patterns.flatten(model, max_strain=0)
    with pytest.raises(InputError, match="max_darts"):
        patterns.flatten(model, max_strain=0.03, max_darts=-1)
    # A limit that already holds cuts nothing.
    assert all(f.darts == () for f in patterns.flatten(model, max_strain=0.5).panels)


def test_squared_seam_allowance_corners(cup_pattern, tmp_path):
    laid = cup_pattern.placed([(0.0, 300.0 * k, 0.0) for k in range(4)])
    outlines = {}
    for corners in ("mitre", "square"):
        path = tmp_path / f"{corners}.dxf"
        patterns.write(laid, path, seam_allowance=10.0, seam_corners=corners)
        doc = ezdxf.readfile(path)
        cuts = [shapely.Polygon([q[:2] for q in e.get_points("xy")]) for e in doc.modelspace().query('LWPOLYLINE[layer=="CUT"]')]
        # panel 0, moved back by the file's own shift into the first quadrant
        outlines[corners] = shapely.affinity.translate(min(cuts, key=lambda c: c.bounds[0]),
                                                       *-drawing_shift(doc.modelspace(), laid, "SEW"))
    flat = laid.panels[0]
    seam_line = flat.uv[flat.loops[0]]
    for cut in outlines.values():
        d = shapely.distance(shapely.points(seam_line), cut.exterior)
        assert d.min() > 10.0 - 1e-3  # the allowance is there all round
    # At each sharp corner of the seam line, the squared outline runs each side on
    # by the allowance: both extension points lie on the cut line.
    loop = seam_line
    a_vec = loop - np.roll(loop, 1, axis=0)
    b_vec = np.roll(loop, -1, axis=0) - loop
    turn = np.arctan2(a_vec[:, 0] * b_vec[:, 1] - a_vec[:, 1] * b_vec[:, 0], (a_vec * b_vec).sum(axis=1))
    sharp = np.flatnonzero(turn > np.radians(30))
    assert len(sharp) == 3  # the quarter sphere's three corners
    ring = outlines["square"].exterior
    for i in sharp:
        for t in (a_vec[i], -b_vec[i]):
            outward = np.array([t[1], -t[0]]) / np.linalg.norm(t)
            if shapely.contains_xy(shapely.Polygon(loop), *(loop[i] + 1e-3 * outward)):
                outward = -outward
            corner = loop[i] + 10.0 * t / np.linalg.norm(t) + 10.0 * outward
            assert ring.distance(shapely.Point(corner)) < 0.05
    assert abs(outlines["square"].area - outlines["mitre"].area) > 1.0
    with pytest.raises(InputError, match="seam_corners"):
        patterns.write(laid, tmp_path / "x.dxf", seam_allowance=10.0, seam_corners="round")


@pytest.mark.slow
def test_the_strain_limit_travels_with_the_pattern():
    """flatten(max_strain=...) records its limit; check() judges against it unless told otherwise
    (a darted pattern still above its limit is not called ok by a check without arguments)."""
    model = patterns.load(SAMPLES / "cup.step")
    pattern = patterns.flatten(model, max_strain=0.02, max_darts=2, max_gores=0)  # darts only, never parted
    assert pattern.max_strain == 0.02
    report = patterns.check(pattern)
    worst = max(p.strain_max for p in report.panels)
    assert worst > 0.02 and not report.ok  # two darts per quarter sphere cannot reach 2 %
    assert patterns.check(pattern, max_strain=0.5).ok  # another limit, when asked
    assert patterns.flatten(model).max_strain is None and patterns.check(patterns.flatten(model)).ok
