"""One piece model, a registry of writers: profiles, layer maps, SVG, the drawing's one frame.

References are independent of the writers: the files read back (ezdxf, Inkscape's PDF of the SVG,
the JSON parsed), the pieces' own geometry, and analytic values (a blank's size, a circle's area).
"""

from __future__ import annotations

import json
import shutil
import subprocess

import build123d as bd
import ezdxf
import numpy as np
import pytest
import shapely

import patterns
from patterns.curves import Arc, Line, Loop, Motion, Polyline
from patterns.errors import ExportError, InputError
from patterns.export import layer_map
from patterns.export.layers import PRESETS, ROLES
from patterns.export.registry import Profile, register, unregister

from .conftest import SAMPLES
from .helpers import is_dashed


@pytest.fixture(scope="module")
def cup():
    return patterns.flatten(patterns.load(SAMPLES / "cup.step"))


@pytest.fixture(scope="module")
def bracket():
    """The bundled L bracket: 2 mm, R3, 60 + 40 mm legs to the centre line, 40 wide, an 8 mm hole."""
    return patterns.unfold(SAMPLES / "bracket.step", k_factor=0.44)


# --------------------------------------------------------------------------- #
# Curves and pieces: exact, immutable, moved rigidly
# --------------------------------------------------------------------------- #


def test_a_loop_of_bulges_is_its_lines_and_arcs():
    """(x, y, bulge) rows to pieces and back: a 20 x 10 slot with round ends, its area and length exact."""
    r = 5.0
    rows = np.array([[0.0, -r, 0.0], [20.0, -r, 1.0], [20.0, r, 0.0], [0.0, r, 1.0]])  # bulge 1: a half circle
    loop = Loop.of_vertices(rows)
    assert [type(p) for p in loop.pieces] == [Polyline, Arc, Polyline, Arc]
    assert loop.length == pytest.approx(2 * 20.0 + 2 * np.pi * r, rel=1e-12)
    assert loop.area == pytest.approx(20.0 * 2 * r + np.pi * r**2, rel=1e-6)
    np.testing.assert_allclose(loop.vertices(), rows, atol=1e-12)


def test_motions_compose_and_mirror_keeps_a_loop_counter_clockwise():
    square = Loop((Line([0, 0], [2, 0]), Line([2, 0], [2, 1]), Line([2, 1], [0, 1]), Line([0, 1], [0, 0])))
    a, b = Motion(0.3, 5.0, -2.0), Motion(-1.1, 1.0, 4.0, mirrored=True)
    p = np.array([[1.5, -0.25], [3.0, 7.0]])
    np.testing.assert_allclose((a @ b)(p), a(b(p)), atol=1e-12)
    moved = square.moved(b)
    assert moved.counter_clockwise and moved.area == pytest.approx(2.0)
    circle = Loop((Arc([1.0, 2.0], 3.0, 0.25, -2 * np.pi),))  # a hole: clockwise
    assert not circle.moved(b).counter_clockwise and circle.moved(b).pieces[0].center == pytest.approx(b([1.0, 2.0]))


def test_a_piece_moved_carries_every_mark(cup):
    """Moved (and mirrored) pieces keep their areas, notches on their cut lines, seam lines to their left."""
    (piece, *_) = patterns.pieces_of(cup, seam_allowance=8.0, notch_spacing=30.0)
    for motion in (Motion(1.0, 100.0, -50.0), Motion(0.4, 3.0, 9.0, mirrored=True)):
        moved = piece.moved(motion)
        assert moved.area == pytest.approx(piece.area, rel=1e-12)
        assert moved.placement == motion
        cut = shapely.LinearRing(moved.outline.points())
        assert max(cut.distance(shapely.Point(n.at)) for n in moved.notches) < 1e-6
        assert all(moved.polygon.contains(shapely.Point(n.tip)) for n in moved.notches)
        for side in moved.seams:  # the piece to the left of its seam line
            a, b = side.points[len(side.points) // 2 - 1:len(side.points) // 2 + 1]
            left = (a + b) / 2 + 1.0 * np.array([-(b - a)[1], (b - a)[0]]) / np.linalg.norm(b - a)
            assert moved.finished.contains(shapely.Point(left))


# --------------------------------------------------------------------------- #
# The registry: one module and one line make a profile
# --------------------------------------------------------------------------- #


def _toy_write(drawing, path, options):
    """A toy profile: one line per piece, its name and cut area."""
    from patterns.files import atomic_output

    with atomic_output(path, what="toy file") as tmp:
        tmp.write_text("".join(f"{p.name}\t{p.area:.3f}\n" for p in drawing.pieces))


def test_a_registered_profile_writes_pieces_of_patterns_and_blanks(cup, bracket, tmp_path):
    register(Profile("toy", ".toy", _toy_write, "a toy: each piece's name and area"))
    try:
        patterns.write([cup, bracket], tmp_path / "parts.toy")
        rows = [line.split("\t") for line in (tmp_path / "parts.toy").read_text().splitlines()]
        assert [r[0] for r in rows] == [f"cup.step/{p.name}" for p in cup.panels] + ["bracket"]
        assert float(rows[-1][1]) == pytest.approx(bracket.area, abs=1e-3)
        assert patterns.WriteOptions(profile="toy").profile == "toy"  # the option takes it at once
        with pytest.raises(InputError, match="the toy profile writes .toy files, not '.dxf'"):
            patterns.write(cup, tmp_path / "x.dxf", profile="toy")
        with pytest.raises(InputError, match="named 'toy' is registered already"):
            register(Profile("toy", ".toy", _toy_write, "again"))
    finally:
        unregister("toy")
    with pytest.raises(InputError, match="profile must be one of machine, astm, svg, json, bends, got 'toy'"):
        patterns.WriteOptions(profile="toy")
    with pytest.raises(InputError, match="cannot write '.toy' files; write .csv, .dxf, .json, .svg"):
        patterns.write(cup, tmp_path / "y.toy")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["parts.toy"]


# --------------------------------------------------------------------------- #
# One layer convention for patterns and blanks; layer maps for shops
# --------------------------------------------------------------------------- #


def _layers(path):
    doc = ezdxf.readfile(path)
    return doc, {layer.dxf.name: (layer.dxf.color, layer.dxf.linetype) for layer in doc.layers}


def test_patterns_and_blanks_share_one_convention(cup, bracket, tmp_path):
    """flatten's and unfold's DXF: the same layers, colours and linetypes for the same roles."""
    patterns.write(cup, tmp_path / "cup.dxf", bend_spacing=40.0)
    patterns.write(bracket, tmp_path / "bracket.dxf")
    _, a = _layers(tmp_path / "cup.dxf")
    doc, b = _layers(tmp_path / "bracket.dxf")
    for name in ("CUT", "BEND", "LABEL"):
        assert a[name] == b[name]
    assert b["CUT"][0] == 1 and b["LABEL"][0] == 7 and b["BEND"][0] == 2 and is_dashed(doc, b["BEND"][1])
    msp = doc.modelspace()
    assert {e.dxf.layer for e in msp.query("LWPOLYLINE CIRCLE")} == {"CUT"}
    allowance = np.pi / 2 * (3.0 + 0.44 * 2.0)  # R3 + K t, a quarter turn: the bend sheet's allowance
    assert [t.dxf.text for t in msp.query("TEXT[layer=='BEND']")] == ["UP 90.0 DEG R3",
                                                                      f"BA {allowance:.2f} L 40.00 MM"]


@pytest.mark.parametrize("preset", sorted(PRESETS))
def test_every_preset_writes_its_layers_and_dashes_bend_lines(bracket, tmp_path, preset):
    """The L bracket's one bend goes up; with the preset's map every role lands on its layer, read back."""
    path = tmp_path / f"{preset}.dxf"
    patterns.write(bracket, path, layer_map=preset)
    doc = ezdxf.readfile(path)
    msp = doc.modelspace()
    table = PRESETS[preset]
    (outline,) = msp.query("LWPOLYLINE")
    (hole,) = msp.query("CIRCLE")
    (bend,) = msp.query("LINE")
    assert outline.dxf.layer == table["cut"].name and hole.dxf.layer == table["hole"].name
    assert bend.dxf.layer == table["bend_up"].name
    assert is_dashed(doc, doc.layers.get(bend.dxf.layer).dxf.linetype)
    assert doc.layers.get(bend.dxf.layer).dxf.color == table["bend_up"].color
    assert {t.dxf.layer for t in msp.query("TEXT")} == {table["label"].name, table["bend_up"].name}


def test_updown_puts_each_bend_on_its_direction_and_a_shop_names_or_drops_roles(tmp_path):
    """A Z bracket (one bend up, one down): BEND_UP and BEND_DOWN; a user's map renames the cut and drops
    the labels; --no-bend-lines leaves the bends and their labels out."""
    with bd.BuildLine() as line:
        bd.FilletPolyline((-40, 0), (0, 0), (0, 30), (40, 30), radius=4.0)
    path = line.wire()
    plane = bd.Plane(origin=path.position_at(0), x_dir=(0, 0, 1), z_dir=path.tangent_at(0))
    blank = patterns.unfold(bd.sweep(plane * bd.Rectangle(40, 2.0), path=path, transition=bd.Transition.RIGHT))
    directions = sorted(b.direction for b in blank.bends)
    assert directions == ["down", "up"]
    patterns.write(blank, tmp_path / "z.dxf", layer_map="updown")
    msp = ezdxf.readfile(tmp_path / "z.dxf").modelspace()
    (piece,) = patterns.pieces.drawing_of(blank).pieces  # the blank as the file lays it out
    for bend in piece.bends:  # each line on the layer of its own direction
        (drawn,) = [e for e in msp.query("LINE") if np.abs(np.array([e.dxf.start, e.dxf.end])[:, :2]
                                                           - bend.line).max() < 1e-9]
        assert drawn.dxf.layer == {"up": "BEND_UP", "down": "BEND_DOWN"}[bend.direction]
    mine = layer_map({"cut": "OUTER", "label": None})
    assert mine["cut"].name == "OUTER" and mine["label"] is None
    patterns.write(blank, tmp_path / "mine.dxf", layer_map="patterns,cut=OUTER,label=")
    doc = ezdxf.readfile(tmp_path / "mine.dxf")
    assert {e.dxf.layer for e in doc.modelspace().query("LWPOLYLINE")} == {"OUTER"}
    assert {t.dxf.layer for t in doc.modelspace().query("TEXT")} == {"BEND"}  # bend labels only
    patterns.write(blank, tmp_path / "nobend.dxf", bend_lines=False)
    doc = ezdxf.readfile(tmp_path / "nobend.dxf")
    assert not doc.modelspace().query("LINE") and "BEND" not in doc.layers
    assert not [t for t in doc.modelspace().query("TEXT") if "DEG" in t.dxf.text]
    for bad, words in (("nope", "unknown preset 'nope'"), ("updown,wing=W", "unknown role 'wing'"),
                       ("updown,cut", "expected role=LAYER")):
        with pytest.raises(InputError, match=words):
            patterns.write(blank, tmp_path / "bad.dxf", layer_map=bad)
    assert not (tmp_path / "bad.dxf").exists()
    assert set(ROLES) == set(PRESETS["patterns"])


def test_astm_takes_no_layer_map(cup, tmp_path):
    with pytest.raises(InputError, match="no layer_map"):
        patterns.write(cup, tmp_path / "a.dxf", profile="astm", layer_map="updown")


# --------------------------------------------------------------------------- #
# SVG: 1:1 in mm, the laser colours, read by Inkscape at true size
# --------------------------------------------------------------------------- #


def _inkscape_pdf(svg, tmp_path):
    from .test_dxf_pattern import _installed_by_ci

    if shutil.which("inkscape") is None:
        if "inkscape" in _installed_by_ci():
            pytest.fail("inkscape is missing although .ci/run installed it")
        pytest.skip("inkscape is not installed (.ci/run installs it with apt-get)")
    pdf = tmp_path / (svg.stem + ".pdf")
    proc = subprocess.run(["inkscape", str(svg), "--export-type=pdf", f"--export-filename={pdf}"],
                          capture_output=True, text=True, timeout=120, env={"HOME": str(tmp_path), "PATH": "/usr/bin"},
                          check=False)
    assert proc.returncode == 0 and pdf.exists(), proc.stderr[-2000:]
    return pdf


@pytest.mark.parametrize("what", ["cup", "bracket"])
def test_inkscape_reads_the_svg_at_true_size(cup, bracket, tmp_path, what):
    """Inkscape prints the SVG to PDF: its red (cut) paths close into the pieces' cut areas within 0.1 %,
    its blue ones are the marks; a blank's hole stays a circle of its radius."""
    from .readers.pdf_paths import segments

    source = cup if what == "cup" else bracket
    svg = tmp_path / f"{what}.svg"
    options = {"seam_allowance": 10.0} if what == "cup" else {}
    patterns.write(source, svg, **options)
    drawn = segments(_inkscape_pdf(svg, tmp_path))
    red = drawn[(1.0, 0.0, 0.0)]
    rings = sorted(g.area for g in shapely.polygonize([shapely.LineString(s) for s in red]).geoms)
    pieces = patterns.pieces_of(source, **options)
    expected = sorted([p.area for p in pieces] + [h.area for p in pieces for h in p.holes])
    assert rings == pytest.approx(expected, rel=1e-3)
    assert (0.0, 0.0, 1.0) in drawn  # score: sew lines and notches, or the bend line


def test_the_svg_is_one_millimetre_per_unit_and_says_what_is_cut(bracket, tmp_path):
    import xml.etree.ElementTree as ET

    path = tmp_path / "b.svg"
    patterns.write(bracket, path)
    root = ET.parse(path).getroot()
    svg = "{http://www.w3.org/2000/svg}"
    w, h = float(root.get("width").removesuffix("mm")), float(root.get("height").removesuffix("mm"))
    assert root.get("viewBox") == f"0 0 {w:.4f} {h:.4f}"
    (piece,) = patterns.pieces_of(bracket)
    # the page is the drawing and its margin: the blank 5 mm from the left and bottom edges, 5 from the others
    assert (w, h) == pytest.approx((bracket.size[0] + 10.0, bracket.size[1] + 10.0), abs=1e-3)
    groups = {g.get("id"): g for g in root.iter(f"{svg}g")}
    assert groups["cut"].get("stroke") == "#FF0000" and groups["score"].get("stroke") == "#0000FF"
    assert groups["engrave"].get("fill") == "#000000"
    cut = list(groups["cut"].iter(f"{svg}path"))
    assert len(cut) == 2 and " A " in cut[1].get("d")  # the hole: true arcs
    assert [p.get("stroke-dasharray") for p in groups["score"].iter(f"{svg}path")] == ["3 2"]  # the bend, dashed
    assert {t.text for t in groups["engrave"].iter(f"{svg}text")} >= {"bracket", "UP 90.0 DEG R3"}
    assert piece.title[0] in {t.text for t in groups["engrave"].iter(f"{svg}text")}


# --------------------------------------------------------------------------- #
# One frame: the DXF, the SVG and the JSON report of one drawing agree
# --------------------------------------------------------------------------- #


def test_the_report_the_dxf_and_the_svg_share_every_coordinate(bracket, tmp_path):
    """The JSON report's bend line lies on the DXF's (within 0.01 mm) and its outline is the DXF's
    outline; the blank's own bend, moved as its piece was, is the report's too."""
    patterns.write(bracket, tmp_path / "b.dxf")
    patterns.write(bracket, tmp_path / "b.json")
    doc = ezdxf.readfile(tmp_path / "b.dxf")
    (line,) = doc.modelspace().query("LINE[layer=='BEND']")
    drawn = np.array([line.dxf.start, line.dxf.end])[:, :2]
    data = json.loads((tmp_path / "b.json").read_text())
    (piece,) = data["pieces"]
    (bend,) = piece["bends"]
    assert np.abs(np.array(bend["line"]) - drawn).max() < 0.01
    (blank,) = data["blanks"]
    assert np.abs(np.array(blank["bends"][0]["line"]) - drawn).max() < 0.01
    (outline,) = doc.modelspace().query("LWPOLYLINE[layer=='CUT']")
    assert np.abs(np.array(outline.get_points("xy")) - np.array(piece["outline"])[:, :2]).max() < 1e-4
    assert data["frame"]["units"] == "mm" and data["ok"] and data["schema"] == "patterns.report/5"


def test_a_blank_that_cannot_be_cut_is_written_by_no_profile_but_the_report(tmp_path):
    from .test_unfold import bent_strip

    strip = bent_strip(la=30, lb=60, width=20, r=2, t=1.5)
    frame = bd.Pos(20, 10, -0.75) * bd.Box(160, 80, 1.5) - bd.Pos(12, 10, -0.75) * bd.Box(24, 30, 1.5)
    blank = patterns.unfold(strip + frame)
    report = patterns.check(blank)
    assert not report.ok and [f.code for f in report.errors] == [patterns.Code.FLANGES_OVERLAP]
    for suffix in (".dxf", ".svg"):
        with pytest.raises(ExportError, match="not written: .*overlap"):
            patterns.write(blank, tmp_path / f"x{suffix}")
    patterns.write(blank, tmp_path / "x.json")
    data = json.loads((tmp_path / "x.json").read_text())
    assert not data["ok"] and data["findings"][0]["code"] == "flanges-overlap"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["x.json"]


def test_the_report_gives_each_label_where_the_dxf_draws_it(cup, tmp_path):
    patterns.write(cup, tmp_path / "c.dxf")
    patterns.write(cup, tmp_path / "c.json")
    texts = [(t.dxf.text, np.array(t.dxf.align_point)[:2]) for t in ezdxf.readfile(tmp_path / "c.dxf").modelspace().query("TEXT")]
    data = json.loads((tmp_path / "c.json").read_text())
    reported = [(label["text"], np.array(label["at"])) for p in data["pieces"] for label in p["labels"]]
    assert len(reported) == len(texts) > 8
    for text, at in reported:  # each at a text of the DXF saying the same, within the report's 0.1 um
        assert min(np.abs(a - at).max() for t, a in texts if t == text) < 1e-4
