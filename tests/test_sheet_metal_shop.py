"""Sheet metal as a shop sees it: the bend sheet, material K-factors, and the faults a shop would notice.

Every reference is independent of the unfolder: flange lengths and bend allowances computed by hand
(``la + lb + angle (r + K t)``), the bend directions of a Z bracket reasoned from its drawing, slot areas
and perimeters from their dimensions, the files read back (csv, ezdxf), and the command's exit code.
Each test names the planted bug it catches (issue 35, item 5).
"""

from __future__ import annotations

import csv
import json

import build123d as bd
import ezdxf
import numpy as np
import pytest
import shapely
from ezdxf.addons import text2path

import patterns
from patterns.bendsheet import COLUMNS
from patterns.cli import main

from .test_unfold import bent_strip, conical_sheet, spline_strip

T, R, WIDTH = 2.0, 3.0, 40.0
Z_PROFILE = [(-40, 0), (0, 0), (0, 30), (60, 30)]  # flange A 36 mm straight, web 22, flange C 56 (centreline R 4)


def swept(profile, *, r=R, t=T, width=WIDTH):
    """A bracket of ``t`` mm sheet, inside radius ``r``, ``width`` wide (along z): a rectangle swept along the
    profile (x, y) filleted at the sheet's middle."""
    with bd.BuildLine() as line:
        bd.FilletPolyline(*profile, radius=r + t / 2)
    path = line.wire()
    plane = bd.Plane(origin=path.position_at(0), x_dir=(0, 0, 1), z_dir=path.tangent_at(0))
    return bd.sweep(plane * bd.Rectangle(width, t), path=path, transition=bd.Transition.RIGHT)


def face_at(part, centre, normal) -> int:
    """The index (``shape.faces()``) of the planar face whose centre is ``centre`` and normal ``normal``."""
    for i, f in enumerate(part.faces()):
        if f.geom_type.name == "PLANE" and np.allclose(tuple(f.center()), centre, atol=1e-6) \
                and np.allclose(tuple(f.normal_at()), normal, atol=1e-9):
            return i
    raise AssertionError(f"no face at {centre}")


@pytest.fixture(scope="module")
def z_bracket():
    return swept(Z_PROFILE)


# --------------------------------------------------------------------------- #
# The bend sheet
# --------------------------------------------------------------------------- #


def test_z_bracket_bend_sheet_has_one_bend_up_and_one_down(z_bracket):
    """Planted bug caught: every bend labelled "up" (``direction = "up"`` in bends.group_bends).

    Seen from flange C's top (y = 31, the viewer above it), the web drops away from the viewer at the C-web
    bend (down) and flange A comes back towards the viewer at the web-A bend (up); seen from C's underside
    (y = 29) both turn the other way.  Outside-in: the web-A bend's outer flange (A, 36 mm + half its
    allowance) is shallower than the C-web bend's (C, 56 mm + half), so it is bent first."""
    k = 0.3
    allowance = np.pi / 2 * (R + k * T)  # 5.6549 mm
    for y, expected in ((31.0, ("up", "down")), (29.0, ("down", "up"))):
        fixed = face_at(z_bracket, (32.0, y, 0.0), (0.0, 1.0 if y > 30 else -1.0, 0.0))
        blank = patterns.unfold(z_bracket, k_factor=k, fixed_face=fixed)
        rows = blank.bend_sheet()
        assert [r.sequence for r in rows] == [1, 2]
        assert (rows[0].direction, rows[1].direction) == expected
        assert [r.flange_mm for r in rows] == pytest.approx([36 + allowance / 2, 56 + allowance / 2], abs=1e-6)
        for r in rows:
            assert r.angle_deg == pytest.approx(90.0, abs=1e-9) and r.inside_radius_mm == pytest.approx(R, abs=1e-9)
            assert r.bend_length_mm == pytest.approx(WIDTH, abs=1e-6) and r.k_factor == k
            assert r.allowance_mm == pytest.approx(allowance, abs=1e-9)
        # the two bend lines lie the web's straight length plus one allowance apart (centre to centre)
        a, b = (np.array([[r.x1_mm, r.y1_mm], [r.x2_mm, r.y2_mm]]) for r in rows)
        d = (a[1] - a[0]) / np.linalg.norm(a[1] - a[0])
        assert abs(d @ [b[0][1] - a[0][1], a[0][0] - b[0][0]]) == pytest.approx(22.0 + allowance, abs=1e-6)
        assert max(blank.size) == pytest.approx(36 + 22 + 56 + 2 * allowance, abs=1e-6)


def test_bend_sheet_csv_and_dxf_text_agree_read_back(z_bracket, tmp_path, capsys):
    """``patterns unfold PART -o blank.dxf --bend-sheet bends.csv``: the CSV read back has the columns and
    two rows; each row's bend line is a BEND line of the DXF, and its label ("1 UP 90.0 DEG R3") lies on it."""
    step = tmp_path / "z.step"
    bd.export_step(z_bracket, str(step))
    fixed = face_at(z_bracket, (32.0, 31.0, 0.0), (0.0, 1.0, 0.0))
    dxf, sheet = tmp_path / "z.dxf", tmp_path / "bends.csv"
    code = main(["unfold", str(step), "-o", str(dxf), "--bend-sheet", str(sheet), "--k-factor", "0.3",
                 "--fixed-face", str(fixed)])
    assert code == 0, capsys.readouterr()
    with open(sheet, newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert list(rows[0]) == list(COLUMNS) and len(rows) == 2
    assert [(r["sequence"], r["direction"], r["angle_deg"], r["inside_radius_mm"], r["bend_length_mm"], r["k_factor"])
            for r in rows] == [("1", "up", "90", "3", "40", "0.3"), ("2", "down", "90", "3", "40", "0.3")]
    assert [float(r["allowance_mm"]) for r in rows] == pytest.approx([np.pi / 2 * (R + 0.3 * T)] * 2, abs=1e-4)
    msp = ezdxf.readfile(dxf).modelspace()
    lines = [np.array([e.dxf.start, e.dxf.end])[:, :2] for e in msp.query("LINE[layer=='BEND']")]
    texts = {t.dxf.text: shapely.MultiPoint([(v.x, v.y) for p in text2path.make_paths_from_entity(t)
                                             for v in p.flattening(0.01)]).convex_hull
             for t in msp.query("TEXT[layer=='BEND']")}
    details = f"BA {np.pi / 2 * (R + 0.3 * T):.2f} L {WIDTH:.2f} MM"  # the rows' allowance and bend length
    assert set(texts) == {"1 UP 90.0 DEG R3", "2 DOWN 90.0 DEG R3", details}
    assert [t.dxf.text for t in msp.query("TEXT[layer=='BEND']")].count(details) == 2  # one under each label
    for r in rows:
        mine = np.array([[float(r["x1_mm"]), float(r["y1_mm"])], [float(r["x2_mm"]), float(r["y2_mm"])]])
        assert min(min(np.abs(e - mine).max(), np.abs(e[::-1] - mine).max()) for e in lines) < 1e-4
        glyphs = texts[f"{r['sequence']} {r['direction'].upper()} 90.0 DEG R3"]
        near = [shapely.LineString(e).distance(glyphs) for e in lines]  # beside its own line, nearer than the other
        assert shapely.LineString(mine).distance(glyphs) == pytest.approx(min(near), abs=1e-3)
    out = capsys.readouterr().out
    assert str(sheet) in out


def test_sequence_is_outside_in_then_shortest_bend_line_first():
    """A box's blank drawn by hand: a 100 x 60 bottom, a 20 mm flange on each side, and a 10 mm return on the
    left long flange.  The return is shallowest (10 mm to the edge): first.  The four sides' outer flanges are
    equally deep (20 mm, the return's side 30): the short sides (60 mm bend lines) before the long ones (100),
    the returned side last."""
    from patterns.bendsheet import flange_depths, sequence

    box = shapely.union_all([shapely.box(0, 0, 100, 60), shapely.box(0, -20, 100, 0), shapely.box(0, 60, 100, 90),
                             shapely.box(-20, 0, 0, 60), shapely.box(100, 0, 120, 60)])
    lines = [np.array(x, dtype=float) for x in ([[0, 0], [100, 0]], [[0, 60], [100, 60]], [[0, 0], [0, 60]],
                                                 [[100, 0], [100, 60]], [[0, 80], [100, 80]])]
    assert [min(flange_depths(box, line)) for line in lines] == pytest.approx([20, 30, 20, 20, 10])
    assert sequence(box, lines) == (4, 2, 3, 0, 1)
    assert sequence(box, lines[::-1]) == (0, 1, 2, 4, 3)  # the same bends listed the other way: ties by index


def test_bend_sheet_is_planned_before_any_work(z_bracket, tmp_path, capsys):
    """A bend sheet that is no .csv, or that would overwrite the part, is refused in one line (exit 2) and nothing
    is written; ``patterns.write`` of a pattern (no blank) to .csv is refused too."""
    step = tmp_path / "z.step"
    bd.export_step(z_bracket, str(step))
    assert main(["unfold", str(step), "-o", str(tmp_path / "z.dxf"), "--bend-sheet", str(tmp_path / "b.txt")]) == 2
    assert "--bend-sheet writes .csv" in capsys.readouterr().err
    assert main(["unfold", str(step), "-o", str(tmp_path / "z.dxf"), "--bend-sheet", str(step.with_suffix(".csv")),
                 "--report", str(step.with_suffix(".csv"))]) == 2
    assert sorted(p.name for p in tmp_path.iterdir()) == ["z.step"]
    box = patterns.flatten(patterns.load(bd.Box(50, 40, 30), max_edge=20))
    with pytest.raises(patterns.InputError, match="a bend sheet lists the bends of a blank"):
        patterns.write(box, tmp_path / "box.csv")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["z.step"]


# --------------------------------------------------------------------------- #
# Materials
# --------------------------------------------------------------------------- #


def test_material_gives_each_bend_the_tables_k_factor(z_bracket, tmp_path):
    """Mild steel, 2 mm, R 3: r/t 1.5 lies in the handbook's class 1-3 t, K 0.43.  A user's table gives a
    K-factor by r/t class; a bend no row covers is refused (never extrapolated)."""
    blank = patterns.unfold(z_bracket, material="mild-steel")
    allowance = np.pi / 2 * (R + 0.43 * T)
    assert max(blank.size) == pytest.approx(36 + 22 + 56 + 2 * allowance, abs=1e-6)
    assert [b.k_factor for b in blank.bends] == [0.43, 0.43] and blank.k_factor == 0.43
    assert blank.material == "mild-steel" and blank.to_dict()["material"] == "mild-steel"
    assert [r.k_factor for r in blank.bend_sheet()] == [0.43, 0.43]
    table = tmp_path / "shop.csv"
    table.write_text("material,thickness_min,thickness_max,rt_min,rt_max,k_factor,source\n"
                     "brass,1,3,0,1,0.35,trial\nbrass,1,3,1,2,0.41,trial\n")
    blank = patterns.unfold(z_bracket, material="Brass", material_table=table)
    assert max(blank.size) == pytest.approx(36 + 22 + 56 + np.pi * (R + 0.41 * T), abs=1e-6)
    with pytest.raises(patterns.InputError, match=r"r/t 2\.5\): no row of .*shop.csv covers it"):
        patterns.unfold(swept(Z_PROFILE, r=5.0), material="brass", material_table=table)


def test_material_table_classes_meet_as_the_handbook_says(tmp_path):
    """Where two r/t classes meet, the one that starts there gives the K-factor (r/t exactly 1 is class 1-3 t);
    a table whose rows overlap, or with a K-factor outside 0-1, is refused naming its file and lines."""
    from patterns.sheetmetal.materials import bundled_materials, read_material_table

    steel = bundled_materials()
    assert steel.k_factor("mild-steel", 3.0, 3.0) == 0.43 and steel.k_factor("mild-steel", 2.0, 1.999) == 0.38
    assert steel.k_factor("Mild-Steel", 2.0, 6.0) == 0.50 and steel.k_factor("aluminium-5052", 1.0, 0.0) == 0.33
    with pytest.raises(patterns.InputError, match=r"7 mm mild-steel.*no row of the bundled material table"):
        steel.k_factor("mild-steel", 7.0, 7.0)
    bad = tmp_path / "bad.csv"
    bad.write_text("material,thickness_min,thickness_max,rt_min,rt_max,k_factor\nx,1,3,0,2,0.4\nx,2,4,1,3,0.45\n")
    with pytest.raises(patterns.InputError, match=r"bad.csv: rows 2 and 3 both give x at 2-3 mm, r/t 1-2"):
        read_material_table(bad)
    bad.write_text("material,thickness_min,thickness_max,rt_min,rt_max,k_factor\nx,1,3,0,2,1.4\n")
    with pytest.raises(patterns.InputError, match=r"bad.csv, line 2: k_factor 1.4 is not a K-factor"):
        read_material_table(bad)


def test_each_bend_takes_the_k_factor_of_its_own_radius():
    """A Z bracket of 2 mm stainless whose bends have inside radii 1 (r/t 0.5: the handbook's hard class 0-1 t,
    K 0.40) and 4 (r/t 2: class 1-3 t, K 0.45): each bend's K-factor and allowance its own, the blank the sum."""
    w = bd.Wire.make_polygon([(-40, 0, 0), (0, 0, 0), (0, 30, 0), (60, 30, 0)], close=False)
    w = w.fillet_2d(1.0 + T / 2, [v for v in w.vertices() if np.allclose(tuple(v), (0, 0, 0))])
    w = w.fillet_2d(4.0 + T / 2, [v for v in w.vertices() if np.allclose(tuple(v), (0, 30, 0))])
    plane = bd.Plane(origin=w.position_at(0), x_dir=(0, 0, 1), z_dir=w.tangent_at(0))
    part = bd.sweep(plane * bd.Rectangle(WIDTH, T), path=w, transition=bd.Transition.RIGHT)
    blank = patterns.unfold(part, material="stainless")
    got = sorted((b.inside_radius, b.k_factor, b.allowance) for b in blank.bends)
    assert np.array(got) == pytest.approx(np.array([(1.0, 0.40, np.pi / 2 * (1 + 0.40 * T)),
                                                    (4.0, 0.45, np.pi / 2 * (4 + 0.45 * T))]), abs=1e-9)
    assert blank.k_factor is None  # no one K-factor for the blank: each bend says its own
    assert sorted(r.k_factor for r in blank.bend_sheet()) == [0.40, 0.45]
    flanges = (40 - 2) + (30 - 2 - 5) + (60 - 5)  # each straight run less the fillets' centreline radii
    assert max(blank.size) == pytest.approx(flanges + sum(a for _, _, a in got), abs=1e-6)


def test_material_with_k_factor_or_bend_table_and_unknown_material_are_refused(tmp_path, capsys):
    bend_table = tmp_path / "bd.csv"
    bend_table.write_text("thickness,radius,angle,deduction\n1.5,2,90,3.5\n")
    part = bent_strip()
    with pytest.raises(patterns.InputError, match=r"material gives every bend its K-factor, bend_table gives"):
        patterns.unfold(part, material="stainless", bend_table=bend_table)
    with pytest.raises(patterns.InputError, match=r"material gives every bend its K-factor, k_factor gives"):
        patterns.unfold(part, material="stainless", k_factor=0.4)
    with pytest.raises(patterns.InputError, match=r"material gives every bend its K-factor, k_factor gives"):
        patterns.unfold(part, material="stainless", k_factor=0.5)  # the default's value, given: still two answers
    with pytest.raises(patterns.InputError, match=r"unknown material 'steel'; the bundled material table has "
                                                  r"aluminium-5052, aluminium-6061, mild-steel, stainless"):
        patterns.unfold(part, material="steel")
    step = tmp_path / "strip.step"
    bd.export_step(part, str(step))
    assert main(["unfold", str(step), "-o", str(tmp_path / "s.dxf"), "--material", "steel"]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "unknown --material 'steel'" in err
    assert main(["unfold", str(step), "-o", str(tmp_path / "s.dxf"), "--material", "stainless",
                 "--bend-table", str(bend_table)]) == 2
    assert "--material gives every bend its K-factor, --bend-table gives them too" in capsys.readouterr().err
    for flag in ("--k-factor", "--k-fac"):  # typed at the default's value, and abbreviated as argparse allows
        assert main(["unfold", str(step), "-o", str(tmp_path / "s.dxf"), "--material", "stainless", flag,
                     "0.5"]) == 2
        assert "--material gives every bend its K-factor, --k-factor gives them too" in capsys.readouterr().err
    table = tmp_path / "shop.csv"  # an input: the bend sheet may not overwrite it
    table.write_text("material,thickness_min,thickness_max,rt_min,rt_max,k_factor\nbrass,1,3,0,3,0.4\n")
    assert main(["unfold", str(step), "-o", str(tmp_path / "s.dxf"), "--material", "brass", "--material-table",
                 str(table), "--bend-sheet", str(table)]) == 2
    assert "shop.csv" in capsys.readouterr().err
    assert table.read_text().endswith("brass,1,3,0,3,0.4\n")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bd.csv", "shop.csv", "strip.step"]


# --------------------------------------------------------------------------- #
# Faults a shop would notice
# --------------------------------------------------------------------------- #


def _contours(path) -> list:
    """Every closed CUT contour of a DXF read back: ``(area, perimeter)`` of each, mm, exactly: a circle from
    its radius, a polyline from its vertices and bulges (each arc's segment added to the polygon's area)."""
    out = []
    for e in ezdxf.readfile(path).modelspace().query("LWPOLYLINE CIRCLE[layer=='CUT']"):
        if e.dxftype() == "CIRCLE":
            out.append((np.pi * e.dxf.radius**2, 2 * np.pi * e.dxf.radius))
            continue
        assert e.closed
        points = np.array(e.get_points("xyb"))
        xy, bulge = points[:, :2], points[:, 2]
        nxt = np.roll(xy, -1, axis=0)
        area = 0.5 * np.sum(xy[:, 0] * nxt[:, 1] - nxt[:, 0] * xy[:, 1])
        chord = np.linalg.norm(nxt - xy, axis=1)
        theta = 4 * np.arctan(bulge)  # each segment's arc angle, signed (0: a straight segment)
        arc = np.abs(theta) > 1e-12
        radius = np.where(arc, chord / (2 * np.abs(np.sin(theta / 2)) + ~arc), 0.0)
        area += np.sum(radius**2 / 2 * (theta - np.sin(theta)))
        out.append((abs(area), float(np.sum(np.where(arc, radius * np.abs(theta), chord)))))
    return out


def test_slots_and_rectangular_cutouts_reach_the_dxf(tmp_path):
    """Planted bug caught: the non-circular holes of a blank left out of the DXF (machine.py writing circles
    only).  An L bracket with an obround slot (12 mm between centres, 6 wide), a rectangular cut-out 8 x 5 and
    a 4 mm drilled hole in its long flange: the DXF read back has each as a closed contour of its area and
    perimeter."""
    part = swept([(60, 0), (0, 0), (0, 40)])
    flange = bd.Plane(origin=(30, 0, 0), x_dir=(1, 0, 0), z_dir=(0, 1, 0))  # on the long flange, across it
    part -= flange * bd.Pos(0, -8) * bd.extrude(bd.SlotCenterToCenter(12, 6), amount=5, both=True)
    part -= flange * bd.Pos(0, 10) * bd.Box(8, 5, 10)
    part -= flange * bd.Pos(15, 0) * bd.Cylinder(2, 10)
    blank = patterns.unfold(part, k_factor=0.4)
    assert len(blank.holes) == 3
    path = tmp_path / "slots.dxf"
    patterns.write(blank, path)
    contours = sorted(_contours(path))
    assert len(contours) == 4
    expected = sorted([(12 * 6 + np.pi * 9, 24 + 6 * np.pi), (40.0, 26.0), (np.pi * 4, 4 * np.pi)])
    for (area, perimeter), (a, p) in zip(contours[:3], expected):
        assert area == pytest.approx(a, rel=1e-5) and perimeter == pytest.approx(p, rel=1e-5)
    length = 56 + 36 + np.pi / 2 * (R + 0.4 * T)
    assert contours[3][0] == pytest.approx(length * WIDTH, rel=1e-6)


def test_convex_conical_bend_takes_its_neutral_layer_from_the_inside(tmp_path):
    """Planted bug caught: the neutral offset of a convex bend written -K t instead of -(1 - K) t
    (bends._cone_map).  A conical bend unfolded from either skin of its flange, K = 0.3: both blanks are the
    same neutral sector, K t in from the cone's inside skin (with K = 0.5 the two offsets agree)."""
    r1, r2, h, t, length, sweep, k = 40.0, 80.0, 60.0, 2.0, 150.0, 120.0, 0.3
    part = conical_sheet(r1=r1, r2=r2, h=h, t=t, length=length, sweep=sweep)
    half, generator = np.arctan2(r2 - r1, h), np.hypot(r2 - r1, h)
    s_a = r1 / np.sin(half) + k * t / np.tan(half)
    s_b, phi = s_a + generator, np.radians(sweep) * np.sin(half)
    skins = [i for i, f in enumerate(part.faces()) if f.geom_type.name == "PLANE" and abs(f.area - length * generator) < 1e-6]
    directions = []
    for fixed in skins:
        blank = patterns.unfold(part, k_factor=k, fixed_face=fixed)
        assert blank.area == pytest.approx(length * generator + phi * (s_b**2 - s_a**2) / 2, rel=1e-5)
        assert blank.perimeter == pytest.approx(2 * length + 2 * generator + phi * (s_a + s_b), rel=1e-6)
        directions.append(blank.bends[0].direction)
    assert sorted(directions) == ["down", "up"]  # one skin concave, the other convex


@pytest.mark.slow
def test_convex_meshed_bend_takes_its_neutral_layer_from_the_inside():
    """Planted bug caught: the meshed face's neutral surface moved K t into the sheet from a convex skin
    instead of (1 - K) t (meshed.meshed_face).  The spline bend unfolded from either skin, K = 0.3, and with mild
    steel (r/t 1.33: K 0.43): 100 + pi/2 (r + K t) long (the mesh's chords: within 0.05 mm)."""
    part = spline_strip()
    skins = [i for i, f in enumerate(part.faces()) if f.geom_type.name == "PLANE" and abs(f.area - 60 * 30) < 1e-6]
    assert len(skins) == 2
    for fixed in skins:
        for keywords, k in (({"k_factor": 0.3}, 0.3), ({"material": "mild-steel"}, 0.43)):
            blank = patterns.unfold(part, fixed_face=fixed, **keywords)
            assert max(blank.size) == pytest.approx(100 + np.pi / 2 * (2.0 + k * 1.5), abs=0.05)
            assert [f.code for f in blank.findings] == [patterns.Code.MESHED_FACE]


def test_unfold_exits_1_and_writes_nothing_when_its_check_fails(tmp_path, capsys):
    """Planted bug caught: ``patterns unfold`` exiting 0 when its check fails.  A flange bent up from the edge of
    a window, longer than the window, lies on the plate once unfolded: exit 1, no DXF, no report, no bend
    sheet."""
    strip = bent_strip(la=30, lb=60, width=20, r=2, t=1.5)
    frame = bd.Pos(20, 10, -0.75) * bd.Box(160, 80, 1.5) - bd.Pos(12, 10, -0.75) * bd.Box(24, 30, 1.5)
    step = tmp_path / "window.step"
    bd.export_step(strip + frame, str(step))
    code = main(["unfold", str(step), "-o", str(tmp_path / "w.dxf"), "--report", str(tmp_path / "w.json"),
                 "--bend-sheet", str(tmp_path / "w.csv")])
    out = capsys.readouterr().out
    assert code == 1
    assert "not written" in out and "error:" in out
    assert sorted(p.name for p in tmp_path.iterdir()) == ["window.step"]


def test_report_numbers_the_bends_as_the_dxf_does(z_bracket, tmp_path):
    blank = patterns.unfold(z_bracket, k_factor=0.3)
    patterns.write(blank, tmp_path / "z.json")
    (piece,) = json.loads((tmp_path / "z.json").read_text())["pieces"]
    assert sorted(b["sequence"] for b in piece["bends"]) == [1, 2]
    labels = sorted(lb["text"] for lb in piece["labels"] if lb["kind"] == "bend")
    # from the face the flanges rise from (of flange C's two equal sides): flange A's bend down, C's up
    details = f"BA {np.pi / 2 * (R + 0.3 * T):.2f} L {WIDTH:.2f} MM"
    assert labels == ["1 DOWN 90.0 DEG R3", "2 UP 90.0 DEG R3", details, details]


@pytest.mark.slow
def test_a_material_unfolds_a_meshed_jog_flat_at_its_middle():
    """An S-shaped jog drawn as a spline is meshed; its middle is an inflection (flat: r/t infinite), so no
    material row gives its K: the mid-plane's (0.5) is taken, and the blank is the centre line's length."""
    path = bd.Wire([bd.Edge.make_line((-40, 0, 0), (0, 0, 0)),
                    bd.Edge.make_spline([(0, 0, 0), (15, 0, 6), (30, 0, 12)], tangents=[(1, 0, 0), (1, 0, 0)]),
                    bd.Edge.make_line((30, 0, 12), (70, 0, 12))])
    plane = bd.Plane(origin=path.position_at(0), x_dir=(0, 1, 0), z_dir=path.tangent_at(0))
    jog = bd.sweep(plane * bd.Rectangle(40, 2), path=path, transition=bd.Transition.RIGHT)  # centred on the path
    blank = patterns.unfold(jog, material="mild-steel")
    assert [f.code for f in blank.findings] == [patterns.Code.MESHED_FACE]
    assert max(blank.size) == pytest.approx(path.length, abs=0.01)  # the mid-surface, developed
