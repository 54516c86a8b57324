"""Issue 53, what a new user trips on: each against an independent reference (the geometry by hand, the file
read back, Python's own exception classes)."""

from __future__ import annotations

import math
import subprocess
import sys

import ezdxf
import numpy as np
import pytest
import shapely

import patterns
from patterns.errors import InputError

from .conftest import SAMPLES


def _gore(tip_deg: float, length: float = 200.0):
    """A flat triangle with a ``tip_deg`` tip at the origin, as one panel (a fan of small triangles)."""
    from patterns.reading import mesh_model

    half = math.radians(tip_deg) / 2
    a = np.array([length * math.cos(half), -length * math.sin(half), 0.0])
    b = np.array([length * math.cos(half), length * math.sin(half), 0.0])
    rows = 8
    pts, index = [], {}
    for i in range(rows + 1):
        for j in range(i + 1):
            u, v = i / rows, (j / i if i else 0.0)
            index[i, j] = len(pts)
            pts.append(u * ((1 - v) * a + v * b))
    faces = []
    for i in range(rows):
        for j in range(i + 1):
            faces.append((index[i, j], index[i + 1, j], index[i + 1, j + 1]))
            if j < i:
                faces.append((index[i, j], index[i + 1, j + 1], index[i, j + 1]))
    return patterns.flatten(mesh_model(np.array(pts), np.array(faces), name="gore"))


def _cut_and_seam(path):
    msp = ezdxf.readfile(path).modelspace()

    def polygon(layer):
        (e,) = msp.query(f"LWPOLYLINE[layer=='{layer}']")
        return shapely.Polygon([p[:2] for p in e.get_points("xy")])

    return polygon("CUT"), polygon("SEW")


@pytest.mark.parametrize(("corners", "limit"), [("mitre", 2.0), ("mitre", 10.0), ("mitre", 3.0), ("bevel", 2.0)])
def test_the_seam_allowance_at_a_gore_tip_stops_where_the_corner_limit_says(tmp_path, corners, limit):
    """A 20 degree tip with a 10 mm allowance, read back from the DXF (CUT and SEW): the cut line keeps the
    allowance everywhere (nowhere nearer the seam line than 10 mm) and reaches at most ``limit`` allowances
    out; unlimited (10 > 1 / sin 10 degrees = 5.76) the mitre's point lies exactly 10 / sin(10 degrees) =
    57.6 mm from the tip, by hand; limited (or bevelled: limited at one allowance), the cut square to the tip's
    bisector ``limit`` allowances out, its ends where the offset lines cross it."""
    pattern = _gore(20.0)
    out = tmp_path / "gore.dxf"
    patterns.write(pattern, out, seam_allowance=10.0, seam_corners=corners, mitre_limit=limit)
    cut, sew = _cut_and_seam(out)
    assert cut.exterior.distance(sew) == pytest.approx(10.0, abs=1e-6)  # the allowance holds, nowhere less
    reach = shapely.hausdorff_distance(cut.exterior, sew.exterior)
    half = math.radians(10.0)
    tip = 10.0 / math.sin(half)  # the mitre's point, from the tip
    cut_at = 10.0 * (1.0 if corners == "bevel" else limit)  # the cut square to the bisector, this far out
    if cut_at >= tip:
        assert reach == pytest.approx(tip, abs=1e-3)  # the full mitre, as drawn by hand
    else:  # the cut's ends, on the offset lines: sqrt(L^2 + ((m - L) tan(half))^2) from the tip
        assert reach == pytest.approx(math.hypot(cut_at, (tip - cut_at) * math.tan(half)), abs=1e-3)


def test_the_corner_limit_is_an_option_of_the_command_line(tmp_path, capsys):
    from patterns.cli import main

    assert main(["flatten", str(SAMPLES / "cup.step"), "-o", str(tmp_path / "c.dxf"), "--seam-allowance", "10",
                 "--mitre-limit", "0.5"]) == 2
    assert "--mitre-limit must be a number between 1 and 10, got 0.5" in capsys.readouterr().err
    assert not (tmp_path / "c.dxf").exists()


def test_gores_without_a_strain_limit_are_refused_in_one_line(tmp_path, capsys):
    from patterns.cli import main

    with pytest.raises(InputError, match="gores cuts a panel into gores where its strain is above max_strain"):
        patterns.flatten(patterns.load(SAMPLES / "cup.step"), gores=True)
    assert main(["flatten", str(SAMPLES / "cup.step"), "-o", str(tmp_path / "c.dxf"), "--gores"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--gores cuts a panel into gores where its strain is above --dart-strain" in err
    assert not (tmp_path / "c.dxf").exists()


def test_a_missing_file_is_a_file_not_found_error_too(tmp_path):
    """As ezdxf's errors are builtins too: ``except FileNotFoundError`` catches it, and it is still the
    patterns error (and ValueError) it was."""
    for call in (lambda: patterns.load(tmp_path / "nope.step"), lambda: patterns.load(tmp_path / "nope.stl"),
                 lambda: patterns.unfold(tmp_path / "nope.step"),
                 lambda: patterns.read_flat_pattern(tmp_path / "nope.dxf")):
        with pytest.raises(FileNotFoundError, match="nope.* no such file") as caught:
            call()
        assert isinstance(caught.value, patterns.MissingFileError)
        assert isinstance(caught.value, patterns.InputError) and isinstance(caught.value, ValueError)


def test_a_heat_map_of_a_blank_says_why_not(tmp_path):
    blank = patterns.unfold(SAMPLES / "bracket.step")
    with pytest.raises(InputError, match="a heat map draws a flattened pattern's strain, not a Blank; a blank is "
                                         "unfolded exactly"):
        patterns.heat_map(blank, tmp_path / "b.png")
    assert not (tmp_path / "b.png").exists()


def test_version_and_a_mistyped_command_answer_without_the_engine():
    """``--version`` and a mistyped command are answered before numpy, scipy, shapely or OpenCascade are
    imported (counted in the process itself: sys.modules), with "did you mean" for the command."""
    probe = ("import sys\nfrom patterns.cli import main\ncode = main({argv!r})\n"
             "print('HEAVY', sorted(m for m in ('numpy', 'scipy', 'shapely', 'OCP', 'build123d') if m in sys.modules))\n"
             "sys.exit(code)")
    done = subprocess.run([sys.executable, "-c", probe.format(argv=["--version"])], capture_output=True, text=True)
    assert done.returncode == 0 and done.stdout.startswith(f"patterns {patterns.__version__}\n"), done
    assert "HEAVY []" in done.stdout
    done = subprocess.run([sys.executable, "-c", probe.format(argv=["unfol", "part.step"])], capture_output=True,
                          text=True)
    assert done.returncode == 2 and "HEAVY []" in done.stdout
    assert done.stderr.strip() == ("patterns: error: unknown command 'unfol' (did you mean unfold?); the commands "
                                   "are flatten, check, info, demo, unfold, batch, serve, freecad, blender")


def _cap(tmp_path, scale: float, name: str):
    """A spherical cap of radius 5 (times ``scale``), as an STL of those numbers."""
    import trimesh

    mesh = trimesh.creation.icosphere(subdivisions=2, radius=5.0).slice_plane([0, 0, 0], [0, 0, 1])
    mesh.apply_scale(scale)
    path = tmp_path / name
    mesh.export(path)
    return path, float(mesh.area)


def test_a_mesh_s_unit_and_the_drawing_s_are_two_flags(tmp_path, capsys):
    """``--input-units cm`` reads the mesh's numbers as cm (its 3D area x 100 in mm2, against trimesh's own area
    of the file's numbers); ``--units`` is the drawing's alone (the DXF's INSUNITS); given alone on a mesh it
    keeps 0.2.0's meaning with a note until 0.3.0."""
    from patterns.cli import main

    path, area = _cap(tmp_path, 1.0, "cap.stl")
    assert main(["flatten", str(path), "-o", str(tmp_path / "a.dxf"), "--input-units", "cm", "--report",
                 str(tmp_path / "a.json")]) == 0
    import json

    report = json.loads((tmp_path / "a.json").read_text())
    assert sum(p["area_3d"] for p in report["panels"]) == pytest.approx(100.0 * area, rel=1e-6)
    assert ezdxf.readfile(tmp_path / "a.dxf").header["$INSUNITS"] == 4  # the drawing stays in mm
    capsys.readouterr()
    assert main(["flatten", str(path), "-o", str(tmp_path / "b.dxf"), "--units", "cm", "--report",
                 str(tmp_path / "b.json")]) == 0
    err = capsys.readouterr().err
    assert "note: --units is the drawing's unit; a mesh's own is --input-units" in err
    report = json.loads((tmp_path / "b.json").read_text())
    assert sum(p["area_3d"] for p in report["panels"]) == pytest.approx(100.0 * area, rel=1e-6)
    assert ezdxf.readfile(tmp_path / "b.dxf").header["$INSUNITS"] == 5
    helped = subprocess.run([sys.executable, "-m", "patterns", "flatten", "--help"], capture_output=True,
                            text=True).stdout
    assert "--input-units" in helped and "a mesh file's own unit is --input-units" in " ".join(helped.split())


def test_a_part_under_a_millimetre_gets_a_note_naming_the_unit(tmp_path):
    """A cap modelled in metres (0.1 m across) read as mm is 0.1 mm across: a note names metres, the size it
    would have (by hand: the file's extent x 1000) and the option; the same cap in mm has none."""
    path, _ = _cap(tmp_path, 0.01, "cap_m.stl")
    pattern = patterns.flatten(patterns.load(path))
    (note,) = [f for f in patterns.check(pattern).findings if f.code is patterns.Code.TINY_PART]
    size = max(float(np.ptp(p.uv, axis=0).max()) for p in pattern.panels)
    assert note.severity is patterns.Severity.NOTE and "was it modelled in m?" in note.message
    assert f"read in m it is {size * 1000:.3g} mm" in note.message and "--input-units m" in note.message
    big = patterns.flatten(patterns.load(path, units="m"))
    assert not [f for f in patterns.check(big).findings if f.code is patterns.Code.TINY_PART]


def test_a_layout_and_a_blank_print_in_one_line():
    """Short reprs, the data in to_dict: the blank's size from Blank.size, the layout's summary its str."""
    blank = patterns.unfold(SAMPLES / "bracket.step")
    w, h = blank.size
    assert repr(blank) == f"Blank('bracket', {w:.1f} x {h:.1f} mm, 2 mm thick, 1 bend, 1 hole, ok)"
    nest = patterns.layout(blank, sheet=(400.0, 300.0), copies=3, time_limit=1, cache=False)
    assert repr(nest) == f"Layout('bracket', 3 pieces, {nest})" and "\n" not in repr(nest)
    data = nest.to_dict()
    assert [p["name"] for p in data["pieces"]] == [p.name for p in nest.pieces]
    assert data["sheets"][0]["size_mm"] == [400.0, 300.0] and data["efficiency"] == round(nest.efficiency, 6)
    turned = [p for p in nest.pieces]
    for row, piece in zip(data["pieces"], turned):
        assert row["angle_deg"] == pytest.approx(math.degrees(piece.placement.angle), abs=1e-6)


# --------------------------------------------------------------------------- #
# The planted-bug audit's escapes: each now caught against an independent reference
# --------------------------------------------------------------------------- #

@pytest.fixture(scope="module")
def z_blank(tmp_path_factory):
    """The Z bracket of docs/sheet-metal.md: one bend down, one up (2 mm, inside radius 3, 40 mm wide)."""
    import build123d as bd

    with bd.BuildLine() as line:
        bd.FilletPolyline((-40, 0), (0, 0), (0, 30), (60, 30), radius=4)
    path = line.wire()
    plane = bd.Plane(origin=path.position_at(0), x_dir=(0, 0, 1), z_dir=path.tangent_at(0))
    step = tmp_path_factory.mktemp("z") / "z.step"
    bd.export_step(bd.sweep(plane * bd.Rectangle(40, 2), path=path, transition=bd.Transition.RIGHT), str(step))
    blank = patterns.unfold(step, k_factor=0.3)
    assert sorted(b.direction for b in blank.bends) == ["down", "up"]
    return blank


@pytest.mark.parametrize("what", ["z blank", "bracket blank", "cup"])
def test_no_two_labels_of_a_piece_overlap(z_blank, what):
    """Every two placed labels of a piece -- the title's lines, the seam and bend labels -- have disjoint text
    boxes (labels.py once tested each new label against all but the first box: "UP 90.0 DEG R3" landed on
    the part's name), and every label lies on its piece."""
    from patterns.pieces.labels import text_box

    source = {"z blank": lambda: z_blank, "bracket blank": lambda: patterns.unfold(SAMPLES / "bracket.step"),
              "cup": lambda: patterns.flatten(patterns.load(SAMPLES / "cup.step"))}[what]()
    for piece in patterns.pieces_of(source):
        placed = piece.labels.placed
        assert len(placed) >= 2
        boxes = [text_box(lb.text, lb.at, lb.height, lb.angle) for lb in placed]
        for i in range(len(boxes)):
            assert shapely.Polygon(piece.outline.points()).contains(boxes[i]), placed[i].text
            for j in range(i):
                assert not boxes[i].intersects(boxes[j]), (placed[i].text, placed[j].text)


@pytest.mark.parametrize(("direction", "angle"), [((1, 0), 0.0), ((0, 1), 90.0), ((-1, 0), 0.0), ((0, -1), 90.0),
                                                  ((1, 1), 45.0), ((-1, 1), -45.0)])
def test_text_along_any_axis_reads_left_to_right_or_bottom_to_top(direction, angle):
    """By hand: along +x or -x a text is level; along +y or -y it reads upwards (90, never -90)."""
    from patterns.pieces.labels import readable_angle

    assert readable_angle(np.array(direction, dtype=float)) == pytest.approx(angle, abs=1e-12)


def test_bend_lines_are_dashed_in_every_preset(tmp_path, z_blank):
    """Each preset's DXF read back: every bend line, up and down, on a layer whose linetype (or its own) has a
    gap between dashes (helpers.is_dashed: a group-49 element below zero)."""
    from patterns.export.layers import PRESETS

    from .helpers import is_dashed

    for preset in PRESETS:
        out = tmp_path / f"{preset}.dxf"
        patterns.write(z_blank, out, layer_map=preset)
        doc = ezdxf.readfile(out)
        lines = [e for e in doc.modelspace().query("LINE")
                 if "BEND" in e.dxf.layer.upper()]
        assert len(lines) == 2, (preset, [e.dxf.layer for e in doc.modelspace().query("LINE")])
        for line in lines:
            own = line.dxf.get("linetype", "BYLAYER")
            linetype = doc.layers.get(line.dxf.layer).dxf.linetype if own.upper() == "BYLAYER" else own
            assert is_dashed(doc, linetype), (preset, line.dxf.layer, linetype)


def _svg_path_area(d: str) -> float:
    """The area inside an SVG path of M, L, A, Z commands (absolute), its arcs sampled from the endpoint form
    (SVG 1.1, appendix F.6.5): a parser of our own, not the writer's code."""
    import re

    tokens = re.findall(r"[MLAZ]|-?\d+(?:\.\d+)?(?:e-?\d+)?", d)
    pts, k, cmd = [], 0, None
    while k < len(tokens):
        if tokens[k] in "MLAZ":
            cmd = tokens[k]
            k += 1
            if cmd == "Z":
                continue
        if cmd in "ML":
            pts.append((float(tokens[k]), float(tokens[k + 1])))
            k += 2
        elif cmd == "A":
            rx, ry, _, large, sweep, x, y = (float(t) for t in tokens[k:k + 7])
            k += 7
            (x1, y1), r = pts[-1], rx
            mx, my = (x1 - x) / 2, (y1 - y) / 2
            half = math.hypot(mx, my)
            r = max(r, half)
            h = math.sqrt(max(r * r - half * half, 0.0))
            sign = -1.0 if large == sweep else 1.0
            cx = (x1 + x) / 2 + sign * h * my / max(half, 1e-300)
            cy = (y1 + y) / 2 - sign * h * mx / max(half, 1e-300)
            a0, a1 = math.atan2(y1 - cy, x1 - cx), math.atan2(y - cy, x - cx)
            turn = a1 - a0
            if sweep and turn < 0:
                turn += 2 * math.pi
            if not sweep and turn > 0:
                turn -= 2 * math.pi
            for t in np.linspace(0, 1, 64)[1:]:
                pts.append((cx + r * math.cos(a0 + t * turn), cy + r * math.sin(a0 + t * turn)))
    return shapely.Polygon(pts).area


def test_a_filleted_piece_s_svg_path_encloses_the_piece_s_area(tmp_path):
    """A 100 x 60 mm plate with 10 mm fillets and no hole: the SVG's cut path, parsed and its arcs sampled by the
    test's own reader, encloses 100 x 60 - (4 - pi) 10^2 mm2 (by hand), as the blank's area; a flipped sweep
    flag would notch the corners (an area smaller by 2 pi 10^2)."""
    import build123d as bd
    import xml.etree.ElementTree as ET

    plate = bd.fillet(bd.Box(100, 60, 2).edges().filter_by(bd.Axis.Z), radius=10)
    step = tmp_path / "plate.step"
    bd.export_step(plate, str(step))
    blank = patterns.unfold(step)
    expected = 100 * 60 - (4 - math.pi) * 100
    assert blank.area == pytest.approx(expected, abs=0.05)
    patterns.write(blank, tmp_path / "plate.svg")
    svg = "{http://www.w3.org/2000/svg}"
    root = ET.parse(tmp_path / "plate.svg").getroot()
    cut = [g for g in root.iter(f"{svg}g") if g.get("id") == "cut"][0]
    (path,) = list(cut.iter(f"{svg}path"))
    assert " A " in f" {path.get('d')} "
    assert _svg_path_area(path.get("d")) == pytest.approx(expected, rel=2e-3)
    import svgelements as se  # a second reader (build123d's dependency): its own arc geometry

    sampled = se.Path(path.get("d")).npoint(np.linspace(0, 1, 4001))
    assert shapely.Polygon(sampled).area == pytest.approx(expected, rel=2e-3)
    # and Inkscape, as a shop opens it: the cut filled black, rendered at 10 px/mm; 1 mm in from the corner's
    # round (by hand: (9, 61) lies 8.5 mm from the fillet's centre (15, 55), within its 10 mm) is material,
    # the box's own corner (6, 64) is not
    import shutil

    if shutil.which("inkscape") is None:
        return
    filled = tmp_path / "filled.svg"
    filled.write_text((tmp_path / "plate.svg").read_text().replace('fill="none" stroke="#FF0000"',
                                                                   'fill="#000000" stroke="none"'))
    png = tmp_path / "filled.png"
    subprocess.run(["inkscape", str(filled), "--export-type=png", f"--export-filename={png}", "--export-dpi=254"],
                   capture_output=True, timeout=120, check=True)
    from PIL import Image

    image = Image.open(png).convert("RGBA")
    x0, y0 = float(root.get("viewBox").split()[0]), float(root.get("viewBox").split()[1])
    corner = np.array(shapely.Polygon(sampled).bounds[:2])  # the plate's lowest x, and its lowest y on the page
    alpha = {name: image.getpixel((int(round((corner[0] + dx - x0) * 10)), int(round((corner[1] + dy - y0) * 10))))[3]
             for name, (dx, dy) in {"round": (4.0, 4.0), "box corner": (1.0, 1.0)}.items()}
    assert alpha == {"round": 255, "box corner": 0}, alpha


def test_the_report_gives_a_turned_piece_s_angle_in_degrees(tmp_path):
    """A 100 x 30 mm plate (100 along x) on a 50 mm roll, quarter turns: it fits only turned, so the JSON's
    angle_deg is 90 or 270 (by hand: the turns that lay its 100 mm along the roll), the same as the piece's own
    turn in degrees -- never the radians (1.5708) it was once written in."""
    import json

    import build123d as bd

    plate = patterns.unfold(bd.Box(100, 30, 2), name="plate")
    assert plate.size == pytest.approx((100.0, 30.0), abs=1e-6)
    nest = patterns.layout(plate, width=50.0, copies=2, rotations="quarter", time_limit=1, cache=False)
    patterns.write(nest, tmp_path / "n.json")
    rows = [p["placement"]["angle_deg"] for p in json.loads((tmp_path / "n.json").read_text())["pieces"]]
    assert len(rows) == 2 and all(min(abs(a % 360 - 90.0), abs(a % 360 - 270.0)) < 1e-6 for a in rows), rows
    assert rows == pytest.approx([math.degrees(p.placement.angle) for p in nest.pieces], abs=1e-6)


OUTPUT_FLAGS = {  # every output flag of each command, and the file it names
    "flatten": [("-o", "p.dxf"), ("--report", "p.json"), ("--heat-map", "h.png"), ("--preview", "v.png")],
    "unfold": [("-o", "b.dxf"), ("--report", "b.json"), ("--preview", "v.png"), ("--bend-sheet", "b.csv")],
    "check": [("--report", "c.json"), ("--heat-map", "h.png")],
}


@pytest.mark.parametrize("command", sorted(OUTPUT_FLAGS))
def test_every_output_flag_of_a_command_writes_its_file(tmp_path, command):
    """One run per command with every output flag it has (its --help, parsed, names no other): each file is
    there, and each PNG is a PNG (its signature)."""
    from patterns.cli import _parser, main

    given = OUTPUT_FLAGS[command]
    parser = _parser().commands[command]
    declared = {f for a in parser._actions for f in a.option_strings
                if a.dest in ("output", "report", "heat_map", "preview", "bend_sheet")}
    assert declared == {flag for flag, _ in given} | ({"--output"} if command != "check" else set())
    part = SAMPLES / ("bracket.step" if command == "unfold" else "cup.step")
    argv = [command, str(part)] + [x for flag, name in given for x in (flag, str(tmp_path / name))]
    assert main(argv) in (0, 1)
    for _, name in given:
        path = tmp_path / name
        assert path.is_file() and path.stat().st_size > 0, name
        if name.endswith(".png"):
            assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_bent_sheet_given_to_flatten_gets_a_note_to_unfold_it():
    """The bracket (2 mm, one bend: what unfold measures) flattened: a sheet-metal note naming its thickness and
    bends, and unfold; the cup and a thick-walled tube (no planes a thickness apart) get none."""
    import build123d as bd

    blank = patterns.unfold(SAMPLES / "bracket.step")
    flat = patterns.flatten(patterns.load(SAMPLES / "bracket.step"))
    (note,) = [f for f in patterns.check(flat).findings if f.code is patterns.Code.SHEET_METAL]
    assert f"({blank.thickness:.3g} mm, {len(blank.bends)} bend)" in note.message and "patterns unfold" in note.message
    for other in (patterns.load(SAMPLES / "cup.step"), patterns.load(bd.Cylinder(50, 100) - bd.Cylinder(48, 100))):
        assert not [f for f in patterns.check(patterns.flatten(other)).findings
                    if f.code is patterns.Code.SHEET_METAL]


def test_batch_unfold_shows_each_blank_s_thickness_size_and_bends(tmp_path, capsys):
    """``batch --unfold``'s table: a blank's columns (what unfold measures of the same part), not a pattern's
    panels and strains."""
    import shutil

    from patterns.cli import main

    (tmp_path / "in").mkdir()
    shutil.copy(SAMPLES / "bracket.step", tmp_path / "in" / "bracket.step")
    assert main(["batch", str(tmp_path / "in"), "-o", str(tmp_path / "out"), "--unfold", "--jobs", "1"]) == 0
    lines = capsys.readouterr().out.splitlines()
    header = [line for line in lines if line.startswith("file ")][0]
    assert header.split() == ["file", "thickness", "mm", "size", "mm", "bends", "seconds", "status"]
    blank = patterns.unfold(SAMPLES / "bracket.step")
    w, h = blank.size
    (row,) = [line for line in lines if line.startswith("bracket.step")]
    assert row.split()[:6] == ["bracket.step", f"{blank.thickness:g}", f"{w:.1f}", "x", f"{h:.1f}",
                               str(len(blank.bends))]


def test_long_work_reports_progress_in_a_log_too(monkeypatch):
    """Off a terminal, a line per LOG_EVERY seconds with the share done (none for short work); 0 s here so that
    every call past the first counts as long."""
    import io

    from patterns import terminal

    log = io.StringIO()
    quiet = terminal.Progress("flattening", stream=log, enabled=False)
    quiet(1, 4)
    assert log.getvalue() == ""  # short work: nothing
    monkeypatch.setattr(terminal, "LOG_EVERY", 0.0)
    progress = terminal.Progress("flattening", stream=log, enabled=False)
    for done in range(5):
        progress(done, 4)
    lines = log.getvalue().splitlines()
    assert [line.split(" (")[0] for line in lines] == ["flattening: 0%", "flattening: 25%", "flattening: 50%",
                                                       "flattening: 75%"]


def test_each_finding_is_marked_on_the_heat_map_where_its_panel_is_drawn():
    """The cup in gores at 5 %: every finding with points is marked, each mark inside the outline of its panel as
    the picture draws it (its uv moved by the picture's offset), the report's points moved the same way."""
    from patterns.export.heatmap import display_offsets, finding_marks

    pattern = patterns.flatten(patterns.load(SAMPLES / "cup.step"), max_strain=0.05, gores=True)
    offsets = display_offsets(pattern)
    assert np.ptp(offsets, axis=0).max() > 0  # the panels are moved apart in the picture
    findings = [f for f in patterns.check(pattern).findings if len(f.points)]
    marks = finding_marks(pattern, offsets)
    assert len(marks) == len(findings) > 0
    names = [p.name for p in pattern.panels]
    for (code, at), f in zip(marks, findings):
        k = names.index(f.panels[0])
        flat = pattern.panels[k]
        drawn = shapely.Polygon(flat.uv[flat.loops[0]] + offsets[k]).buffer(1e-6)
        assert code == f.code.value and all(drawn.contains(shapely.Point(p)) for p in at)
        np.testing.assert_allclose(at, np.asarray(f.points) + offsets[k])


def test_a_command_s_help_and_a_mistyped_flag_answer_without_the_engine():
    """``patterns flatten --help`` prints what the full parser prints (at 80 columns), and a mistyped flag gets
    the closest one, both before numpy, scipy, shapely or OpenCascade are imported; the index they come from is
    the parser's own (python -m patterns.cli writes it anew)."""
    import json

    from patterns.cli import COMMAND_INDEX, command_index

    assert json.loads(COMMAND_INDEX.read_text(encoding="utf-8")) == command_index()
    probe = ("import sys\nfrom patterns.cli import main\ncode = main({argv!r})\n"
             "print('HEAVY', sorted(m for m in ('numpy', 'scipy', 'shapely', 'OCP', 'build123d') if m in sys.modules))\n"
             "sys.exit(code)")
    done = subprocess.run([sys.executable, "-c", probe.format(argv=["flatten", "--help"])], capture_output=True,
                          text=True, env={**__import__("os").environ, "COLUMNS": "80"})
    assert done.returncode == 0 and done.stdout.endswith("HEAVY []\n")
    assert done.stdout[:-len("HEAVY []\n")] == command_index()["flatten"]["help"]
    done = subprocess.run([sys.executable, "-c", probe.format(argv=["flatten", "p.step", "-o", "p.dxf",
                                                                    "--seam-alowance", "5"])],
                          capture_output=True, text=True)
    assert done.returncode == 2 and "HEAVY []" in done.stdout
    assert done.stderr.strip() == ("patterns: error: unknown option --seam-alowance; did you mean --seam-allowance? "
                                   "(patterns flatten --help lists the options)")


def test_batch_units_keeps_0_2_0_s_meaning_with_a_warning(tmp_path):
    """``batch(folder, out, units="cm")`` on a mesh: as 0.2.0, the mesh read in cm too (its report's 3D area
    100 x trimesh's area of the file's numbers), with a DeprecationWarning naming input_units."""
    import json

    path, area = _cap(tmp_path, 1.0, "cap.stl")
    (tmp_path / "in").mkdir()
    path.rename(tmp_path / "in" / "cap.stl")
    with pytest.warns(DeprecationWarning, match="batch\\(units=\\) sets units and input_units"):
        result = patterns.batch(tmp_path / "in", tmp_path / "out", units="cm", jobs=1)
    assert [r.status for r in result.rows] == ["ok"]
    report = json.loads((tmp_path / "out" / "cap.json").read_text())
    assert sum(p["area_3d"] for p in report["panels"]) == pytest.approx(100.0 * area, rel=1e-6)
