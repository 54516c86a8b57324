"""Sheet metal: a bent part unfolds into one blank (``patterns.unfold``, ``patterns unfold``).

References are independent of the unfolder: the neutral-layer length of a bent
strip built with build123d (``la + lb + angle (r + k t)``), a bend-deduction
table's own arithmetic, the written DXF read back (ezdxf, dxf2gcode, FreeCAD),
and SolidWorks' flat patterns of four real parts (``../shared/sheetmetal``).
"""

from __future__ import annotations

import itertools
import json
import os
import re
import shutil
import subprocess
import zlib
from pathlib import Path

import build123d as bd
import ezdxf
import numpy as np
import pytest
import shapely
from scipy.spatial import cKDTree

import patterns
from patterns.cli import main
from patterns.comparison import _resample

from .helpers import is_dashed

SHEETMETAL = Path(__file__).resolve().parent.parent.parent / "shared" / "sheetmetal"
READERS = Path(__file__).resolve().parent / "readers"
PARTS = {  # SolidWorks' figures from ../shared/sheetmetal/README.md: area mm², outer perimeter mm, holes, bend lines
    "MMP.00.00.00.002_Back_panel": (79828.8, 1231.17, 15, 4),
    "MMP.01.00.00.001_Cover": (383025.3, 2663.69, 15, 10),
    "MMP.03.00.00.001_Wheel_bracket_outer": (38289.7, 1074.45, 22, 3),
    "MMP.05.00.00.001_Support": (16902.6, 870.54, 12, 4),
}
K = 0.47  # the parts' K-factor (their README)


def bent_strip(*, la=60.0, lb=40.0, width=30.0, r=2.0, t=1.5, angle=90.0, hole=0.0):
    """A strip of thickness t bent once (inside radius r, by ``angle`` degrees) about an axis along y:
    flange A (la long) in z in [-t, 0] along -x, flange B (lb long) after the bend; a hole in flange A."""
    th = np.radians(angle)

    def arc(rad, frac):
        a = -np.pi / 2 + th * frac
        return (rad * np.cos(a), 0.0, r + rad * np.sin(a))

    d = np.array([np.cos(th), 0.0, np.sin(th)])
    i1, i2, o1, o2 = (0, 0, 0), arc(r, 1), (0, 0, -t), arc(r + t, 1)
    i3, o3 = tuple(np.array(i2) + lb * d), tuple(np.array(o2) + lb * d)
    edge = bd.Edge
    edges = [edge.make_line((-la, 0, 0), i1), edge.make_three_point_arc(i1, arc(r, 0.5), i2),
             edge.make_line(i2, i3), edge.make_line(i3, o3), edge.make_line(o3, o2),
             edge.make_three_point_arc(o2, arc(r + t, 0.5), o1), edge.make_line(o1, (-la, 0, -t)),
             edge.make_line((-la, 0, -t), (-la, 0, 0))]
    solid = bd.extrude(bd.Face(bd.Wire(edges)), amount=width, dir=(0, 1, 0))
    if hole:
        solid -= bd.Pos(-la / 2, width / 2, 0) * bd.Cylinder(hole, 4 * t)
    return solid


def spline_strip(*, r=2.0, t=1.5, width=30.0):
    """A strip bent 90 degrees whose bend is drawn as splines (an extrusion surface, meshed when unfolded):
    flanges 60 and 40 mm on both skins."""
    th = np.radians(90.0)

    def arc(rad, frac):
        a = -np.pi / 2 + th * frac
        return (rad * np.cos(a), 0.0, r + rad * np.sin(a))

    i2, o2 = arc(r, 1), arc(r + t, 1)
    fr = np.linspace(0, 1, 9)
    edge = bd.Edge
    edges = [edge.make_line((-60, 0, 0), (0, 0, 0)),
             edge.make_spline([arc(r, x) for x in fr], tangents=[(1, 0, 0), (0, 0, 1)]),
             edge.make_line(i2, (r, 0, r + 40)), edge.make_line((r, 0, r + 40), (r + t, 0, r + 40)),
             edge.make_line((r + t, 0, r + 40), o2),
             edge.make_spline([arc(r + t, x) for x in fr[::-1]], tangents=[(0, 0, -1), (-1, 0, 0)]),
             edge.make_line((0, 0, -t), (-60, 0, -t)), edge.make_line((-60, 0, -t), (-60, 0, 0))]
    return bd.extrude(bd.Face(bd.Wire(edges)), amount=width, dir=(0, 1, 0))


def _need_parts():
    if not SHEETMETAL.is_dir():
        pytest.skip(f"{SHEETMETAL} is absent (the shared sheet-metal parts sit beside the repository in CI)")


# --------------------------------------------------------------------------- #
# The development: analytic lengths
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize("angle", [60.0, 90.0, 135.0])
def test_bent_strip_unfolds_to_its_neutral_length(angle):
    k, r, t, width = 0.4, 2.0, 1.5, 30.0
    blank = patterns.unfold(bent_strip(angle=angle, r=r, t=t, width=width, hole=4.0), k_factor=k)
    length = 60.0 + 40.0 + np.radians(angle) * (r + k * t)  # flange A + flange B + the neutral arc
    assert blank.thickness == pytest.approx(t, abs=1e-9)
    assert blank.perimeter == pytest.approx(2 * (length + width), abs=1e-6)
    assert blank.area == pytest.approx(length * width - np.pi * 16.0, rel=2e-5)  # the hole sampled within 1 µm
    assert sorted(blank.size) == pytest.approx(sorted([length, width]), abs=1e-6)
    (bend,) = blank.bends
    assert bend.angle == pytest.approx(angle, abs=1e-9)
    assert bend.inside_radius == pytest.approx(r, abs=1e-9)
    assert bend.allowance == pytest.approx(np.radians(angle) * (r + k * t), abs=1e-9)
    assert bend.direction == "up"  # flange B rises towards the side the fixed face shows
    # The bend line: across the whole width, in the middle of the bend zone: 60 + allowance / 2 from flange A's end.
    assert np.linalg.norm(bend.line[1] - bend.line[0]) == pytest.approx(width, abs=1e-6)
    outline = blank.outline.points()
    distances = (outline - bend.line[0]) @ _normal(bend.line)
    assert sorted([abs(distances.min()), abs(distances.max())]) == pytest.approx(
        sorted([60 + bend.allowance / 2, 40 + bend.allowance / 2]), abs=1e-6)
    (hole,) = blank.holes
    assert hole.is_circle and hole.pieces[0].radius == pytest.approx(4.0, abs=1e-9)


def _unit(line):
    d = line[1] - line[0]
    return d / np.linalg.norm(d)


def _normal(line):
    d = _unit(line)
    return np.array([-d[1], d[0]])


def conical_sheet(*, r1=40.0, r2=80.0, h=60.0, t=2.0, length=150.0, sweep=120.0):
    """A cone of sheet (inside radius r1 at the bottom, r2 at height h, thickness t across the generator)
    turning ``sweep`` degrees about z, with a flat flange ``length`` long tangent to it along its first
    generator."""
    g = np.array([r2 - r1, h]) / np.hypot(r2 - r1, h)
    n = np.array([g[1], -g[0]])
    a, b = np.array([r1, 0.0]), np.array([r2, h])
    face = bd.Face(bd.Wire.make_polygon([(p[0], 0, p[1]) for p in (a, b, b + t * n, a + t * n)], close=True))
    return bd.revolve(face, axis=bd.Axis.Z, revolution_arc=sweep) + bd.extrude(face, amount=length, dir=(0, -1, 0))


def test_conical_bend_unfolds_to_its_neutral_sector():
    r1, r2, h, t, length, sweep, k = 40.0, 80.0, 60.0, 2.0, 150.0, 120.0, 0.4
    blank = patterns.unfold(conical_sheet(r1=r1, r2=r2, h=h, t=t, length=length, sweep=sweep), k_factor=k)
    half = np.arctan2(r2 - r1, h)  # the cone's half-angle
    generator = np.hypot(r2 - r1, h)
    # The neutral cone: the inside offset by k t across the generator; its apex moves, its slant distances
    # grow by k t / tan(half); developed, an annular sector of angle sweep sin(half).
    s_a = r1 / np.sin(half) + k * t / np.tan(half)
    s_b = s_a + generator
    phi = np.radians(sweep) * np.sin(half)
    assert blank.area == pytest.approx(length * generator + phi * (s_b**2 - s_a**2) / 2, rel=1e-5)
    assert blank.perimeter == pytest.approx(2 * length + 2 * generator + phi * (s_a + s_b), rel=1e-6)
    assert len(blank.bends) == 1 and blank.bends[0].direction == "up"
    assert blank.bends[0].allowance == pytest.approx(phi * (s_a + s_b) / 2, rel=1e-9)
    # The cone has a flat face on one side only: a warning, and the blank is still cut.
    (warning,) = blank.findings
    assert warning.code is patterns.Code.BEND_WITHOUT_FLANGE and not warning.error and blank.ok


def test_a_bend_that_is_no_cylinder_is_meshed_and_says_so():
    """The bend of a strip drawn as splines (an extrusion surface, not a cylinder) is meshed, moved to
    its neutral surface and flattened: close to the exact length, with its strain reported."""
    r, t, k, width = 2.0, 1.5, 0.4, 30.0
    part = spline_strip(r=r, t=t, width=width)
    assert "EXTRUSION" in {f.geom_type.name for f in part.faces()}
    blank = patterns.unfold(part, k_factor=k)
    length = 100.0 + np.pi / 2 * (r + k * t)
    assert max(blank.size) == pytest.approx(length, abs=0.05)  # the mesh's chords and relaxation: < 0.05 mm
    assert blank.area == pytest.approx(length * width, rel=5e-4)
    (finding,) = blank.findings
    assert finding.code is patterns.Code.MESHED_FACE and not finding.error and blank.ok
    assert "meshed" in finding.message and "strain up to" in finding.message


def test_k_factor_moves_the_length_by_angle_times_thickness():
    a = patterns.unfold(bent_strip(), k_factor=0.3)
    b = patterns.unfold(bent_strip(), k_factor=0.5)
    assert max(b.size) - max(a.size) == pytest.approx(np.radians(90) * 0.2 * 1.5, abs=1e-9)


def test_bend_table_gives_the_bend_deduction(tmp_path):
    table = tmp_path / "bends.csv"
    table.write_text("thickness,radius,angle,deduction\n1.5,2,60,1.3\n1.5,2,120,6.7\n2,2,90,3.5\n")
    blank = patterns.unfold(bent_strip(), bend_table=table)
    # 90 degrees lies half-way between the rows of 60 and 120: BD 4.0.  Mold-line flanges: la + r + t, lb + r + t.
    assert max(blank.size) == pytest.approx((60 + 2 + 1.5) + (40 + 2 + 1.5) - 4.0, abs=1e-9)
    assert blank.k_factor is None
    with pytest.raises(patterns.InputError, match=r"bends.csv: no row for thickness 1.5 mm, inside radius 2 mm"):
        patterns.unfold(bent_strip(angle=150), bend_table=table)
    bad = tmp_path / "bad.csv"
    bad.write_text("thickness,radius,angle,deduction\n1.5,2,x,1\n")
    with pytest.raises(patterns.InputError, match=r"bad.csv, line 2: every value must be a number"):
        patterns.unfold(bent_strip(), bend_table=bad)


# --------------------------------------------------------------------------- #
# Faults: never a wrong blank
# --------------------------------------------------------------------------- #


def test_a_machined_block_is_not_a_sheet():
    block = bd.Box(100, 100, 20) - bd.Pos(0, 0, 5) * bd.Box(50, 50, 10)
    with pytest.raises(patterns.InputError, match="not a sheet"):
        patterns.unfold(block)


def corrugated(*, t=1.0, width=5.0, r=2.0, waves=4, flat=20.0, rise=15.0):
    """A corrugated strip: a ``width`` x ``t`` rectangle swept along a filleted zig-zag centre line; its end
    face (the whole profile, ``t`` thick) is larger than any one flat.  Returns (solid, centre line)."""
    points, x = [(0.0, 0.0)], 0.0
    for i in range(waves):
        x += flat
        points.append((x, (i % 2) * rise))
        x += flat / 2
        points.append((x, ((i + 1) % 2) * rise))
    points.append((x + flat, (waves % 2) * rise))
    with bd.BuildLine() as line:
        bd.FilletPolyline(*points, radius=r + t / 2)
    path = line.wire()
    plane = bd.Plane(origin=path.position_at(0), x_dir=(0, 0, 1), z_dir=path.tangent_at(0))
    return bd.sweep(plane * bd.Rectangle(width, t), path=path, transition=bd.Transition.RIGHT), path


def test_a_corrugated_strip_whose_end_face_is_the_largest_unfolds_from_a_flat():
    """Issue 33: the largest planar face is the end (8 % of the surface, not a skin): the next plane that starts
    a sheet is the fixed face, and the blank is the centre line long (K 0.5: the neutral layer is the middle)."""
    part, path = corrugated()
    planes = sorted((f for f in part.faces() if f.geom_type == bd.GeomType.PLANE), key=lambda f: -f.area)
    assert planes[0].area == pytest.approx(path.length * 1.0, rel=1e-9)  # the end face: the profile, 1 mm thick
    blank = patterns.unfold(part, k_factor=0.5)
    assert sorted(blank.size) == pytest.approx([5.0, path.length], abs=1e-6)
    assert len(blank.bends) == 8 and blank.thickness == pytest.approx(1.0, abs=1e-9)
    assert part.faces()[blank.fixed_face].geom_type == bd.GeomType.PLANE
    assert part.faces()[blank.fixed_face].area < planes[0].area


def test_a_block_is_refused_naming_the_face_option():
    block = bd.Box(100, 100, 20) - bd.Pos(0, 0, 5) * bd.Box(50, 50, 10)
    with pytest.raises(patterns.InputError, match=r"not a sheet.*no other planar face starts a sheet either "
                                                  r"\(fixed_face=N, --fixed-face N"):
        patterns.unfold(block)


def test_a_square_tube_with_no_seam_is_refused_with_where_to_cut():
    outer = bd.fillet(bd.Box(60, 60, 100).edges().filter_by(bd.Axis.Z), 5)
    inner = bd.fillet(bd.Box(56, 56, 100).edges().filter_by(bd.Axis.Z), 3)
    with pytest.raises(patterns.InputError, match="closes on itself.*cut it"):
        patterns.unfold(outer - inner)


def test_a_round_tube_is_refused():
    with pytest.raises(patterns.InputError, match="closed tube.*cut it"):
        patterns.unfold(bd.Cylinder(20, 100) - bd.Cylinder(18, 100))


def test_flanges_that_land_on_the_plate_are_an_error_and_no_dxf(tmp_path):
    # A flange bent up from the edge of a window, longer than the window: unfolded, it lies on the plate.
    strip = bent_strip(la=30, lb=60, width=20, r=2, t=1.5)
    frame = bd.Pos(20, 10, -0.75) * bd.Box(160, 80, 1.5) - bd.Pos(12, 10, -0.75) * bd.Box(24, 30, 1.5)
    part = strip + frame
    blank = patterns.unfold(part)
    assert not blank.ok
    assert [f.code for f in blank.findings if f.error] == [patterns.Code.FLANGES_OVERLAP]
    with pytest.raises(patterns.ExportError, match="not written"):
        patterns.write(blank, tmp_path / "x.dxf")
    assert list(tmp_path.iterdir()) == []


# --------------------------------------------------------------------------- #
# The DXF, read back
# --------------------------------------------------------------------------- #


@pytest.fixture(scope="module")
def strip_blank():
    return patterns.unfold(bent_strip(hole=4.0, angle=90), k_factor=0.4)


def test_dxf_holds_the_blank_and_its_bend_lines(strip_blank, tmp_path):
    path = tmp_path / "blank.dxf"
    patterns.write(strip_blank, path)
    doc = ezdxf.readfile(path)
    assert doc.header["$INSUNITS"] == 4 and doc.header["$MEASUREMENT"] == 1
    msp = doc.modelspace()
    (outline,) = msp.query("LWPOLYLINE[layer=='CUT']")
    assert outline.closed
    (circle,) = msp.query("CIRCLE[layer=='CUT']")
    assert circle.dxf.radius == pytest.approx(4.0, abs=1e-12)
    (bend,) = msp.query("LINE[layer=='BEND']")
    linetype = doc.layers.get("BEND").dxf.linetype  # dashed: a pattern of dashes and gaps
    assert is_dashed(doc, linetype)
    texts = [t.dxf.text for t in msp.query("TEXT[layer=='BEND']")]
    assert texts == ["UP 90.0 DEG R2", f"BA {np.pi / 2 * (2.0 + 0.4 * 1.5):.2f} L 30.00 MM"]  # R + K t; the width
    # on its line, from the bend's own line moved as the drawing moved the blank (5 mm from the axes)
    x0, y0 = strip_blank.polygon.bounds[:2]
    expected = strip_blank.bends[0].line + [5.0 - x0, 5.0 - y0]
    got = np.array([bend.dxf.start, bend.dxf.end])[:, :2]
    assert np.abs(got - expected).max() < 1e-9 or np.abs(got[::-1] - expected).max() < 1e-9
    read = patterns.read_flat_pattern(path)
    assert read.area == pytest.approx(strip_blank.area, rel=1e-5)  # the reader samples the hole within 0.001 mm: 0.017 mm² short
    assert read.perimeter == pytest.approx(strip_blank.perimeter, rel=1e-9)
    assert len(read.bend_lines) == 1
    x0, y0 = read.outline.min(axis=0)
    assert (x0, y0) == pytest.approx((5.0, 5.0), abs=1e-9)  # first quadrant, 5 mm from the axes


def test_librecad_renders_a_real_blank(tmp_path):
    if shutil.which("librecad") is None:
        pytest.skip("librecad is not installed (.ci/run installs it with apt-get)")
    _need_parts()
    blank = patterns.unfold(SHEETMETAL / "MMP.05.00.00.001_Support.STEP", k_factor=K)
    path = tmp_path / "support.dxf"
    patterns.write(blank, path)
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen", XDG_RUNTIME_DIR=str(tmp_path), HOME=str(tmp_path))
    proc = subprocess.run(["librecad", "dxf2pdf", "--fit", str(path)], capture_output=True, text=True, env=env,
                          timeout=120)
    assert proc.returncode == 0, proc.stderr[-2000:]
    data = (tmp_path / "support.pdf").read_bytes()
    content = b"".join(_inflate(s) for s in re.findall(rb"stream\r?\n(.*?)\r?\nendstream", data, re.DOTALL))
    # Drawn as vector paths: at least one line-to for every straight piece of the outline.
    straight = sum(1 for piece in blank.outline.pieces if isinstance(piece, patterns.curves.Line))
    assert len(re.findall(rb"\sl\s", content)) >= straight


def _inflate(stream: bytes) -> bytes:
    try:
        return zlib.decompress(stream)
    except zlib.error:
        return stream


def test_dxf2gcode_reads_closed_contours(strip_blank, tmp_path):
    if shutil.which("dxf2gcode") is None:
        pytest.skip("dxf2gcode is not installed (.ci/run installs it with apt-get)")
    path = tmp_path / "blank.dxf"
    patterns.write(strip_blank, path)
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen", XDG_RUNTIME_DIR=str(tmp_path), HOME=str(tmp_path))
    proc = subprocess.run(["/usr/bin/python3", str(READERS / "dxf2gcode_contours.py"), str(path)],
                          capture_output=True, text=True, env=env, timeout=120)
    assert proc.returncode == 0, proc.stderr[-2000:]
    found = json.loads(proc.stdout.strip().splitlines()[-1])
    assert found["entities"]["CUT"]["contours"] == found["entities"]["CUT"]["closed"] == 2
    # the outline at its area and the hole (a CIRCLE) at pi r^2, as dxf2gcode holds them
    outer, hole = strip_blank.polygon.exterior, strip_blank.polygon.interiors[0]
    expected = sorted([np.pi * 4.0**2, shapely.Polygon(outer).area])
    np.testing.assert_allclose(found["entities"]["CUT"]["areas"], expected, rtol=1e-3)
    assert shapely.Polygon(hole).area == pytest.approx(np.pi * 4.0**2, rel=1e-3)
    assert found["metric"] is True


def test_freecad_reads_the_blank_closed_at_its_area(strip_blank, tmp_path):
    if shutil.which("freecadcmd") is None:
        pytest.skip("freecadcmd is not installed (.ci/run installs it with apt-get)")
    path = tmp_path / "blank.dxf"
    patterns.write(strip_blank, path)
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen", XDG_RUNTIME_DIR=str(tmp_path), HOME=str(tmp_path),
               DXF=str(path))
    proc = subprocess.run(["freecadcmd", str(READERS / "freecad_layers.py")], capture_output=True, text=True,
                          env=env, timeout=300)
    lines = [x for x in proc.stdout.splitlines() if "RESULT " in x]
    assert lines, proc.stdout[-2000:] + proc.stderr[-2000:]
    layers = json.loads(lines[-1].split("RESULT ", 1)[1])
    wires = sorted(w["area"] for w in layers["CUT"]["closed_wires"])
    assert wires == pytest.approx(sorted([np.pi * 16.0, strip_blank.outline.area]), rel=1e-4)
    assert "BEND" in layers


# --------------------------------------------------------------------------- #
# Real parts against SolidWorks' flat patterns
# --------------------------------------------------------------------------- #


@pytest.mark.slow
@pytest.mark.parametrize("part", sorted(PARTS))
def test_real_part_matches_solidworks(part):
    _need_parts()
    area, perimeter, holes, bends = PARTS[part]
    blank = patterns.unfold(SHEETMETAL / f"{part}.STEP", k_factor=K)
    assert blank.ok
    assert abs(blank.area - area) <= 0.0005 * area
    assert len(blank.holes) == holes
    assert len(blank.bends) == bends
    c = patterns.compare_blank(blank, SHEETMETAL / f"{part}.DXF")
    assert c.area_reference == pytest.approx(area, abs=0.5)  # our reading of their DXF agrees with their figures
    # every cut square to the sheet, as SolidWorks' sheet-metal cuts are (the Center bracket's two windows
    # across its bends were said to be counterbores before the first look at squareness)
    assert not [f for f in blank.findings if f.code is patterns.Code.OBLIQUE_CUT]
    if part != "MMP.05.00.00.001_Support":  # its one corner: SolidWorks' 0.5 x 2 mm slot (docs/sheet-metal.md)
        assert abs(blank.perimeter - perimeter) <= 0.5  # the Back panel's corners square, as SolidWorks draws them
        assert c.hausdorff <= 0.1


@pytest.mark.slow
def test_the_center_bracket_matches_solidworks_at_the_k_it_was_made_with():
    """The Center bracket (2 mm, R 1.5: r/t below 1, where the OpenAMR material table gives K 0.40) against
    SolidWorks' flat pattern (its figures in ../shared/sheetmetal/README.md): 124 holes, 18 bend lines, the
    outer perimeter within 0.5 mm and the outline within 0.1 mm; and none of its 124 cuts, all square to the
    sheet, carries an ``oblique-cut`` note (its two windows across bends were said to be counterbores)."""
    _need_parts()
    part = "MMP.04.00.00.001_Center_bracket"
    blank = patterns.unfold(SHEETMETAL / f"{part}.STEP", k_factor=0.40)
    assert blank.ok
    assert (len(blank.holes), len(blank.bends)) == (124, 18)
    assert abs(blank.perimeter - 3922.17) <= 0.5
    c = patterns.compare_blank(blank, SHEETMETAL / f"{part}.DXF")
    assert c.hausdorff <= 0.1
    assert not [f for f in blank.findings if f.code is patterns.Code.OBLIQUE_CUT]
    # what differs: its sixteen M5 tapping holes (Ø 4.2 in the model) are Ø 1.5 marks in SolidWorks' DXF
    assert [(d.kind, round(d.size, 1), round(d.size_reference, 1)) for d in c.differences] == [("hole", 4.2, 1.5)] * 16


@pytest.mark.slow
def test_the_support_differs_from_solidworks_only_by_its_slot():
    """SolidWorks' flat pattern of the Support has a 2 x 0.5 mm slot at the corner where one flange butts
    against the other's inside; its folded STEP has no such cut (two bend faces and two B-spline closing
    faces there). Everywhere more than 3 mm from that corner the outlines agree within 0.1 mm, and the
    perimeters differ by the slot's two long sides."""
    _need_parts()
    part = "MMP.05.00.00.001_Support"
    blank = patterns.unfold(SHEETMETAL / f"{part}.STEP", k_factor=K)
    ref = patterns.read_flat_pattern(SHEETMETAL / f"{part}.DXF")
    from patterns.comparison import _align

    ours = [blank.outline.points(), *[h.points() for h in blank.holes]]
    rot, shift = _align(np.vstack([_resample(lp, 0.5) for lp in ours]),
                        np.vstack([_resample(lp, 0.02) for lp in (ref.outline, *ref.holes)]))
    ours = _resample(blank.outline.points(), 0.02) @ rot.T + shift
    theirs = _resample(ref.outline, 0.02)
    there, back = cKDTree(theirs).query(ours)[0], cKDTree(ours).query(theirs)[0]
    far = np.vstack([ours[there > 0.1], theirs[back > 0.1]])
    corner = far.mean(axis=0)
    assert np.linalg.norm(far - corner, axis=1).max() < 1.5  # one place: the slot, 2 x 0.5 mm
    assert there[np.linalg.norm(ours - corner, axis=1) > 3].max() <= 0.1
    assert back[np.linalg.norm(theirs - corner, axis=1) > 3].max() <= 0.1
    assert blank.perimeter - ref.perimeter == pytest.approx(-2 * 2.0, abs=0.05)
    # compare_blank names that one place: the slot, 2 mm deep, where the far points are
    (place,) = patterns.compare_blank(blank, ref).differences
    assert place.kind == "outline" and place.distance == pytest.approx(2.0, abs=0.05)
    assert np.hypot(place.x - corner[0], place.y - corner[1]) < 0.5


@pytest.mark.slow
def test_each_part_unfolds_through_the_command_line(tmp_path, capsys):
    _need_parts()
    part = "MMP.03.00.00.001_Wheel_bracket_outer"
    out, report = tmp_path / "blank.dxf", tmp_path / "blank.json"
    code = main(["unfold", str(SHEETMETAL / f"{part}.STEP"), "-o", str(out), "--k-factor", str(K),
                 "--report", str(report), "--compare", str(SHEETMETAL / f"{part}.DXF")])
    assert code == 0
    data = json.loads(report.read_text())
    (blank,) = data["blanks"]
    assert blank["holes"] == 22 and len(blank["bends"]) == 3 and data["ok"]
    assert data["comparison"]["hausdorff_mm"] <= 0.1
    read = patterns.read_flat_pattern(out)
    assert read.area == pytest.approx(blank["area_mm2"], rel=1e-4)
    (piece,) = data["pieces"]  # the report's blank is the DXF's, line for line
    assert read.area == pytest.approx(piece["area_mm2"], rel=1e-4)
    assert np.abs(np.array(read.bend_lines).reshape(-1, 4).min(axis=0)
                  - np.array([b["line"] for b in piece["bends"]]).reshape(-1, 4).min(axis=0)).max() < 0.01
    assert "Hausdorff" in capsys.readouterr().out


def test_command_line_refuses_bad_input_in_one_line_and_writes_nothing(tmp_path, capsys):
    step = tmp_path / "strip.step"
    bd.export_step(bent_strip(), str(step))
    out = tmp_path / "blank.dxf"
    for argv in (["--k-factor", "1.5"], ["--bend-table", str(tmp_path / "none.csv")], ["--fixed-face", "999"]):
        assert main(["unfold", str(step), "-o", str(out), *argv]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and err.startswith("patterns: error: ")
    assert main(["unfold", str(step), "-o", str(step)]) == 2
    assert sorted(p.name for p in tmp_path.iterdir()) == ["strip.step"]


# --------------------------------------------------------------------------- #
# Blanks are pieces: nested, written by every profile, checked, batched
# --------------------------------------------------------------------------- #


def _cut_polygons(path, layer="CUT"):
    """Every cut outline of a DXF read back, with the holes inside it (ezdxf's paths, 0.001 mm chords)."""
    from ezdxf import path as ezpath

    doc = ezdxf.readfile(path)
    rings = []
    for e in doc.modelspace().query(f"LWPOLYLINE CIRCLE[layer=='{layer}']"):
        pts = np.array([(v.x, v.y) for v in ezpath.make_path(e).flattening(0.001)])
        rings.append(shapely.Polygon(pts))
    outers = [r for r in rings if not any(o is not r and o.contains(r) for o in rings)]
    return doc, [shapely.Polygon(o.exterior, [r.exterior for r in rings if r is not o and o.contains(r)])
                 for o in outers]


def test_unfold_nests_six_blanks_on_sheets_read_back(tmp_path, capsys):
    """``patterns unfold PART -o nest.dxf --sheet 600x400 --copies 6``: six blanks, each the blank's area,
    pairwise disjoint (10 mm apart) and inside their sheets, from the DXF read back with shapely; the
    report's bend lines lie on the DXF's."""
    step = tmp_path / "strip.step"
    bd.export_step(bent_strip(hole=4.0), str(step))
    blank = patterns.unfold(step, k_factor=0.5)
    out, report = tmp_path / "nest.dxf", tmp_path / "nest.json"
    code = main(["unfold", str(step), "-o", str(out), "--sheet", "600x400", "--copies", "6", "--nest-time", "1",
                 "--no-nest-cache", "--report", str(report)])
    assert code == 0, capsys.readouterr()
    doc, blanks = _cut_polygons(out)
    assert len(blanks) == 6
    assert all(b.area == pytest.approx(blank.area, rel=1e-5) and len(b.interiors) == 1 for b in blanks)
    assert all(blanks[i].distance(blanks[j]) >= 10.0 - 1e-6 for i in range(6) for j in range(i + 1, 6))
    sheets = [shapely.Polygon(np.array(e.get_points("xy"))) for e in doc.modelspace().query("LWPOLYLINE[layer=='STOCK']")]
    assert sheets and all(s.area == pytest.approx(600.0 * 400.0) for s in sheets)
    assert all(any(s.buffer(1e-6).contains(b) for s in sheets) for b in blanks)
    data = json.loads(report.read_text())
    bends = [np.array(e.dxf.start)[:2] for e in doc.modelspace().query("LINE[layer=='BEND']")]
    reported = [np.array(b["line"][0]) for p in data["pieces"] for b in p["bends"]]
    assert len(reported) == len(bends) == 6
    assert all(min(np.linalg.norm(bends - r, axis=1)) < 0.01 for r in reported)


def test_blanks_and_pattern_pieces_nest_together():
    """layout() of a blank, and of a blank with a pattern: every piece on the sheet, none touching."""
    blank = patterns.unfold(bent_strip(hole=4.0), k_factor=0.5)
    nest = patterns.layout(blank, sheet=(500.0, 250.0), copies=3, time_limit=1, cache=False)
    assert [p.name for p in nest.pieces] == ["part", "part #2", "part #3"]
    box = patterns.flatten(patterns.load(bd.Box(100, 60, 20), max_edge=20))
    mix = patterns.layout([box, blank], sheet=(500.0, 250.0), time_limit=1, cache=False)
    assert len(mix.pieces) == 7 and {p.source.kind for p in mix.pieces} == {"panel", "blank"}
    polys = [p.polygon for p in mix.pieces]
    assert all(polys[i].distance(polys[j]) >= 10.0 - 1e-6 for i in range(7) for j in range(i + 1, 7))
    (sheet,) = mix.stock
    assert shapely.box(*sheet).buffer(1e-6).contains(shapely.union_all(polys))


@pytest.mark.parametrize("name", ["L", "U", "Z"])
def test_exact_brackets_are_ok_everywhere(name, tmp_path, capsys):
    """A 2 mm L, U and Z bracket, inside radius 3 mm, a hole in a flange, drawn in build123d (a rectangle
    swept along the filleted profile): flattened face by face every panel is an exact development and every
    seam is its exact length on both sides (a bend's end arc against the arc's chords no more), so
    ``patterns check`` says ok; unfolded, the blank is the flanges plus the bends' allowances."""
    t, r, width = 2.0, 3.0, 40.0
    profile = {"L": [(60, 0), (0, 0), (0, 40)], "U": [(50, 30), (50, 0), (0, 0), (0, 30)],
               "Z": [(-40, 0), (0, 0), (0, 30), (40, 30)]}[name]
    with bd.BuildLine() as line:
        bd.FilletPolyline(*profile, radius=r + t / 2)
    path = line.wire()
    plane = bd.Plane(origin=path.position_at(0), x_dir=(0, 0, 1), z_dir=path.tangent_at(0))
    part = bd.sweep(plane * bd.Rectangle(width, t), path=path, transition=bd.Transition.RIGHT)
    (x0, y0), (x1, y1) = profile[:2]  # a hole through the first flange, in its middle
    drill = bd.Plane(origin=((x0 + x1) / 2, (y0 + y1) / 2, 0), z_dir=(y0 - y1, x1 - x0, 0)) * bd.Cylinder(4, 50)
    part = part - drill
    step = tmp_path / f"{name}.step"
    bd.export_step(part, str(step))
    assert main(["check", str(step)]) == 0
    assert f"{name}.step: ok" in capsys.readouterr().out
    pattern = patterns.flatten(patterns.load(step))
    for fs in pattern.seams:
        assert fs.flat_lengths == pytest.approx((fs.length, fs.length), rel=1e-9)
    blank = patterns.unfold(step, k_factor=0.47)
    straight = sum(np.linalg.norm(np.subtract(a, b)) for a, b in itertools.pairwise(profile))
    bends = len(profile) - 2
    # each flange shortened by (r + t/2) at a bend, each bend adds its neutral arc (r + K t) pi / 2
    expected = straight - 2 * bends * (r + t / 2) + bends * np.pi / 2 * (r + 0.47 * t)
    assert max(blank.size) == pytest.approx(expected, abs=1e-6) and min(blank.size) == pytest.approx(width)
    assert len(blank.holes) == 1 and blank.holes[0].is_circle and len(blank.bends) == len(profile) - 2


@pytest.mark.slow
def test_a_folder_of_real_parts_unfolds_in_a_batch(tmp_path):
    """``patterns batch IN -o OUT --unfold --k-factor 0.47`` on the shared OpenAMR parts: a row per part, each
    ``ok``; each DXF read back is the blank ``unfold`` makes (area, outer perimeter, holes, bend lines) and
    so matches SolidWorks as unfold does (area within 0.05 %, holes and bend lines equal); each report's
    bend lines lie on its DXF's."""
    _need_parts()
    folder = tmp_path / "in"
    folder.mkdir()
    for part in PARTS:
        (folder / f"{part}.STEP").symlink_to(SHEETMETAL / f"{part}.STEP")
    (folder / "notes.txt").write_text("not a part")
    out = tmp_path / "out"
    code = main(["batch", str(folder), "-o", str(out), "--unfold", "--k-factor", str(K), "--jobs", "2", "--quiet"])
    assert code == 0
    for part, (area, _, holes, bends) in PARTS.items():
        read = patterns.read_flat_pattern(out / f"{part}.dxf")
        blank = patterns.unfold(SHEETMETAL / f"{part}.STEP", k_factor=K)
        assert read.area == pytest.approx(blank.area, rel=1e-5) and abs(read.area - area) <= 0.0005 * area
        assert read.perimeter == pytest.approx(blank.perimeter, rel=1e-5)  # arcs read back as chords within 0.001 mm
        assert len(read.holes) == holes and len(read.bend_lines) == bends
        data = json.loads((out / f"{part}.json").read_text())
        assert data["ok"] and data["blanks"][0]["holes"] == holes
        reported = np.array([b["line"] for b in data["pieces"][0]["bends"]]).reshape(-1, 2)
        drawn = read.bend_lines.reshape(-1, 2)
        assert cKDTree(drawn).query(reported)[0].max() < 0.01
    assert sorted(p.name for p in out.iterdir()) == sorted(f"{p}.{s}" for p in PARTS for s in ("dxf", "json"))


def test_a_mesh_is_no_part_to_unfold_and_a_bend_table_is_never_overwritten(tmp_path, capsys):
    """The bend table is an input: ``-o table.dxf --bend-table table.dxf`` (or ``--report table.json`` over a
    table of that name) is refused in one line and the table is kept as it was."""
    step = tmp_path / "strip.step"
    bd.export_step(bent_strip(), str(step))
    rows = "thickness,radius,angle,deduction\n1.5,2,90,3.2\n"
    for name, flag in (("table.dxf", "-o"), ("table.json", "--report")):
        table = tmp_path / name
        table.write_text(rows)
        outputs = ["-o", str(table)] if flag == "-o" else ["-o", str(tmp_path / "b.dxf"), "--report", str(table)]
        assert main(["unfold", str(step), *outputs, "--bend-table", str(table)]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and name in err and "input" in err
        assert table.read_text() == rows
    assert sorted(p.name for p in tmp_path.iterdir()) == ["strip.step", "table.dxf", "table.json"]
    folder = tmp_path / "meshes"
    folder.mkdir()
    (folder / "dish.obj").symlink_to(Path(__file__).resolve().parent.parent / "samples" / "dish.obj")
    assert main(["batch", str(folder), "-o", str(tmp_path / "out"), "--unfold"]) == 2
    assert "no CAD (STEP, BREP, IGES) files in this folder" in capsys.readouterr().err


@pytest.mark.slow
def test_a_batch_of_exact_brackets_flattens_ok(tmp_path):
    """The L, U and Z brackets flattened face by face in a batch: every row ``ok`` (the seams of exact
    developments judged on their exact lengths), every part's report ok."""
    from patterns.samples import bracket

    folder = tmp_path / "in"
    folder.mkdir()
    for name, profile in (("L", None), ("U", [(50, 30), (50, 0), (0, 0), (0, 30)]),
                          ("Z", [(-40, 0), (0, 0), (0, 30), (40, 30)])):
        if profile is None:
            part = bracket()
        else:
            with bd.BuildLine() as line:
                bd.FilletPolyline(*profile, radius=4.0)
            path = line.wire()
            plane = bd.Plane(origin=path.position_at(0), x_dir=(0, 0, 1), z_dir=path.tangent_at(0))
            part = bd.sweep(plane * bd.Rectangle(40, 2.0), path=path, transition=bd.Transition.RIGHT)
        bd.export_step(part, str(folder / f"{name}.step"))
    result = patterns.batch(folder, tmp_path / "out", jobs=2, quiet=True)
    assert [(r.file, r.status) for r in result.rows] == [("L.step", "ok"), ("U.step", "ok"), ("Z.step", "ok")]
    for name in "LUZ":
        assert json.loads((tmp_path / "out" / f"{name}.json").read_text())["ok"]
