"""Countersunk and counterbored holes: the blank cuts the through hole and marks the rim on its own layer;
a flat pattern drawn with both circles (as SolidWorks draws it) reads as one hole and one rim; a contour
the drawing leaves open is an error, or left out and counted.

Every expected number comes from the construction (the build123d plate and bracket below, the
ezdxf-written drawings), never from a run of the code under test."""

from __future__ import annotations

import itertools
import json

import build123d as bd
import ezdxf
import numpy as np
import pytest
import shapely

import patterns
from patterns.errors import InputError

from .test_unfold import bent_strip

SAMPLED = 1e-3
"""read_flat_pattern samples arcs within this chord error (mm): a circle's polygon lacks at most its length
times it in area."""

UP = (bd.Align.CENTER, bd.Align.CENTER, bd.Align.MIN)
DOWN = (bd.Align.CENTER, bd.Align.CENTER, bd.Align.MAX)

# The plate: 120 x 80 x 2 mm, z in [-1, 1].  (x, y, through radius, rim radius, depth, kind, skin: +1 top)
W, H, T = 120.0, 80.0, 2.0
HOLES = {
    "A": (-30.0, 10.0, 4.6, 5.25, 0.65, "countersink", +1),   # 90°: Ø9.2 through, Ø10.5 rim, on top
    "B": (25.0, -15.0, 3.3, 5.5, 1.0, "counterbore", -1),     # Ø6.6 through, Ø11 x 1 deep, from below
    "C": (30.0, 20.0, 3.0, 3.8, 0.8, "countersink", -1),      # 90°: Ø6 through, Ø7.6 rim, from below
    "D": (-40.0, -25.0, 2.5, None, None, None, 0),            # a plain hole
}


def plate():
    solid = bd.Box(W, H, T)
    for x, y, r, rim, depth, kind, skin in HOLES.values():
        solid -= bd.Pos(x, y, 0) * bd.Cylinder(r, 4 * T)
        if kind == "countersink":  # a 90° cone, radius r at `depth` below the skin, widening out past it
            z = skin * (T / 2 - depth)
            cone = bd.Cone(r, r + 2, 2, align=UP) if skin > 0 else bd.Cone(r + 2, r, 2, align=DOWN)
            solid -= bd.Pos(x, y, z) * cone
        elif kind == "counterbore":
            solid -= bd.Pos(x, y, skin * (T / 2 - depth)) * bd.Cylinder(rim, 2, align=UP if skin > 0 else DOWN)
    return solid


def _face(solid, z):
    """The index of the plate's planar face at height z."""
    return next(i for i, f in enumerate(solid.faces())
                if f.geom_type == bd.GeomType.PLANE and abs(f.center().Z - z) < 1e-9 and abs(f.normal_at().Z) > 0.99)


def _corner_distances(point, corners):
    return sorted(np.linalg.norm(np.asarray(corners) - point, axis=1))


@pytest.fixture(scope="module")
def blank():
    solid = plate()
    return patterns.unfold(solid, fixed_face=_face(solid, -T / 2))  # the bottom stays: near = below


def test_plate_rims_are_the_construction(blank):
    # the holes are cut at their through diameters, the near side's countersink and counterbore too
    assert sorted(h.pieces[0].radius for h in blank.holes) == pytest.approx([2.5, 3.0, 3.3, 4.6], abs=1e-9)
    assert all(h.is_circle for h in blank.holes)
    assert blank.area == pytest.approx(W * H - np.pi * (4.6**2 + 3.3**2 + 3.0**2 + 2.5**2), abs=1e-6)
    got = sorted(blank.rims, key=lambda r: r.diameter)
    assert [(r.kind, r.side) for r in got] == [("countersink", "near"), ("countersink", "far"),
                                                ("counterbore", "near")]  # C, A, B: the bottom is near
    assert [r.diameter for r in got] == pytest.approx([7.6, 10.5, 11.0], abs=1e-9)
    assert [r.through for r in got] == pytest.approx([6.0, 9.2, 6.6], abs=1e-9)
    assert [r.depth for r in got] == pytest.approx([0.8, 0.65, 1.0], abs=1e-9)
    assert got[0].angle == pytest.approx(90.0, abs=1e-7) and got[1].angle == pytest.approx(90.0, abs=1e-7)
    assert got[2].angle is None
    # where: each rim about a hole of its through diameter, as far from the blank's corners as in the plate
    corners = blank.outline.vertices()[:, :2]
    plate_corners = [(sx * W / 2, sy * H / 2) for sx in (-1, 1) for sy in (-1, 1)]
    for rim, key in zip(got, "CAB"):
        x, y = HOLES[key][:2]
        assert _corner_distances(rim.center, corners) == pytest.approx(_corner_distances((x, y), plate_corners),
                                                                       abs=1e-9)
        assert any(np.linalg.norm(h.pieces[0].center - rim.center) < 1e-9 and
                   abs(2 * h.pieces[0].radius - rim.through) < 1e-9 for h in blank.holes)


def test_l_bracket_rims_follow_their_faces():
    """A countersink in the fixed flange and a counterbore in the flange across the bend, both from the
    outside of the bend (the far side: the inside of flange A stays)."""
    k, r, t, la, lb, width = 0.4, 2.0, 2.0, 60.0, 40.0, 60.0
    solid = bent_strip(la=la, lb=lb, width=width, r=r, t=t)
    solid -= bd.Pos(-30, 30, 0) * bd.Cylinder(4.6, 10)  # flange A: z in [-2, 0]; the cone opens downwards
    solid -= bd.Pos(-30, 30, -t + 0.65) * bd.Cone(6.6, 4.6, 2, align=DOWN)
    axis_x = bd.Rot(0, 90, 0)  # flange B: x in [2, 4], z in [2, 42]; a counterbore 1 deep from x = 4
    solid -= bd.Pos(3, 30, 22) * axis_x * bd.Cylinder(3.3, 10)
    solid -= bd.Pos(r + t - 1, 30, 22) * axis_x * bd.Cylinder(5.5, 2, align=UP)
    fixed = next(i for i, f in enumerate(solid.faces()) if f.geom_type == bd.GeomType.PLANE
                 and abs(f.center().Z) < 1e-9 and f.normal_at().Z > 0.99)
    blank = patterns.unfold(solid, k_factor=k, fixed_face=fixed)
    (bend,) = blank.bends
    allowance = np.pi / 2 * (r + k * t)
    sink, bore = sorted(blank.rims, key=lambda rim: rim.kind == "counterbore")
    assert (sink.kind, sink.side, bore.kind, bore.side) == ("countersink", "far", "counterbore", "far")
    assert (sink.diameter, sink.through, bore.diameter, bore.through) == pytest.approx((10.5, 9.2, 11.0, 6.6),
                                                                                      abs=1e-9)
    line = bend.line
    d = (line[1] - line[0]) / np.linalg.norm(line[1] - line[0])
    normal = np.array([-d[1], d[0]])
    across = [(rim.center - line[0]) @ normal for rim in (sink, bore)]
    assert sorted(np.abs(across)) == pytest.approx([allowance / 2 + 20, allowance / 2 + 30], abs=1e-9)
    assert abs(across[0]) == pytest.approx(allowance / 2 + 30, abs=1e-9)  # the countersink: 30 from the bend
    assert across[0] * across[1] < 0  # on either side of the bend line
    along = [(rim.center - line[0]) @ d for rim in (sink, bore)]
    assert along == pytest.approx([width / 2, width / 2], abs=1e-9) or along == pytest.approx(
        [-width / 2, -width / 2], abs=1e-9)
    assert sorted(h.pieces[0].radius for h in blank.holes) == pytest.approx([3.3, 4.6], abs=1e-9)


def test_dxf_svg_json_draw_rims_as_marks(blank, tmp_path):
    patterns.write(blank, tmp_path / "plate.dxf")
    doc = ezdxf.readfile(tmp_path / "plate.dxf")
    circles = {}
    for e in doc.modelspace().query("CIRCLE"):
        circles.setdefault(e.dxf.layer, []).append((round(e.dxf.radius, 9), np.array(e.dxf.center)[:2]))
    assert sorted(r for r, _ in circles["CUT"]) == pytest.approx([2.5, 3.0, 3.3, 4.6], abs=1e-9)  # only holes
    assert sorted(r for r, _ in circles["COUNTERSINK"]) == pytest.approx([3.8, 5.25, 5.5], abs=1e-9)
    assert set(circles) == {"CUT", "COUNTERSINK"}
    layer = doc.layers.get("COUNTERSINK")
    assert layer.color == 4 and layer.dxf.linetype.upper() == "CONTINUOUS"
    cut = {r: c for r, c in circles["CUT"]}
    for radius, through in ((3.8, 3.0), (5.25, 4.6), (5.5, 3.3)):  # each rim about its through hole
        (centre,) = [c for r, c in circles["COUNTERSINK"] if abs(r - radius) < 1e-9]
        assert np.linalg.norm(centre - cut[through]) < 1e-9

    patterns.write(blank, tmp_path / "sw.dxf", layer_map="solidworks")
    layers = [e.dxf.layer for e in ezdxf.readfile(tmp_path / "sw.dxf").modelspace().query("CIRCLE")]
    assert layers == ["0"] * 7  # as SolidWorks draws them: both circles on layer 0
    patterns.write(blank, tmp_path / "none.dxf", layer_map="patterns,countersink=")
    assert len(ezdxf.readfile(tmp_path / "none.dxf").modelspace().query("CIRCLE")) == 4

    read = patterns.read_flat_pattern(tmp_path / "plate.dxf")
    assert (len(read.holes), len(read.rims)) == (4, 3)
    radii = (4.6, 3.3, 3.0, 2.5)
    assert read.area == pytest.approx(W * H - np.pi * sum(r * r for r in radii), abs=2 * np.pi * sum(radii) * SAMPLED)
    c = patterns.compare_blank(blank, tmp_path / "sw.dxf")
    assert (c.holes, c.holes_reference, c.rims, c.rims_reference) == (4, 4, 3, 3)
    assert c.hausdorff_rims < 0.011  # contours resampled every 0.02 mm: a point lies within 0.01 of the other's
    assert c.area - c.area_reference == pytest.approx(0, abs=2 * np.pi * sum(radii) * SAMPLED)
    assert c.to_dict()["rims_reference"] == 3

    patterns.write(blank, tmp_path / "plate.svg")
    svg = (tmp_path / "plate.svg").read_text()
    cut_layer = svg[svg.index('<g id="cut"'):svg.index("</g>", svg.index('<g id="cut"'))]
    score_layer = svg[svg.index('<g id="score"'):svg.index("</g>", svg.index('<g id="score"'))]
    for radius in ("3.8000", "5.2500", "5.5000"):
        assert f"A {radius} {radius}" in score_layer and f"A {radius} {radius}" not in cut_layer
    assert cut_layer.count("<path") == 5  # the outline and the four through holes

    patterns.write(blank, tmp_path / "plate.json")
    report = json.loads((tmp_path / "plate.json").read_text())
    rims = sorted(report["pieces"][0]["rims"], key=lambda r: r["diameter_mm"])
    assert [(r["kind"], r["side"], r["diameter_mm"], r["through_mm"], r["depth_mm"]) for r in rims] == [
        ("countersink", "near", 7.6, 6.0, 0.8), ("countersink", "far", 10.5, 9.2, 0.65),
        ("counterbore", "near", 11.0, 6.6, 1.0)]
    assert [r["angle_deg"] for r in rims] == [90.0, 90.0, None]
    holes = report["pieces"][0]["holes"]  # a full circle is one row (its start); the rim is about it
    for rim in rims:
        assert sum(len(h) == 1 and abs(np.linalg.norm(np.array(h[0][:2]) - rim["center"]) - rim["through_mm"] / 2)
                   < 1e-3 for h in holes) == 1
    assert len(report["blanks"][0]["rims"]) == 3


def _drawing(path, *, circles=(), arcs=(), order=None):
    """A 100 x 60 mm rectangle (LWPOLYLINE) with CIRCLEs ``(x, y, r)`` and ARCs ``(x, y, r, start, end)``
    (degrees, counter-clockwise), all on layer 0, continuous, written by ezdxf."""
    doc = ezdxf.new("R2000")
    msp = doc.modelspace()
    msp.add_lwpolyline([(0, 0), (100, 0), (100, 60), (0, 60)], close=True)
    for x, y, r in circles:
        msp.add_circle((x, y), r)
    for x, y, r, a0, a1 in arcs if order is None else [arcs[k] for k in order]:
        msp.add_arc((x, y), r, a0, a1)
    doc.saveas(path)
    return path


def test_concentric_circles_read_as_one_hole_and_its_rim(tmp_path):
    path = _drawing(tmp_path / "cs.dxf", circles=[(20, 20, 5.5), (20, 20, 4.0), (70, 30, 3.0)])
    read = patterns.read_flat_pattern(path)
    assert len(read.holes) == 2 and len(read.rims) == 1
    areas = sorted(shapely.Polygon(h).area for h in read.holes)
    assert areas[0] == pytest.approx(np.pi * 9.0, abs=2 * np.pi * 3.0 * SAMPLED)
    assert areas[1] == pytest.approx(np.pi * 16.0, abs=2 * np.pi * 4.0 * SAMPLED)  # the inner circle is the hole
    (rim,) = read.rims
    assert np.linalg.norm(rim - (20, 20), axis=1) == pytest.approx(np.full(len(rim), 5.5), abs=1e-9)
    assert read.area == pytest.approx(6000 - np.pi * (16 + 9), abs=2 * np.pi * 7.0 * SAMPLED)


@pytest.mark.parametrize("order", [(0, 1), (1, 0)])
def test_open_contour_is_an_error_or_left_out(tmp_path, order):
    arcs = [(70, 30, 2.0, 0.0, 90.0), (70, 30, 2.0, 90.0, 180.0)]  # half a circle, from (72, 30) to (68, 30)
    path = _drawing(tmp_path / "open.dxf", circles=[(20, 20, 4.0)], arcs=arcs, order=order)
    with pytest.raises(InputError, match=r"open\.dxf: a contour does not close \(open end at x 6[89]\.000, y 30"):
        patterns.read_flat_pattern(path)
    with pytest.raises(InputError, match="open_contours must be one of 'error', 'leave-out', got 'skip'"):
        patterns.read_flat_pattern(path, open_contours="skip")
    read = patterns.read_flat_pattern(path, open_contours="leave-out")
    assert len(read.holes) == 1 and len(read.rims) == 0
    assert read.open_contours.shape == (1, 2, 2)
    ends = sorted(map(tuple, np.round(read.open_contours[0], 9)))
    assert ends == [(68.0, 30.0), (72.0, 30.0)]
    assert read.area == pytest.approx(6000 - np.pi * 16, abs=2 * np.pi * 4.0 * SAMPLED)
    closed = _drawing(tmp_path / "closed.dxf", circles=[(20, 20, 4.0)])
    c = patterns.compare_blank(closed, read)
    assert (c.open_contours_reference, c.holes, c.holes_reference) == (1, 1, 1)
    assert c.to_dict()["open_contours_reference"] == 1


def test_rims_move_with_the_blank(blank):
    from patterns.curves import Motion

    for motion in (Motion(0.7, 10.0, -3.0), Motion(0.0, 5.0, 0.0, mirrored=True)):
        moved = blank.moved(motion)
        for a, b in itertools.zip_longest(blank.rims, moved.rims):
            assert np.allclose(motion(a.center[None, :])[0], b.center, atol=1e-12)
            assert b.circle.sweep > 0 and (a.kind, a.side, a.through) == (b.kind, b.side, b.through)


@pytest.mark.parametrize("fixed", ["bored side", "other side", "default"])
def test_a_counterbore_on_either_side_leaves_the_thickness_alone(fixed):
    """A 2 mm plate, 100 x 60, with one Ø 6.6 hole counterbored Ø 11 x 1 deep from the top: the counterbore's
    floor is a face parallel to either skin, 1 mm from the top -- and, from the bottom, nearer than the top
    skin.  Fixed on either side, the thickness is the plate's 2 mm and the blank the bottom's outline with the
    through hole (before: 1 mm when the bore was on the far side)."""
    solid = bd.Box(100, 60, 2) - bd.Cylinder(3.3, 8) - bd.Pos(0, 0, 0) * bd.Cylinder(5.5, 2, align=UP)
    face = {"bored side": _face(solid, 1.0), "other side": _face(solid, -1.0), "default": None}[fixed]
    blank = patterns.unfold(solid, fixed_face=face)
    assert blank.thickness == pytest.approx(2.0, abs=1e-9)
    assert blank.area == pytest.approx(100 * 60 - np.pi * 3.3 ** 2, abs=2e-3 * 2 * np.pi * 3.3)


def test_compare_takes_a_flat_pattern_with_an_open_contour_when_asked(tmp_path):
    """``--compare`` refuses a DXF with an open contour in one line (exit 2, nothing written) unless
    ``--compare-open leave-out``: then it compares and says how many it left out.  A blank with no bends
    says its bend sheet has the header only (and the CSV read back has no row)."""
    import csv

    from patterns.cli import main

    bd.export_step(bd.Box(100, 60, 2) - bd.Pos(-30, -10, 0) * bd.Cylinder(4, 4), str(tmp_path / "plate.step"))
    theirs = _drawing(tmp_path / "theirs.dxf", circles=[(20, 20, 4.0)], arcs=[(70, 30, 2.0, 0.0, 90.0)])
    argv = ["unfold", str(tmp_path / "plate.step"), "-o", str(tmp_path / "ours.dxf"), "--compare", str(theirs),
            "--bend-sheet", str(tmp_path / "bends.csv")]
    assert main(argv) == 2
    assert not (tmp_path / "ours.dxf").exists() and not (tmp_path / "bends.csv").exists()
    assert main(argv + ["--compare-open", "leave-out"]) == 0
    with open(tmp_path / "bends.csv", newline="") as f:
        assert len(list(csv.reader(f))) == 1
    assert (tmp_path / "ours.dxf").is_file()


def test_compare_open_notes(tmp_path, capsys):
    """What ``--compare-open leave-out`` and a bend sheet of no bends print: one note each, naming the file."""
    from patterns.cli import main

    bd.export_step(bd.Box(100, 60, 2), str(tmp_path / "plate.step"))
    theirs = _drawing(tmp_path / "theirs.dxf", circles=[], arcs=[(70, 30, 2.0, 0.0, 90.0)])
    assert main(["unfold", str(tmp_path / "plate.step"), "-o", str(tmp_path / "ours.dxf"), "--compare", str(theirs),
                 "--compare-open", "leave-out", "--bend-sheet", str(tmp_path / "b.csv")]) == 0
    out = capsys.readouterr().out
    assert f"note: 1 open contour of {theirs} left out" in out
    assert f"note: plate has no bends: {tmp_path / 'b.csv'} has its header only" in out


def test_a_plate_of_many_holes_is_read_and_unfolded_whole(tmp_path):
    """A 2 mm plate with 30 x 30 Ø 5 holes (906 faces), written as STEP and read back: every hole is cut, at
    its place and size, and the blank's area is the square's less the holes' (exact arcs).  The reader's
    lighter repairs, the holes' KD-tree and the labels' margin test all meet it (benchmarks/plate_faces.py
    times the larger plates)."""
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

    from patterns.samples import holed_plate

    writer = STEPControl_Writer()
    writer.Transfer(holed_plate(30), STEPControl_AsIs)
    writer.Write(str(tmp_path / "plate.step"))
    blank = patterns.unfold(tmp_path / "plate.step")
    assert (blank.thickness, len(blank.holes), len(blank.bends)) == (2.0, 900, 0)
    assert blank.area == pytest.approx(300 ** 2 - 900 * np.pi * 2.5 ** 2, rel=1e-9)
    centres = np.array([hole.pieces[0].center for hole in blank.holes])
    centres -= centres.min(axis=0)
    grid = np.round(centres / 10.0, 9)
    assert sorted(map(tuple, grid)) == [(float(i), float(j)) for i in range(30) for j in range(30)]
    assert all(hole.pieces[0].radius == pytest.approx(2.5, abs=1e-9) for hole in blank.holes)
    patterns.write(blank, tmp_path / "plate.dxf")
    assert len(ezdxf.readfile(tmp_path / "plate.dxf").modelspace().query("CIRCLE[layer=='CUT']")) == 900
