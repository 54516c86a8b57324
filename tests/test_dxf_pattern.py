"""Pattern DXF files for cutters: machine and ASTM profiles, read back by ezdxf and by
real readers (LibreCAD, dxf2gcode, FreeCAD) where they are installed."""

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
import shapely.affinity
import trimesh
from ezdxf import recover

import patterns
from patterns.errors import ExportError, InputError
from patterns.export.layers import PRESETS
from patterns.export.preview import preview_dxf

MACHINE_LAYERS = {layer.name for layer in PRESETS["patterns"].values()}
"""The layers of the machine profile's default layer map."""

from .conftest import SAMPLES
from .helpers import drawing_shift, small_disk

READERS = Path(__file__).parent / "readers"


@pytest.fixture(scope="module")
def cup():
    return patterns.flatten(patterns.load(SAMPLES / "cup.step"))


@pytest.fixture(scope="module")
def plate():
    """A box with a through hole: planar panels with holes, a cylindrical wall."""
    import build123d as bd

    return patterns.flatten(patterns.load(bd.Box(200, 100, 50) - bd.Cylinder(20, 50), max_edge=10))


def read(path):
    doc, auditor = recover.readfile(str(path))
    assert not auditor.has_errors, [str(e) for e in auditor.errors]
    return doc


def polylines(doc, layer):
    out = []
    for e in doc.modelspace().query(f'LWPOLYLINE POLYLINE[layer=="{layer}"]'):
        if e.dxftype() == "LWPOLYLINE":
            pts, closed = np.array([p[:2] for p in e.get_points("xy")]), e.closed
        else:
            pts, closed = np.array([tuple(v.dxf.location)[:2] for v in e.vertices]), e.is_closed
        out.append((pts, closed))
    return out


def ring_numbers(pts):
    ring = shapely.Polygon(pts)
    return abs(ring.area), ring.exterior.length


@pytest.mark.parametrize("version", ["R12", "R2000", "R2018"])
def test_machine_cut_contours_are_the_flat_outlines(plate, tmp_path, version):
    path = tmp_path / "plate.dxf"
    patterns.write(plate, path, version=version)
    doc = read(path)
    assert doc.dxfversion == ezdxf.const.acad_release_to_dxf_version[version]
    cuts = polylines(doc, "CUT")
    loops = [loop for flat in plate.panels for loop in flat.loops]
    assert len(cuts) == len(loops) and all(closed for _, closed in cuts)
    # Every flat loop appears once, with its area and perimeter, within 1e-6 (relative).
    expected = sorted(ring_numbers(flat.uv[loop]) for flat in plate.panels for loop in flat.loops)
    found = sorted(ring_numbers(pts) for pts, _ in cuts)
    np.testing.assert_allclose(found, expected, rtol=1e-6)
    # z = 0 everywhere, 1:1, units declared, text never on CUT, layers as documented.
    for e in doc.modelspace():
        assert e.dxf.layer in MACHINE_LAYERS
        if e.dxftype() in ("TEXT", "MTEXT"):
            assert e.dxf.layer == "LABEL"
        if e.dxftype() == "LINE":
            assert e.dxf.start.z == 0 and e.dxf.end.z == 0
        if e.dxftype() == "POLYLINE":
            assert all(v.dxf.location.z == 0 for v in e.vertices)
    if version != "R12":
        assert doc.header["$INSUNITS"] == 4
    else:
        assert any(t.dxf.text == "UNITS: MM" for t in doc.modelspace().query("TEXT"))
    # No two cut contours are the same (nothing gets cut twice), no panels overlap.
    polys = [shapely.Polygon(p) for p, _ in cuts]
    outers = [p for p in polys if not any(q.contains(p) for q in polys if q is not p)]
    for i, a in enumerate(outers):
        for b in outers[i + 1:]:
            assert a.intersection(b).area < 1e-9


def test_seam_annotations_equal_the_report(cup, tmp_path):
    path = tmp_path / "cup.dxf"
    patterns.write(cup, path)
    report = patterns.check(cup)
    texts = [t.dxf.text for t in read(path).modelspace().query('TEXT[layer=="LABEL"]')]
    seams = [re.fullmatch(r"S(\d+) 3D ([\d.]+) FLAT ([\d.]+) MM", t) for t in texts]
    seams = [m for m in seams if m]
    assert len(seams) == 2 * len(report.seams)  # each seam labelled on both sides
    for m in seams:
        numbers = report.seams[int(m.group(1))]
        assert float(m.group(2)) == round(numbers.length_3d, 2)
        assert float(m.group(3)) in {round(x, 2) for x in numbers.length_flat}
    for panel in report.panels:
        assert panel.name in texts
        assert f"STRAIN RMS {100 * panel.strain_rms:.2f}% MAX {100 * panel.strain_max:.2f}%" in texts


def test_seam_allowance_offsets_the_cut_line_and_keeps_the_seam_line(cup, tmp_path):
    path = tmp_path / "cup.dxf"
    patterns.write(cup, path, seam_allowance=10.0)
    doc = read(path)
    sews, cuts = polylines(doc, "SEW"), polylines(doc, "CUT")
    assert len(cuts) == len(sews) == 4
    for sew, _ in sews:  # each seam line with the cut line around it
        (cut, closed), = [(c, k) for c, k in cuts if shapely.Polygon(c).contains(shapely.Polygon(sew).centroid)]
        assert closed
        seam_line, cut_line = shapely.Polygon(sew), shapely.Polygon(cut)
        assert cut_line.contains(seam_line)
        # Every point of the seam line is 10 mm inside the cut line (mitred corners
        # are farther only at the corners).
        d = shapely.distance(shapely.points(sew), cut_line.exterior)
        assert np.median(d) == pytest.approx(10.0, abs=1e-4) and d.min() > 10.0 - 1e-4
    # Per seam: 15 mm on seam 0, 5 mm elsewhere.
    path2 = tmp_path / "cup2.dxf"
    patterns.write(cup, path2, seam_allowance={0: 15.0, None: 5.0})
    doc2 = read(path2)
    seam0 = cup.seams[0].seam
    panel = seam0.panels[0]
    offset = np.array(_placed_offset(doc2, cup, panel))
    on_seam = cup.panels[panel].uv[seam0.vertices[0]][3:-3] + offset
    cut_line = max((shapely.Polygon(p) for p, _ in polylines(doc2, "CUT")),
                   key=lambda poly: -poly.distance(shapely.Point(on_seam[len(on_seam) // 2])))
    d = shapely.distance(shapely.points(on_seam), cut_line.exterior)
    np.testing.assert_allclose(d, 15.0, atol=1e-4)


def _placed_offset(doc, pattern, panel):
    """Where the writer put a panel: the SEW loop with the panel's area and shape, minus its flat position."""
    flat = pattern.panels[panel]
    loop = flat.uv[flat.loops[0]]
    for pts, _ in polylines(doc, "SEW"):
        if len(pts) == len(loop) and np.allclose(np.diff(pts, axis=0), np.diff(loop, axis=0), atol=1e-6):
            return pts[0] - loop[0]
    raise AssertionError("panel not found")


def test_notches_mark_both_ends_of_every_seam(cup, tmp_path):
    path = tmp_path / "cup.dxf"
    patterns.write(cup, path, seam_allowance=8.0)
    notches = read(path).modelspace().query('LINE[layer=="NOTCH"]')
    assert len(notches) == 2 * 2 * len(cup.seams)
    for line in notches:
        assert line.dxf.start.distance(line.dxf.end) == pytest.approx(8.0)


def test_astm_profile_is_piece_blocks_for_garment_cad(cup, tmp_path):
    path = tmp_path / "cup_astm.dxf"
    patterns.write(cup, path, profile="astm", seam_allowance=10.0)
    text = path.read_text(encoding="ascii")
    # What Gerber's parser wants: no handles, no layout blocks; a header with only the units.
    assert "$MODEL_SPACE" not in text.upper() and "$PAPER_SPACE" not in text.upper()
    doc = read(path)
    assert doc.dxfversion == "AC1009"
    inserts = doc.modelspace().query("INSERT")
    assert len(inserts) == 4
    # The style's text in model space, the standard's version line first; every layer used declared.
    style = [t.dxf.text for t in doc.modelspace().query("TEXT")]
    assert style[0] == "ASTM/D6673/10" and style[1:2] == [f"Style Name:{cup.name}"]
    assert re.fullmatch(r"Creation Date:\d\d-\d\d-\d{4}", style[2])
    assert style[3:] == ["Author:patterns", "Sample Size:BASE", "Grading Rule Table:", "Units:METRIC"]
    assert {t.dxf.layer for t in doc.modelspace().query("TEXT")} == {"1"}  # the style's text: layer 1
    used = {e.dxf.layer for e in doc.modelspace()} | {e.dxf.layer for b in doc.blocks if not b.is_any_layout for e in b}
    assert used <= {layer.dxf.name for layer in doc.layers}
    for insert, flat in zip(inserts, cup.panels):
        assert insert.dxf.layer == "1" and insert.dxf.name == flat.name
        block = doc.blocks[insert.dxf.name]
        layers = {e.dxf.layer for e in block}
        assert {"1", "2", "3", "4", "7", "14"} <= layers
        (cut,) = [e for e in block.query("POLYLINE") if e.dxf.layer == "1"]
        (sew,) = [e for e in block.query("POLYLINE") if e.dxf.layer == "14"]
        assert cut.is_closed and sew.is_closed
        sew_pts = np.array([tuple(v.dxf.location)[:2] for v in sew.vertices])
        assert ring_numbers(sew_pts) == pytest.approx(ring_numbers(flat.uv[flat.loops[0]]), rel=1e-6)
        piece = {t.dxf.text for t in block.query("TEXT") if t.dxf.layer == "1"}
        assert {f"Piece Name:{flat.name}", "Quantity:1", "Material:", "Units:METRIC"} <= piece
        panel = patterns.check(cup).panels[cup.panels.index(flat)]  # the report's numbers, as on the machine profile
        assert f"STRAIN RMS {100 * panel.strain_rms:.2f}% MAX {100 * panel.strain_max:.2f}%" in {
            t.dxf.text for t in block.query("TEXT")}
        notches = [e for e in block.query("POINT") if e.dxf.layer == "4"]
        assert len(notches) == 4  # two seams, two ends each
        for n in notches:
            assert n.dxf.location.z == pytest.approx(10.0)  # notch depth = the allowance
            assert n.dxf.hasattr("angle")
        assert len(block.query('LINE[layer=="7"]')) == 1  # grain line


def test_preview_is_the_file_at_one_to_one(cup, tmp_path):
    path = tmp_path / "cup.dxf"
    patterns.write(cup, path, seam_allowance=10.0)
    extents = ezdxf.bbox.extents(read(path).modelspace())
    svg = tmp_path / "cup.svg"
    preview_dxf(path, svg, margin=10.0)
    head = svg.read_text()[:400]
    width = float(re.search(r'width="([\d.]+)mm"', head).group(1))
    height = float(re.search(r'height="([\d.]+)mm"', head).group(1))
    assert width == pytest.approx(extents.size.x + 20.0, abs=0.1)
    assert height == pytest.approx(extents.size.y + 20.0, abs=0.1)
    png = tmp_path / "cup.png"
    preview_dxf(path, png, dpi=50, margin=10.0)
    import matplotlib.image

    img = matplotlib.image.imread(png)
    assert img.shape[1] == pytest.approx((extents.size.x + 20.0) / 25.4 * 50, abs=2)
    # Red cut lines and blue sew lines are drawn (the layers' colours).
    rgb = img[..., :3]
    assert np.count_nonzero((rgb[..., 0] > 0.8) & (rgb[..., 1] < 0.3)) > 100
    assert np.count_nonzero((rgb[..., 2] > 0.8) & (rgb[..., 0] < 0.3)) > 100
    # The ASTM file renders too (its layers have no table: named for the preview).
    astm = tmp_path / "astm.dxf"
    patterns.write(cup, astm, profile="astm")
    preview_dxf(astm, tmp_path / "astm.png", dpi=30)
    dark = matplotlib.image.imread(tmp_path / "astm.png")[..., :3].mean(axis=2) < 0.5
    assert np.count_nonzero(dark) > 500


def test_strain_layer(cup, tmp_path):
    path = tmp_path / "cup.dxf"
    patterns.write(cup, path, strain_layer=True, version="R2004")
    doc = read(path)
    solids = doc.modelspace().query('SOLID[layer=="STRAIN"]')
    assert len(solids) == sum(len(p.faces) for p in cup.panels)
    assert all(s.dxf.hasattr("true_color") for s in solids)
    # Each SOLID is its flat triangle (the same area), coloured on a scale symmetric about 0:
    # strain s at RdBu_r(1/2 + s / (2 max|s|)) of the panel, blue for compression, red for stretch.
    from ezdxf.colors import int2rgb
    from matplotlib import colormaps

    from patterns.measure import triangle_strains

    k = 0
    for flat in cup.panels:
        s = triangle_strains(flat.vertices, flat.faces, flat.uv).dominant
        assert s.min() < 0 < s.max()  # both kinds on the cup
        want = colormaps["RdBu_r"](0.5 + 0.5 * s / np.abs(s).max())[:, :3] * 255
        a, b, c = (flat.uv[flat.faces[:, i]] for i in range(3))
        area = 0.5 * np.abs((b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0])
        for i in range(len(flat.faces)):
            (x0, y0, _), (x1, y1, _), (x2, y2, _) = (solids[k + i].dxf.get(f"vtx{j}") for j in range(3))
            drawn = 0.5 * abs((x1 - x0) * (y2 - y0) - (y1 - y0) * (x2 - x0))
            assert drawn == pytest.approx(area[i], rel=1e-6, abs=1e-9)
            assert np.abs(np.array(int2rgb(solids[k + i].dxf.true_color)) - want[i]).max() <= 1.0
        k += len(flat.faces)


@pytest.mark.parametrize("version", ["R12", "R2000"])
def test_strain_colours_are_the_version_s(cup, tmp_path, version):
    """True colour from R2004 on; R12 and R2000 have none (ACI red or blue)."""
    path = tmp_path / "cup.dxf"
    patterns.write(cup, path, strain_layer=True, version=version)
    solids = read(path).modelspace().query('SOLID[layer=="STRAIN"]')
    assert len(solids) > 0 and not any(s.dxf.hasattr("true_color") for s in solids)
    assert {s.dxf.color for s in solids} == {1, 5}


def test_labels_read_left_to_right():
    """A label along a direction is turned to read left to right, never upside down: its angle lies in
    (-90, 90] degrees, the direction's or the opposite one's."""
    from patterns.pieces.labels import readable_angle as _readable_angle

    cases = {(1, 0): 0.0, (0, 1): 90.0, (0, -1): 90.0, (-1, 0): 0.0, (1, 1): 45.0, (-1, -1): 45.0,
             (-1, 1): -45.0, (1, -1): -45.0, (-1, 1e-9): pytest.approx(-1e-9 * 180 / np.pi, abs=1e-12)}
    for direction, angle in cases.items():
        assert _readable_angle(np.array(direction, dtype=float)) == pytest.approx(angle, abs=1e-12)


def test_grain_lines_lie_inside_their_pieces(cup, plate, tmp_path):
    for name, pattern in (("cup", cup), ("plate", plate)):
        path = tmp_path / f"{name}.dxf"
        patterns.write(pattern, path)
        doc = read(path)
        cuts = _polygons(doc, "CUT")
        lines = doc.modelspace().query('LINE[layer=="GRAIN"]')
        assert len(lines) == len(pattern.panels)
        for line in lines:
            a, b = shapely.Point(tuple(line.dxf.start)[:2]), shapely.Point(tuple(line.dxf.end)[:2])
            assert any(c.contains(a) and c.contains(b) for c in cuts), name


def test_a_text_height_given_is_the_text_height(cup, tmp_path):
    path = tmp_path / "cup.dxf"
    patterns.write(cup, path, version="R12", text_height=7.0)
    (units,) = [t for t in read(path).modelspace().query("TEXT") if t.dxf.text.startswith("UNITS:")]
    assert units.dxf.height == 7.0


def test_astm_texts_are_six_tenths_of_the_text_height(cup, tmp_path):
    """ASTM text_height=5: the style's lines in model space and every piece's text (its lines, its seam
    labels) are 3 mm high, 0.6 of it."""
    path = tmp_path / "cup.dxf"
    patterns.write(cup, path, profile="astm", text_height=5.0)
    doc = read(path)
    texts = list(doc.modelspace().query("TEXT"))
    texts += [e for ents in _block_entities(doc).values() for e in ents if e.dxftype() == "TEXT"]
    seam_labels = [t for t in texts if t.dxf.text.startswith("S") and " 3D " in t.dxf.text]
    assert len(texts) > 7 and seam_labels
    np.testing.assert_allclose([t.dxf.height for t in texts], 3.0, rtol=1e-12)


def test_marks_are_counted_before_drawing():
    """check_marks' estimates: 2 x (seam length / notch spacing + seams) notches, the panels' sizes over
    the bend spacing for bend lines; refused over MAX_MARKS, not under."""
    from patterns.pieces.options import MAX_MARKS, check_marks
    from patterns.pieces.options import PieceOptions as DxfOptions

    seams, sizes = [1000.0] * 10, [500.0] * 8  # 10 m of seams, 4 m of panels
    notch_at = 2 * (10_000.0 / MAX_MARKS)  # about MAX_MARKS / 2 ... / 1 notches below and above
    check_marks("p", seams, sizes, DxfOptions(notch_spacing=notch_at * 1.1))
    with pytest.raises(InputError, match=r"^p: notch_spacing .* would draw about"):
        check_marks("p", seams, sizes, DxfOptions(notch_spacing=notch_at * 0.9))
    bend_at = 4000.0 / MAX_MARKS
    check_marks("p", seams, sizes, DxfOptions(bend_spacing=bend_at * 1.1))
    with pytest.raises(InputError, match=r"^p: bend_spacing .* would draw up to .* bend lines across 8 panels"):
        check_marks("p", seams, sizes, DxfOptions(bend_spacing=bend_at * 0.9))
    check_marks("p", [], [], DxfOptions(notch_spacing=1e-3, bend_spacing=1e-3))  # nothing to mark


def test_snap_drops_repeated_points_and_the_closing_one():
    from patterns.pieces.allowance import snap as _snap

    square = np.array([[0, 0], [10, 0], [10, 10], [0, 10]], dtype=float)
    np.testing.assert_array_equal(_snap(np.vstack([square, square[:1]])), square)  # closed by repeating
    np.testing.assert_array_equal(_snap(np.vstack([square[:2], square[1:2] + 1e-9, square[2:]])), square)
    triangle = square[:3]
    np.testing.assert_array_equal(_snap(np.vstack([triangle, triangle[:1]])), triangle)


def test_arcs_are_for_the_cut_line_only(cup, tmp_path):
    """arcs=True: the cut contours are fitted with arcs (bulges); the seam lines are drawn as they are."""
    path = tmp_path / "cup.dxf"
    patterns.write(cup, path, arcs=True, seam_allowance=10.0)
    msp = read(path).modelspace()
    bulges = {layer: [b for e in msp.query(f'LWPOLYLINE[layer=="{layer}"]') for *_, b in e.get_points("xyb")]
              for layer in ("CUT", "SEW")}
    assert any(b != 0 for b in bulges["CUT"]) and not any(b != 0 for b in bulges["SEW"])


def test_layers_are_declared_only_when_used(cup, tmp_path):
    """STOCK (a nest's roll or sheets) and STRAIN (the strain solids) are declared only when drawn."""
    path = tmp_path / "cup.dxf"
    patterns.write(cup, path)
    layers = {layer.dxf.name for layer in read(path).layers}
    assert {"CUT", "LABEL", "NOTCH", "GRAIN"} <= layers and not {"STOCK", "STRAIN"} & layers
    patterns.write(cup, path, strain_layer=True)
    assert "STRAIN" in {layer.dxf.name for layer in read(path).layers}


def test_seam_labels_lie_inside_their_panel_near_their_seam(cup, tmp_path):
    """Each seam's label (S<id> 3D ... FLAT ...) lies inside its panel, about a label height from its
    seam: 1.6 x its own height, within the panel's own seam polyline's reach."""
    path = tmp_path / "cup.dxf"
    pattern = cup.placed([(0.0, 400.0 * k, 0.0) for k in range(len(cup.panels))])
    patterns.write(pattern, path)
    doc = read(path)
    shift = drawing_shift(doc.modelspace(), pattern, "CUT")
    labels = [t for t in doc.modelspace().query('TEXT[layer=="LABEL"]') if re.match(r"S\d+ 3D ", t.dxf.text)]
    assert len(labels) == 2 * len(pattern.seams)
    for t in labels:
        sid = int(t.dxf.text[1:].split()[0])
        (fs,) = [fs for fs in pattern.seams if fs.seam.id == sid]
        at = shapely.Point(np.array(t.dxf.align_point)[:2] - shift)
        lines = [shapely.LineString(pattern.panels[p].uv[idx]) for p, idx in zip(fs.seam.panels, fs.seam.vertices)]
        assert min(line.distance(at) for line in lines) == pytest.approx(1.6 * t.dxf.height, rel=0.05)


def test_a_per_seam_allowance_is_bounded_too(cup, tmp_path):
    with pytest.raises(InputError, match="seam_allowance"):
        patterns.write(cup, tmp_path / "cup.dxf", seam_allowance={None: 5.0, cup.seams[0].seam.id: 1e6})
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    ("kwargs", "words"),
    [
        ({"profile": "gerber"}, "profile must be one of machine, astm, svg, json, bends, got .gerber."),
        ({"units": "furlong"}, "units must be one of mm, cm, m, in"),
        ({"version": "R14"}, "version must be one of R12, R2000"),
        ({"profile": "astm", "version": "R2000"}, "R12 only"),
        ({"profile": "astm", "units": "in"}, "METRIC"),
        ({"seam_allowance": -1.0}, "seam_allowance"),
        ({"seam_allowance": {99: 5.0}}, "does not have"),
        ({"seam_allowance": "wide"}, "seam_allowance"),
    ],
)
def test_bad_options_write_nothing(cup, tmp_path, kwargs, words):
    path = tmp_path / "out.dxf"
    with pytest.raises(InputError, match=words):
        patterns.write(cup, path, **kwargs)
    assert list(tmp_path.iterdir()) == []


def test_failed_export_leaves_no_file(cup, tmp_path):
    with pytest.raises(ExportError, match="does not exist"):
        patterns.write(cup, tmp_path / "missing" / "cup.dxf")
    assert list(tmp_path.iterdir()) == []


# --------------------------------------------------------------------------- #
# Real readers (installed by .ci/run from the distribution's packages)
# --------------------------------------------------------------------------- #


PACKAGES = {"librecad": "librecad", "dxf2gcode": "dxf2gcode", "freecadcmd": "freecad", "openscad": "openscad",
            "inkscape": "inkscape"}
"""Each reader's command and the Debian package .ci/run installs it from."""


def _installed_by_ci() -> set:
    """The packages .ci/run installed (PATTERNS_READERS): their commands must be there."""
    return set(os.environ.get("PATTERNS_READERS", "").split())


def _need(tool):
    if shutil.which(tool) is None:
        if PACKAGES[tool] in _installed_by_ci():
            pytest.fail(f"{tool} is missing although .ci/run installed the {PACKAGES[tool]} package")
        pytest.skip(f"{tool} is not installed (.ci/run installs it with apt-get)")


def _qt_env(tmp_path):
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen", XDG_RUNTIME_DIR=str(tmp_path), HOME=str(tmp_path))
    return env


@pytest.mark.parametrize("version", ["R12", "R2000"])
def test_librecad_renders_the_file(plate, tmp_path, version):
    _need("librecad")
    path = tmp_path / "plate.dxf"
    patterns.write(plate, path, version=version)
    pdf = tmp_path / "plate.pdf"  # dxf2pdf writes FILE.pdf beside FILE.dxf
    # --fit: at the default 1:1 on A4 the 450 x 355 mm sheet falls off the page.
    proc = subprocess.run(["librecad", "dxf2pdf", "--fit", str(path)], capture_output=True, text=True,
                          env=_qt_env(tmp_path), timeout=120)
    assert proc.returncode == 0, proc.stderr[-2000:]
    data = pdf.read_bytes()
    content = b"".join(_inflate(s) for s in re.findall(rb"stream\r?\n(.*?)\r?\nendstream", data, re.DOTALL))
    # Drawn as vector paths: at least one line-to for every cut vertex.
    n_vertices = sum(len(loop) for flat in plate.panels for loop in flat.loops)
    assert len(re.findall(rb"\sl\s", content)) >= n_vertices


def _inflate(stream: bytes) -> bytes:
    try:
        return zlib.decompress(stream)
    except zlib.error:
        return stream


@pytest.mark.parametrize("version", ["R12", "R2000"])
def test_dxf2gcode_finds_one_closed_contour_per_cut_loop(plate, tmp_path, version):
    """Holes too: the plate's cut loops (outlines and the hole's) each one closed contour."""
    path = tmp_path / "plate.dxf"
    patterns.write(plate, path, version=version, seam_allowance=5.0)
    found = _dxf2gcode(path, tmp_path)
    n_loops = len(polylines(read(path), "CUT"))
    assert found["entities"]["CUT"]["contours"] == found["entities"]["CUT"]["closed"] == n_loops
    assert found["metric"] is True


def test_freecad_reads_the_machine_profile(plate, tmp_path):
    _need("freecadcmd")
    path = tmp_path / "plate.dxf"
    patterns.write(plate, path)
    proc = subprocess.run(["freecadcmd", str(READERS / "freecad_layers.py")], capture_output=True, text=True,
                          env=dict(_qt_env(tmp_path), DXF=str(path)), timeout=300)
    lines = [x for x in proc.stdout.splitlines() if "RESULT " in x]
    assert lines, proc.stdout[-2000:] + proc.stderr[-2000:]
    layers = json.loads(lines[-1].split("RESULT ", 1)[1])
    wires = layers["CUT"]["closed_wires"]
    expected = sorted(ring_numbers(flat.uv[loop]) for flat in plate.panels for loop in flat.loops)
    assert len(wires) == len(expected)
    found = sorted((w["area"], w["length"]) for w in wires)
    np.testing.assert_allclose(found, expected, rtol=1e-6)
    assert {"GRAIN", "NOTCH"} <= set(layers)


def test_readers_are_present_in_ci():
    """Every reader .ci/run installed (PATTERNS_READERS) answers on the PATH, named if not."""
    packages = _installed_by_ci()
    if not packages:
        pytest.skip("PATTERNS_READERS is empty (only .ci/run installs the real readers)")
    missing = [tool for tool, package in PACKAGES.items() if package in packages and shutil.which(tool) is None]
    assert not missing, f"readers installed by .ci/run but missing: {missing}"


# --------------------------------------------------------------------------- #
# Planted-bug guards: notch directions, units, true scale (issue 17, point 9)
# --------------------------------------------------------------------------- #


def _polygons(doc, layer):
    return [shapely.Polygon(pts) for pts, closed in polylines(doc, layer) if closed]


def _pieces(doc, layer):
    """The closed polylines of ``layer`` as pieces: each ring not inside another, with the rings inside
    it as its holes."""
    rings = _polygons(doc, layer)
    outer = [r for r in rings if not any(o is not r and o.contains(r) for o in rings)]
    return [shapely.Polygon(o.exterior, [r.exterior for r in rings if r is not o and o.contains(r)]) for o in outer]


def test_notch_slits_cut_into_the_allowance_never_into_the_piece(cup, tmp_path):
    """Every slit runs from the cut line in to the seam line, through the seam allowance: its
    middle lies inside the cut contour and outside every seam line (a slit flipped inwards would
    cut the finished piece)."""
    path = tmp_path / "cup.dxf"
    patterns.write(cup, path, seam_allowance=10.0)
    doc = read(path)
    cut, sew = shapely.union_all(_polygons(doc, "CUT")), shapely.union_all(_polygons(doc, "SEW"))
    lines = doc.modelspace().query('LINE[layer=="NOTCH"]')
    assert len(lines) == 2 * 2 * len(cup.seams)
    for line in lines:
        b, a = np.array(line.dxf.start)[:2], np.array(line.dxf.end)[:2]
        assert cut.boundary.distance(shapely.Point(b)) < 1e-6  # starts on the cut line
        assert sew.boundary.distance(shapely.Point(a)) < 1e-6  # ends on the seam line
        mid = shapely.Point((a + b) / 2)
        assert cut.contains(mid) and not sew.contains(mid)


def test_astm_notches_point_into_the_piece(cup, tmp_path):
    """An ASTM notch is a POINT on the cut line whose angle (group 50) points into the piece,
    as deep as the allowance: base + depth x direction lands on the seam line."""
    path = tmp_path / "cup_astm.dxf"
    patterns.write(cup, path, profile="astm", seam_allowance=10.0)
    doc = read(path)
    for insert in doc.modelspace().query("INSERT"):
        block = doc.blocks[insert.dxf.name]
        (cut,) = [e for e in block.query("POLYLINE") if e.dxf.layer == "1"]
        (sew,) = [e for e in block.query("POLYLINE") if e.dxf.layer == "14"]
        cut_poly = shapely.Polygon([tuple(v.dxf.location)[:2] for v in cut.vertices])
        sew_poly = shapely.Polygon([tuple(v.dxf.location)[:2] for v in sew.vertices])
        for point in block.query('POINT[layer=="4"]'):
            base = np.array(point.dxf.location)[:2]
            depth = point.dxf.location.z
            direction = np.array([np.cos(np.radians(point.dxf.angle)), np.sin(np.radians(point.dxf.angle))])
            assert cut_poly.exterior.distance(shapely.Point(base)) < 1e-6
            assert cut_poly.contains(shapely.Point(base + 0.5 * depth * direction))  # into the piece
            assert sew_poly.exterior.distance(shapely.Point(base + depth * direction)) < 1e-6


@pytest.mark.parametrize("units", ["mm", "cm", "m", "in"])
def test_other_units_end_to_end(tmp_path, units):
    """A mesh in inches (or cm, m) read with --input-units, written in the same unit (--units): the DXF's outline
    area, in that unit squared, is the mesh's own area computed from the file's numbers; the header
    says the unit (INSUNITS 1/4/5/6, MEASUREMENT 0 for inches) and the label says it too."""
    import trimesh

    from patterns import cli, surfaces

    # A whole turn of a cylinder (numbers in `units`): it is cut open, and the cut is a seam with a label.
    v, f = surfaces.cylinder_patch(radius=20.0, height=50.0, angle=360.0, n_around=40, n_along=8)
    v, f = _welded(v, f)
    mesh_path = tmp_path / "tube.obj"
    trimesh.Trimesh(v, f, process=False).export(mesh_path)
    file_v = trimesh.load(mesh_path, process=False).vertices
    p = file_v[f]
    area_3d = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1).sum()
    out = tmp_path / "tube.dxf"
    assert cli.main(["flatten", str(mesh_path), "-o", str(out), "--input-units", units, "--units", units]) == 0
    doc = read(out)
    assert doc.header["$INSUNITS"] == patterns.Unit(units).insunits
    assert doc.header["$MEASUREMENT"] == (0 if units == "in" else 1)
    (outline,) = _polygons(doc, "CUT")
    assert outline.area == pytest.approx(area_3d, rel=1e-6)  # a cylinder unrolls without strain
    assert not outline.area == pytest.approx(area_3d * 25.4**2, rel=0.5)
    labels = [t.dxf.text.split() for t in doc.modelspace().query("TEXT") if t.dxf.text.startswith("S0 ")]
    assert labels and all(words[-1] == patterns.Unit(units).label for words in labels)  # "S0 3D ... FLAT ... IN"


def test_true_scale_against_independent_lengths(cup, tmp_path):
    """1:1 checked with numbers computed here, not by patterns: each flat outline's area (shapely)
    against the 3D area (cross products), each seam side's flat length against the 3D polyline of
    its points.  A pattern scaled by 1.5 fails both; one scaled by 1.001 fails the seams."""
    for flat in cup.panels:
        p = flat.vertices[flat.faces]
        area_3d = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1).sum()
        area_flat = shapely.Polygon(flat.uv[flat.loops[0]]).area
        assert abs(area_flat / area_3d - 1) < 0.05  # a sphere's quarter pressed flat: -2.9 % of its area
    for fs in cup.seams:
        length_3d = np.linalg.norm(np.diff(fs.seam.points, axis=0), axis=1).sum()
        for side, (panel, idx) in enumerate(zip(fs.seam.panels, fs.seam.vertices)):
            uv = cup.panels[panel].uv[np.asarray(idx)]
            flat_length = np.linalg.norm(np.diff(uv, axis=0), axis=1).sum()
            assert flat_length == pytest.approx(length_3d, rel=2e-4), (fs.seam.id, side)


def _welded(v, f):
    """The mesh with vertices at the same coordinates (the seam of a whole turn) made one."""
    _, index, inverse = np.unique(np.round(v, 9), axis=0, return_index=True, return_inverse=True)
    return v[index], inverse.ravel()[f]


# --------------------------------------------------------------------------- #
# The ASTM file read back entity by entity (mutation testing found it untested)
# --------------------------------------------------------------------------- #


def _block_entities(doc):
    """``{block name: [entities]}`` for every piece inserted in model space."""
    return {ins.dxf.name: list(doc.blocks[ins.dxf.name]) for ins in doc.modelspace().query("INSERT")}


def test_astm_pieces_read_back_entity_by_entity(tmp_path):
    """A box's six faces with a 10 mm allowance, ASTM: per piece, the cut line (layer 1) is the face
    grown by 10 mm, the sew line (14) the face itself, turn points (2) at exactly the four corners
    and curve points (3) at every other cut vertex, the five piece-text lines on layer 1 in order,
    inside the piece, 0.6 x the label height (3 % of the piece's size), the strain line on 15 below
    them, a vertical grain line (7) inside the seam line; block names are unique and legal."""
    sizes = sorted([(200.0, 100.0), (200.0, 50.0), (100.0, 50.0)] * 2)
    pattern = patterns.flatten(patterns.load(bd.Box(200, 100, 50), max_edge=25))
    path = tmp_path / "box_astm.dxf"
    patterns.write(pattern, path, profile="astm", seam_allowance=10.0)
    doc = read(path)
    blocks = _block_entities(doc)
    assert len(blocks) == 6
    assert all(re.fullmatch(r"[A-Za-z0-9_\-]{1,31}", name) for name in blocks)
    assert len({name.upper() for name in blocks}) == 6
    found = []
    for name, ents in blocks.items():
        by = {}
        for e in ents:
            by.setdefault((e.dxftype(), e.dxf.layer), []).append(e)
        (cut,) = by[("POLYLINE", "1")]
        (sew,) = by[("POLYLINE", "14")]
        cut_pts = np.array([tuple(v.dxf.location)[:2] for v in cut.vertices])
        sew_poly = shapely.Polygon([tuple(v.dxf.location)[:2] for v in sew.vertices])
        x0, y0, x1, y1 = sew_poly.bounds
        w, h = sorted([x1 - x0, y1 - y0], reverse=True)
        found.append(tuple(sorted((w, h))))
        assert sew_poly.area == pytest.approx(w * h, rel=1e-9)
        assert shapely.Polygon(cut_pts).area == pytest.approx((w + 20) * (h + 20), rel=1e-9)
        turns = np.array([tuple(p.dxf.location)[:2] for p in by[("POINT", "2")]])
        curves = np.array([tuple(p.dxf.location)[:2] for p in by.get(("POINT", "3"), [])]).reshape(-1, 2)
        corners = np.array([[x0 - 10, y0 - 10], [x1 + 10, y0 - 10], [x1 + 10, y1 + 10], [x0 - 10, y1 + 10]])
        assert len(turns) == 4
        assert np.abs(np.sort(turns, axis=0) - np.sort(corners, axis=0)).max() < 1e-6
        assert len(turns) + len(curves) == len(cut_pts)  # every cut vertex is one or the other
        texts = by[("TEXT", "1")]
        assert [t.dxf.text for t in texts] == [f"Piece Name:{name}", "Size:BASE", "Quantity:1", "Material:",
                                               f"Style Name:{pattern.name}", "Units:METRIC"]
        th = float(np.clip(0.03 * max(w, h), 2.0, 12.0))
        # 0.6 x the label height, or smaller where the piece is too narrow for the lines (the 50 mm
        # wide faces): the block shrinks as a whole, its lines a label height apart -- never below the
        # least text height, 2 mm (issue 34)
        size = texts[0].dxf.height
        assert 2.0 - 1e-9 <= size <= max(0.6 * th, 2.0) + 1e-9
        assert all(t.dxf.height == pytest.approx(size) for t in texts)
        ys = [t.dxf.align_point[1] for t in texts]
        assert np.allclose(np.diff(ys), -size / 0.6)
        assert all(sew_poly.contains(shapely.Point(tuple(t.dxf.align_point)[:2])) for t in texts)
        (strain,) = [t for t in by[("TEXT", "15")] if t.dxf.text.startswith("STRAIN")]
        assert strain.dxf.align_point[1] == pytest.approx(ys[0] - 7 * size / 0.6)  # 1.5 line heights below them
        assert strain.dxf.height == pytest.approx(size)
        (grain,) = by[("LINE", "7")]
        a, b = np.array(tuple(grain.dxf.start)[:2]), np.array(tuple(grain.dxf.end)[:2])
        assert a[0] == pytest.approx(b[0]) and b[1] > a[1]  # along +Y
        assert sew_poly.contains(shapely.Point(a)) and sew_poly.contains(shapely.Point(b))
    assert sorted(found) == [tuple(sorted(s)) for s in sizes]


def test_astm_internal_lines_are_the_rulings_of_a_rolled_panel(tmp_path):
    """bend_spacing on a rolled cylinder: the ASTM internal lines (layer 8) are the machine
    profile's BEND lines, the same segments, inside the piece."""
    pattern = patterns.flatten(patterns.load(SAMPLES / "rolled_cylinder.step"))
    astm, machine = tmp_path / "a.dxf", tmp_path / "m.dxf"
    patterns.write(pattern, astm, profile="astm", bend_spacing=50.0)
    patterns.write(pattern, machine, bend_spacing=50.0)
    lines = sorted(tuple(np.round(np.r_[tuple(e.dxf.start)[:2], tuple(e.dxf.end)[:2]], 6))
                   for ents in _block_entities(read(astm)).values() for e in ents
                   if e.dxftype() == "LINE" and e.dxf.layer == "8")
    bends = sorted(tuple(np.round(np.r_[tuple(e.dxf.start)[:2], tuple(e.dxf.end)[:2]], 6))
                   for e in read(machine).modelspace().query('LINE[layer=="BEND"]'))
    assert len(lines) == len(bends) > 0
    # Each file is moved into the first quadrant by its own extents: the same segments up to one shift.
    lines, bends = np.array(lines), np.array(bends)
    shift = (bends - lines)[0]
    np.testing.assert_allclose(lines + shift, bends, atol=1e-6)
    assert np.ptp(shift[[0, 2]]) < 1e-9 and np.ptp(shift[[1, 3]]) < 1e-9


def test_block_names_and_turning_angles():
    from patterns.export.astm import _block_name, _turning

    used = set()
    assert _block_name("face 1/a", used) == "face_1_a"
    assert _block_name("FACE_1_A", used) == "FACE_1_A_2"  # unique without regard to case
    assert _block_name("face 1/a", used) == "face_1_a_3"
    assert _block_name("", used) == "PIECE"
    long = _block_name("x" * 40, used)
    assert long == "x" * 31 and _block_name("x" * 40, used) == "x" * 28 + "_2"
    square = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]])
    np.testing.assert_allclose(_turning(square), [np.pi / 2, 0.0, np.pi / 2, np.pi / 2, np.pi / 2], atol=1e-12)
    triangle = np.array([[0.0, 0.0], [4.0, 0.0], [0.0, 3.0]])
    inner = np.array([np.pi / 2, np.arctan2(3, 4), np.arctan2(4, 3)])
    np.testing.assert_allclose(_turning(triangle), np.pi - inner, atol=1e-12)


@pytest.mark.parametrize("corners", ["mitre", "square"])
def test_each_seam_gets_its_own_allowance(tmp_path, corners):
    """seam_allowance={None: 5, s: 15}: along every seam segment away from the corners, the cut
    line lies exactly that segment's allowance outside the seam line (shapely distances from the
    segment's middle, on the file read back; the panels placed 300 mm apart so that each piece's
    place is known)."""
    flat = patterns.flatten(patterns.load(bd.Box(200, 100, 50), max_edge=25))
    pattern = flat.placed([(0.0, 300.0 * k, 0.0) for k in range(len(flat.panels))])
    wide = max(pattern.seams, key=lambda fs: fs.length).seam.id  # a 200 mm edge: segments away from its ends
    path = tmp_path / "box.dxf"
    patterns.write(pattern, path, seam_allowance={None: 5.0, wide: 15.0}, seam_corners=corners)
    doc = read(path)
    cuts = _polygons(doc, "CUT")
    shift = drawing_shift(doc.modelspace(), pattern, "SEW")
    checked = {5.0: 0, 15.0: 0}
    for fs in pattern.seams:
        allowance = 15.0 if fs.seam.id == wide else 5.0
        for side, p in enumerate(fs.seam.panels):
            panel = pattern.panels[p]
            inside = shapely.Point(panel.uv.mean(axis=0) + shift)
            (cut,) = [c for c in cuts if c.contains(inside)]
            pts = panel.uv[np.asarray(fs.seam.vertices[side])] + shift
            for a, b in zip(pts[1:-2], pts[2:-1]):  # away from the seam's ends (the corners)
                assert cut.exterior.distance(shapely.Point((a + b) / 2)) == pytest.approx(allowance, abs=1e-6)
                checked[allowance] += 1
    assert checked[5.0] > 0 and checked[15.0] > 0


@pytest.mark.parametrize("allowance", [1.0, 10.0])
def test_squared_corners_of_a_rectangle_are_the_rectangle_grown(tmp_path, allowance):
    """A box's faces are rectangles: with squared corners, each cut line is its rectangle grown by
    the allowance on every side -- (w + 2a) x (h + 2a), no more (a run carried past a corner by
    more than the allowance, or capped round, adds area; an allowance skipped adds none)."""
    flat = patterns.flatten(patterns.load(bd.Box(200, 100, 50), max_edge=25))
    pattern = flat.placed([(0.0, 300.0 * k, 0.0) for k in range(len(flat.panels))])
    path = tmp_path / "box.dxf"
    patterns.write(pattern, path, seam_allowance=allowance, seam_corners="square")
    doc = read(path)
    cuts = _polygons(doc, "CUT")
    shift = drawing_shift(doc.modelspace(), pattern, "SEW")
    assert len(cuts) == len(pattern.panels) == 6
    for panel in pattern.panels:
        x0, y0, x1, y1 = shapely.Polygon(panel.uv[panel.loops[0]] + shift).bounds
        grown = shapely.box(x0 - allowance, y0 - allowance, x1 + allowance, y1 + allowance)
        (cut,) = [c for c in cuts if c.contains(shapely.Point((x0 + x1) / 2, (y0 + y1) / 2))]
        assert cut.symmetric_difference(grown).area < 1e-3 * allowance


def _expected_cut(pts, widths, corners):
    """The documented cut line of a convex panel, built here from its definition: ``pts`` (k, 2) its
    seam loop (counter-clockwise), ``widths`` (k,) the allowance of each segment. A side runs between
    corners and changes of allowance, and is offset outwards by its width; ``"square"``: run straight
    on past a corner turning by more than 30 degrees by its own width; ``"mitre"``: the loop grown by
    the least width (mitred), with each wider side's strip square-ended on it."""
    before, after = pts - np.roll(pts, 1, axis=0), np.roll(pts, -1, axis=0) - pts
    turn = np.degrees(np.arctan2(before[:, 0] * after[:, 1] - before[:, 1] * after[:, 0], (before * after).sum(1)))
    ends = np.flatnonzero((np.abs(turn) > 1e-6) | (widths != np.roll(widths, 1)))  # where a side starts
    square = corners == "square"
    parts = [shapely.Polygon(pts).buffer(0.0 if square else float(widths.min()), join_style="mitre")]
    for i, j in zip(ends, np.roll(ends, -1)):
        a, p, q = widths[i], pts[i], pts[j]
        t = (q - p) / np.linalg.norm(q - p)
        n = np.array([t[1], -t[0]])  # outwards: the material lies to the left
        p0 = p - a * t if square and turn[i] > 30 else p
        q0 = q + a * t if square and turn[j] > 30 else q
        parts.append(shapely.Polygon([p0, q0, q0 + a * n, p0 + a * n]))
    return shapely.union_all(parts)


def test_squared_corners_at_a_corner_just_past_thirty_degrees(tmp_path):
    """A prism on a convex pentagon whose corners turn by 30.5, 75, 85, 90 and 79.5 degrees: with
    ``seam_corners="square"`` each of its faces' cut lines, read back, is the squared outline built
    from the definition (every corner over 30 degrees squared, the 30.5 degree one too)."""
    prism = _pentagon_prism([30.5, 75, 85, 90, 79.5])
    flat = patterns.flatten(patterns.load(prism, max_edge=10))
    pattern = flat.placed([(0.0, 400.0 * k, 0.0) for k in range(len(flat.panels))])
    path = tmp_path / "prism.dxf"
    patterns.write(pattern, path, seam_allowance=8.0, seam_corners="square")
    doc = read(path)
    cuts = _polygons(doc, "CUT")
    shift = drawing_shift(doc.modelspace(), pattern, "SEW")
    checked = 0
    for panel in pattern.panels:
        loop = panel.uv[panel.loops[0]] + shift
        expected = _expected_cut(loop, np.full(len(loop), 8.0), "square")
        (cut,) = [c for c in cuts if c.contains(shapely.Polygon(loop).representative_point())]
        assert cut.symmetric_difference(expected).area < 1e-6 * expected.area
        checked += len(shapely.Polygon(loop).simplify(1e-6).exterior.coords) == 6  # a pentagon
    assert checked == 2  # the two pentagons, and the five rectangles


def _pentagon_prism(turns_deg):
    """A prism 30 mm tall on a convex pentagon whose corners turn by ``turns_deg`` (summing to 360),
    its first three sides 120, 80 and 60 mm (the last two close it)."""
    turns = np.radians(turns_deg)
    heading = np.cumsum(np.r_[0, turns[:-1]])
    d = np.column_stack([np.cos(heading), np.sin(heading)])
    first = np.array([120.0, 80.0, 60.0])
    sides = np.r_[first, np.linalg.solve(d[3:].T, -(first[:, None] * d[:3]).sum(axis=0))]
    corners = np.vstack([[0, 0], np.cumsum(sides[:, None] * d, axis=0)[:-1]])
    return bd.extrude(bd.Polygon(*[tuple(c) for c in corners], align=None), 30)


def test_astm_turn_points_are_the_corners_past_twenty_degrees(tmp_path):
    """ASTM layer 2 (turn points) holds the outline's corners, layer 3 (curve points) the rest: on a
    pentagon whose corners turn by 20.5 to 90 degrees every corner is a turn point, the 20.5 one too;
    a hole's cut loop is closed, on layer 11."""
    flat = patterns.flatten(patterns.load(_pentagon_prism([20.5, 75, 85, 90, 89.5]), max_edge=10))
    path = tmp_path / "prism.dxf"
    patterns.write(flat, path, profile="astm")
    doc = read(path)
    pentagons = 0
    for ents in _block_entities(doc).values():
        (cut,) = [e for e in ents if e.dxftype() == "POLYLINE" and e.dxf.layer == "1"]
        ring = np.array([tuple(v.dxf.location)[:2] for v in cut.vertices])
        turns = [e for e in ents if e.dxftype() == "POINT" and e.dxf.layer == "2"]
        assert len(turns) == len(ring)  # its straight runs are one segment: every vertex a corner
        pentagons += len(ring) == 5
    assert pentagons == 2
    plate = patterns.flatten(patterns.load(bd.Box(200, 100, 50) - bd.Cylinder(20, 50), max_edge=10))
    patterns.write(plate, path, profile="astm", seam_allowance=5.0)
    doc = read(path)
    holes = [e for ents in _block_entities(doc).values() for e in ents
             if e.dxftype() == "POLYLINE" and e.dxf.layer == "11"]
    assert len(holes) == 2 and all(h.is_closed for h in holes)


def test_a_notch_a_hair_before_the_end_is_left_out(notched, tmp_path):
    """notch_spacing 49 on the box: a notch every 49 mm of each seam and at its end, but none closer
    than a quarter of the spacing before the end one -- 200 mm: 0, 49, 98, 147, 200 (not 196);
    100 mm: 0, 49, 100 (not 98); 50 mm: 0, 50 (not 49) -- on both sides of every seam."""
    pattern = notched["box"]
    path = tmp_path / "box.dxf"
    patterns.write(pattern, path, notch_spacing=49.0)
    expected = {200.0: 5, 100.0: 3, 50.0: 2}
    assert len(_notch_lines(read(path))) == sum(2 * expected[round(fs.length)] for fs in pattern.seams)


@pytest.mark.parametrize("corners", ["square", "mitre"])
def test_corners_where_a_one_segment_seam_has_its_own_allowance(tmp_path, corners):
    """A box sewn from faces whose top is three faces (40, 20 and 40 mm wide): the front's and back's
    top edges are three seams on one straight line, the middle one a single segment. With 10 mm on
    those middle seams, 5 mm on the rest, each cut line read back is the one built from the
    definition: squared, each side's strip its own width, run on past the sharp corners only (not
    where the allowance changes along a straight line); mitred, the outline grown by 5 mm and the
    10 mm strips square-ended on it."""
    def rect(pts):
        return bd.Face(bd.Wire.make_polygon([bd.Vector(*q) for q in pts], close=True))

    w, d, h = 100.0, 40.0, 30.0
    faces = [rect([(x0, 0, h), (x1, 0, h), (x1, d, h), (x0, d, h)]) for x0, x1 in ((0, 40), (40, 60), (60, 100))]
    faces += [rect([(0, 0, 0), (0, d, 0), (w, d, 0), (w, 0, 0)]), rect([(0, 0, 0), (w, 0, 0), (w, 0, h), (0, 0, h)]),
              rect([(0, d, 0), (0, d, h), (w, d, h), (w, d, 0)]), rect([(0, 0, 0), (0, 0, h), (0, d, h), (0, d, 0)]),
              rect([(w, 0, 0), (w, d, 0), (w, d, h), (w, 0, h)])]
    flat = patterns.flatten(patterns.load(bd.Compound(faces), max_edge=25))
    middle = {fs.seam.id for fs in flat.seams if len(fs.seam.vertices[0]) == 2}  # one segment each
    assert len(middle) == 2
    allowance = {None: 5.0, **{k: 10.0 for k in middle}}
    pattern = flat.placed([(0.0, 300.0 * k, 0.0) for k in range(len(flat.panels))])
    path = tmp_path / "box.dxf"
    patterns.write(pattern, path, seam_allowance=allowance, seam_corners=corners)
    doc = read(path)
    cuts = _polygons(doc, "CUT")
    shift = drawing_shift(doc.modelspace(), pattern, "SEW")
    seam_of = {}
    for fs in pattern.seams:
        for p, idx in zip(fs.seam.panels, fs.seam.vertices):
            for a, b in zip(idx[:-1], idx[1:]):
                seam_of[(p, int(a), int(b))] = seam_of[(p, int(b), int(a))] = fs.seam.id
    for k, panel in enumerate(pattern.panels):
        loop = panel.loops[0]
        pts = panel.uv[loop] + shift
        widths = np.array([allowance.get(seam_of.get((k, int(a), int(b))), 5.0) for a, b in zip(loop, np.roll(loop, -1))])
        expected = _expected_cut(pts, widths, corners)
        (cut,) = [c for c in cuts if c.contains(shapely.Polygon(pts).representative_point())]
        assert cut.symmetric_difference(expected).area < 1e-6 * expected.area, panel.name


def test_an_allowance_only_for_the_seams_named(plate, tmp_path):
    """seam_allowance={seam: mm} without a None key: every other edge gets none. The seam's two panels
    get a seam line (SEW) and a cut line outside it; every other panel is cut on its seam line."""
    seam = plate.seams[0].seam
    path = tmp_path / "plate.dxf"
    patterns.write(plate, path, seam_allowance={seam.id: 8.0})
    doc = read(path)
    sews = sorted(ring_numbers(pts) for pts, _ in polylines(doc, "SEW"))
    cuts = sorted(ring_numbers(pts) for pts, _ in polylines(doc, "CUT"))
    with_allowance = set(seam.panels)
    np.testing.assert_allclose(sews, sorted(ring_numbers(plate.panels[k].uv[loop]) for k in with_allowance
                                            for loop in plate.panels[k].loops), rtol=1e-9)
    bare = sorted(ring_numbers(flat.uv[loop]) for k, flat in enumerate(plate.panels) if k not in with_allowance
                  for loop in flat.loops)
    assert len(cuts) == len(bare) + len(sews)
    assert all(any(c == pytest.approx(b, rel=1e-9) for c in cuts) for b in bare)
    assert sum(c[0] for c in cuts) > sum(b[0] for b in bare) + sum(w[0] for w in sews)  # grown where named


def test_a_folder_for_the_dxf_is_refused_naming_it(cup, tmp_path):
    folder = tmp_path / "out.dxf"
    folder.mkdir()
    with pytest.raises(ExportError, match=r"is a folder; name a file for the DXF file$"):
        patterns.write(cup, folder)


def test_ezdxf_s_time_stamps_are_fixed(cup, tmp_path):
    """The file says which ezdxf wrote it, at a fixed time (2000-01-01): the same pattern gives the
    same bytes tomorrow."""
    path = tmp_path / "cup.dxf"
    patterns.write(cup, path)
    text = path.read_text(encoding="utf-8", errors="replace")
    stamps = re.findall(r"\d+\.\d+\.\d+ @ \d{4}-\d\d-\d\dT[\d:.]+\+00:00", text)
    assert stamps and all(s == f"{ezdxf.__version__} @ 2000-01-01T00:00:00+00:00" for s in stamps)


def test_an_allowance_grows_the_outline_and_shrinks_the_hole(plate, tmp_path):
    """With a 5 mm allowance every cut loop read back is its seam loop offset by 5 mm (mitred):
    the outlines outwards, the hole's inwards -- every point of each (a loop missing one has
    another area)."""
    path = tmp_path / "plate.dxf"
    patterns.write(plate, path, seam_allowance=5.0)
    found = sorted(ring_numbers(pts) for pts, _ in polylines(read(path), "CUT"))
    expected = []
    for flat in plate.panels:
        outline, *holes = (shapely.Polygon(flat.uv[loop]) for loop in flat.loops)
        expected.append(outline.buffer(5.0, join_style="mitre"))
        expected += [hole.buffer(-5.0, join_style="mitre") for hole in holes]
    assert sum(len(flat.loops) > 1 for flat in plate.panels) == 2  # the top and the bottom have the hole
    expected = sorted((g.area, g.exterior.length) for g in expected)
    np.testing.assert_allclose(found, expected, rtol=1e-9)


def test_a_hole_s_own_allowance_is_drawn(plate, tmp_path):
    """seam_allowance 10 mm on the hole's seams, 5 mm elsewhere: the plate's outlines grow by 5 mm, the
    holes shrink by 10 (a panel whose outline has the least allowance still gets its hole's)."""
    holed = [k for k, flat in enumerate(plate.panels) if len(flat.loops) > 1]
    hole_seams = {fs.seam.id for fs in plate.seams
                  if any(p in holed and not set(idx.tolist()) - set(plate.panels[p].loops[1].tolist())
                         for p, idx in zip(fs.seam.panels, fs.seam.vertices))}
    assert hole_seams
    path = tmp_path / "plate.dxf"
    patterns.write(plate, path, seam_allowance={None: 5.0, **{k: 10.0 for k in hole_seams}})
    found = sorted(ring_numbers(pts) for pts, _ in polylines(read(path), "CUT"))
    expected = []
    for k in holed:
        outline, hole = (shapely.Polygon(plate.panels[k].uv[loop]) for loop in plate.panels[k].loops)
        expected += [outline.buffer(5.0, join_style="mitre"), hole.buffer(-10.0, join_style="mitre")]
    expected = sorted((g.area, g.exterior.length) for g in expected)
    for e in expected:  # the holed panels' loops among the cut loops read back
        assert any(np.allclose(f, e, rtol=1e-6) for f in found), e


def test_a_panel_too_small_to_draw_is_refused_at_any_angle(tmp_path):
    """A 6 mm-thousandths square laid out along its diagonal: 0.0085 mm across each way (under the
    0.01 mm a DXF draws), 0.0127 mm from its lowest coordinate to its highest -- refused, by its
    extent across, and nothing written."""
    s = 0.006
    trimesh.Trimesh([[0, 0, 0], [s, s, 0], [0, s, 0], [s, 0, 0]], [[0, 1, 2], [0, 3, 1]],
                    process=False).export(tmp_path / "speck.obj")
    pattern = patterns.flatten(patterns.load(tmp_path / "speck.obj"))
    uv = pattern.panels[0].uv
    assert np.ptp(uv, axis=0).max() < 0.01 < np.ptp(uv)  # the case: its coordinates span more than it does
    for profile in ("machine", "astm"):
        with pytest.raises(InputError, match=rf"a panel {s * np.sqrt(2):.3g} mm across, under the 0.01 mm"):
            patterns.write(pattern, tmp_path / "speck.dxf", profile=profile)
    assert not (tmp_path / "speck.dxf").exists()


@pytest.mark.parametrize("profile", ["machine", "astm"])
def test_a_full_disk_is_named_and_leaves_nothing(cup, tmp_path, profile):
    disk = tmp_path / "disk"
    small_disk(disk, "24k")
    try:
        with pytest.raises(ExportError, match=r"cup.dxf: cannot write the DXF file \(No space left on device\)"):
            patterns.write(cup, disk / "cup.dxf", profile=profile)
        assert list(disk.iterdir()) == []  # no partial file, no temporary
    finally:
        subprocess.run(["umount", str(disk)], check=False)


def test_notches_off_a_corner_are_square_to_the_outline(notched, tmp_path):
    """Without an allowance, a notch every 1.5 mm along the box's seams: the last of each lies
    0.5 mm before the end of a 50 or 200 mm seam, a corner of the outline. Every notch not on a corner is a snip
    square to the straight line it is on (a notch near a corner taken for one at it would run
    along the corner's bisector)."""
    pattern = notched["box"]
    path = tmp_path / "box.dxf"
    patterns.write(pattern, path, notch_spacing=1.5)
    doc = read(path)
    cuts = _polygons(doc, "CUT")
    near_corners = 0
    for a, b in _notch_lines(doc):
        cut = cuts[int(np.argmin([c.distance(shapely.Point((a + b) / 2)) for c in cuts]))]
        ring = np.asarray(cut.exterior.coords)
        corner = np.linalg.norm(ring - a, axis=1).min()
        if corner < 1e-6:
            continue
        near_corners += corner < 1.0
        edges = [k for k in range(len(ring) - 1)
                 if shapely.LineString(ring[k:k + 2]).distance(shapely.Point(a)) < 1e-6]
        (k,) = edges
        along = (ring[k + 1] - ring[k]) / np.linalg.norm(ring[k + 1] - ring[k])
        assert abs(along @ (b - a)) / np.linalg.norm(b - a) < 1e-9
    # the 0.5 mm ones were there and were checked: both sides of each 200 and 50 mm seam (100 = 66 x 1.5 + 1)
    assert near_corners == 2 * sum(1 for fs in pattern.seams if fs.length % 1.5 == pytest.approx(0.5))


def test_write_outline_dxf_checks_every_loop_and_writes_them_as_given(tmp_path):
    from patterns.export import write_outline_dxf

    path = tmp_path / "outline.dxf"
    bad = {"three columns": [[0, 0, 0], [1, 0, 0], [1, 1, 0]], "two points": [[0, 0], [1, 0]],
           "a NaN": [[0, 0], [1, np.nan], [1, 1]], "flat list": [0, 0, 1, 0, 1, 1]}
    for loop in bad.values():
        with pytest.raises(InputError, match=r"outline.dxf: loop 1 is not a finite"):
            write_outline_dxf(path, [np.array([[0, 0], [1, 0], [0, 1]]), np.array(loop, dtype=float)])
    with pytest.raises(InputError, match="unknown unit 'ft'; choose one of mm, cm, m, in"):
        write_outline_dxf(path, [np.array([[0, 0], [1, 0], [0, 1]])], units="ft")
    assert not path.exists()
    square, hole = np.array([[0, 0], [50, 0], [50, 40], [0, 40]]), np.array([[10, 10], [10, 20], [20, 20]])
    write_outline_dxf(path, [square, hole], units="in", layer="OUTLINE")
    doc = read(path)
    assert doc.dxfversion == "AC1015" and doc.header["$INSUNITS"] == 1 and doc.header["$MEASUREMENT"] == 0
    assert doc.layers.get("OUTLINE").color == 1
    got = [np.array(e.get_points("xy")) for e in doc.modelspace().query('LWPOLYLINE[layer=="OUTLINE"]')]
    assert all(e.closed for e in doc.modelspace().query("LWPOLYLINE"))
    np.testing.assert_array_equal(got[0], square)
    np.testing.assert_array_equal(got[1], hole)


# --------------------------------------------------------------------------- #
# Notches: on the cut line, pointing into the piece, at corners too (issue 20)
# --------------------------------------------------------------------------- #


@pytest.fixture(scope="module")
def notched():
    """The box, the cup, the square-to-round and a plate with a hole, flattened once."""
    return {"box": patterns.flatten(patterns.load(bd.Box(200, 100, 50), max_edge=10)),
            "cup": patterns.flatten(patterns.load(SAMPLES / "cup.step")),
            "square_to_round": patterns.flatten(patterns.load(SAMPLES / "square_to_round.step")),
            "plate": patterns.flatten(patterns.load(bd.Box(200, 100, 50) - bd.Cylinder(20, 50), max_edge=10))}


def _notch_lines(doc):
    """(k, 2, 2): the NOTCH lines of a machine file (a V gives two)."""
    return np.array([[np.array(e.dxf.start)[:2], np.array(e.dxf.end)[:2]]
                     for e in doc.modelspace().query('LINE[layer=="NOTCH"]')]).reshape(-1, 2, 2)


@pytest.mark.parametrize("allowance", [0.0, 10.0])
@pytest.mark.parametrize("style", ["slit", "v"])
@pytest.mark.parametrize("part", ["box", "cup", "square_to_round"])
def test_every_notch_starts_on_the_cut_line_and_points_into_the_piece(notched, tmp_path, part, style, allowance):
    """Each panel's notches, read back from the machine file, checked with shapely against its own cut
    polygon (and seam polygon): one end on the cut line; the rest inside the cut outline, within the
    seam allowance when there is one (never past the seam line into the finished piece), and never
    running along the cut line."""
    pattern = notched[part]
    path = tmp_path / f"{part}.dxf"
    patterns.write(pattern, path, seam_allowance=allowance, notch_style=style)
    doc = read(path)
    cuts = _polygons(doc, "CUT")
    sews = _polygons(doc, "SEW") if allowance else cuts
    lines = _notch_lines(doc)
    n_notches = 2 * 2 * len(pattern.seams)  # both ends of both sides of every seam
    assert len(lines) == n_notches * (1 if style == "slit" else 2)
    for a, b in lines:
        k = int(np.argmin([c.distance(shapely.Point((a + b) / 2)) for c in cuts]))
        cut, sew = cuts[k], sews[int(np.argmin([s.distance(shapely.Point((a + b) / 2)) for s in sews]))]
        on_cut = [cut.exterior.distance(shapely.Point(p)) < 1e-6 for p in (a, b)]
        assert any(on_cut)
        outer, inner = (a, b) if on_cut[0] else (b, a)
        for t in (0.25, 0.5, 0.75):
            q = shapely.Point(outer + t * (inner - outer))
            assert cut.contains(q)  # into the piece's outline
            assert cut.exterior.distance(q) > 1e-3  # not along the cut line
            if allowance:
                assert not sew.buffer(-1e-6).contains(q)  # not past the seam line


@pytest.mark.parametrize("part", ["box", "cup", "square_to_round"])
def test_a_v_notch_opens_as_wide_as_it_is_deep(notched, tmp_path, part):
    """notch_style="v" with a 10 mm allowance: each V is two lines from one tip (on the seam line) to two
    mouth points on the cut line, as far from the tip as each other, the mouth 10 mm wide along the cut
    line (as wide as the V is deep)."""
    path = tmp_path / f"{part}.dxf"
    patterns.write(notched[part], path, seam_allowance=10.0, notch_style="v")
    doc = read(path)
    cuts = _polygons(doc, "CUT")
    lines = _notch_lines(doc)
    assert len(lines) == 2 * 2 * 2 * len(notched[part].seams)  # two lines a V, at both ends of both sides
    for first, second in zip(lines[0::2], lines[1::2]):  # a V's two lines are written one after the other
        ends = []
        for a, b in (first, second):  # the tip: the end not on the cut line
            k = int(np.argmin([c.distance(shapely.Point((a + b) / 2)) for c in cuts]))
            on_cut = cuts[k].exterior.distance(shapely.Point(a)) < 1e-6
            ends.append((b, a, k) if on_cut else (a, b, k))
        (tip0, mouth0, k), (tip1, mouth1, _) = ends
        np.testing.assert_allclose(tip0, tip1, atol=1e-9)  # one tip
        assert np.linalg.norm(mouth0 - tip0) == pytest.approx(np.linalg.norm(mouth1 - tip0), abs=1e-3)
        mouths = [mouth0, mouth1]
        ring = cuts[k].exterior
        gap = abs(ring.project(shapely.Point(mouths[0])) - ring.project(shapely.Point(mouths[1])))
        assert min(gap, ring.length - gap) == pytest.approx(10.0, abs=1e-3)  # as wide as deep, along the line


@pytest.mark.parametrize("allowance", [0.0, 10.0])
@pytest.mark.parametrize("part", ["box", "cup", "square_to_round"])
def test_every_astm_notch_points_into_the_piece(notched, tmp_path, part, allowance):
    pattern = notched[part]
    path = tmp_path / f"{part}_astm.dxf"
    patterns.write(pattern, path, profile="astm", seam_allowance=allowance)
    doc = read(path)
    count = 0
    for insert in doc.modelspace().query("INSERT"):
        block = doc.blocks[insert.dxf.name]
        (cut,) = [e for e in block.query("POLYLINE") if e.dxf.layer == "1"]
        cut_poly = shapely.Polygon([tuple(v.dxf.location)[:2] for v in cut.vertices])
        for point in block.query('POINT[layer=="4"]'):
            base = np.array(point.dxf.location)[:2]
            depth = point.dxf.location.z
            direction = np.array([np.cos(np.radians(point.dxf.angle)), np.sin(np.radians(point.dxf.angle))])
            assert cut_poly.exterior.distance(shapely.Point(base)) < 1e-6
            for t in (0.25, 0.5, 0.75):
                q = shapely.Point(base + t * depth * direction)
                assert cut_poly.contains(q) and cut_poly.exterior.distance(q) > 1e-3
            count += 1
    assert count == 2 * 2 * len(pattern.seams)


@pytest.mark.parametrize("options", [{}, {"version": "R12"}, {"profile": "astm"}, {"seam_allowance": 10.0},
                                     {"units": "in"}, {"units": "cm", "version": "R2018"}])
def test_the_drawing_starts_in_the_first_quadrant(plate, tmp_path, options):
    """A laser's work area and a page start at (0, 0): the extents start 5 mm from each axis."""
    from ezdxf import bbox

    path = tmp_path / "plate.dxf"
    patterns.write(plate, path, **options)
    box = bbox.extents(read(path).modelspace())
    scale = patterns.Unit(options.get("units", "mm")).mm
    assert (box.extmin.x * scale, box.extmin.y * scale) == pytest.approx((5.0, 5.0), abs=1e-6)


@pytest.mark.parametrize("options", [{}, {"seam_allowance": 10.0}, {"version": "R12"}, {"profile": "astm"}])
def test_straight_edges_are_one_segment(notched, tmp_path, options):
    """The box's panels are rectangles: each cut line (and seam line) is four vertices, not the
    hundreds of mesh points along its edges; ASTM has no curve points on them."""
    pattern = notched["box"]
    path = tmp_path / "box.dxf"
    patterns.write(pattern, path, **options)
    doc = read(path)
    if options.get("profile") == "astm":
        rings = [e for b in doc.blocks for e in b if e.dxftype() == "POLYLINE"]
        assert [len(list(e.vertices)) for e in rings] == [4] * len(pattern.panels)
        assert not [e for b in doc.blocks for e in b if e.dxftype() == "POINT" and e.dxf.layer == "3"]
        return
    for layer in ("CUT", "SEW") if options.get("seam_allowance") else ("CUT",):
        assert [len(pts) for pts, _ in polylines(doc, layer)] == [4] * len(pattern.panels)
        # ... and still the panels' true areas
        areas = sorted(shapely.Polygon(pts).area for pts, _ in polylines(doc, layer))
        if layer == "CUT" and not options.get("seam_allowance"):
            assert areas == pytest.approx(sorted(p.area for p in pattern.panels), rel=1e-9)


LABELLED = ["box", "cup.step", "duct_transition.step", "hopper.step", "hull_panel.step", "rolled_cylinder.step",
            "square_to_round.step", "dish.obj", "cone.obj"]


@pytest.fixture(scope="module")
def labelled():
    out = {}
    for name in LABELLED:
        source = bd.Box(200, 100, 50) if name == "box" else SAMPLES / name
        out[name] = patterns.flatten(patterns.load(source))
    return out


@pytest.mark.slow
@pytest.mark.parametrize("allowance", [0.0, 10.0])
@pytest.mark.parametrize("name", LABELLED)
def test_no_label_crosses_a_cut_line_or_another_label(labelled, tmp_path, name, allowance):
    """Every TEXT of the machine file (names, strain, seam lengths, bend angles), boxed with ezdxf's
    own font metrics for the standard style at its height and angle, read back: off every CUT and SEW
    line, and off every other label."""
    from patterns.pieces.labels import text_box

    path = tmp_path / "p.dxf"
    patterns.write(labelled[name], path, seam_allowance=allowance, bend_spacing=50.0)
    doc = read(path)
    lines = shapely.union_all([shapely.LinearRing(pts) for layer in ("CUT", "SEW")
                               for pts, _ in polylines(doc, layer)])
    boxes = [text_box(t.dxf.text, tuple(t.dxf.align_point)[:2], t.dxf.height, t.dxf.rotation, widen=1.0)
             for t in doc.modelspace().query("TEXT")]
    assert boxes
    assert not [b for b in boxes if b.intersects(lines)]
    tree = shapely.STRtree(boxes)
    pairs = [(i, j) for i, j in zip(*tree.query(boxes, predicate="intersects")) if i < j]
    assert not pairs


@pytest.mark.parametrize("options", [{"version": "R12"}, {"version": "R12", "units": "in"}, {"profile": "astm"}])
def test_r12_files_declare_their_units_too(plate, tmp_path, options):
    """R12 predates $INSUNITS and $MEASUREMENT; they are written anyway (Inkscape scales by them)."""
    path = tmp_path / "plate.dxf"
    patterns.write(plate, path, **options)
    doc = read(path)
    unit = patterns.Unit(options.get("units", "mm"))
    assert doc.dxfversion == "AC1009"
    assert (doc.header["$INSUNITS"], doc.header["$MEASUREMENT"]) == (unit.insunits, unit.measurement)


@pytest.mark.parametrize("name", LABELLED)
def test_no_astm_label_crosses_a_line_or_another_label(labelled, tmp_path, name):
    """The same for the ASTM profile: the piece text, strain and seam lengths inside each piece block
    and the style text in model space, off the cut and sew lines (layers 1, 14) and off each other."""
    from patterns.pieces.labels import text_box

    path = tmp_path / "p.dxf"
    patterns.write(labelled[name], path, profile="astm", seam_allowance=10.0)
    doc = read(path)
    entities = list(doc.modelspace()) + [e for b in doc.blocks if not b.is_any_layout for e in b]
    lines = shapely.union_all([shapely.LinearRing([tuple(v.dxf.location)[:2] for v in e.vertices])
                               for e in entities if e.dxftype() == "POLYLINE" and e.dxf.layer in ("1", "14")])
    boxes = [_text_box_read_back(t, text_box) for t in entities if t.dxftype() == "TEXT"]
    assert not [b for b in boxes if b.intersects(lines)]
    tree = shapely.STRtree(boxes)
    assert not [(i, j) for i, j in zip(*tree.query(boxes, predicate="intersects")) if i < j]


def _text_box_read_back(t, text_box):
    """The box of a TEXT read back, from its alignment: centred boxes as written, bottom-left ones (the
    ASTM style text; unrotated) moved so that their lower-left corner is the alignment point."""
    h = t.dxf.height
    if (t.dxf.halign, t.dxf.valign) == (1, 2):  # MIDDLE_CENTER
        return text_box(t.dxf.text, tuple(t.dxf.align_point)[:2], h, t.dxf.rotation, widen=1.0)
    assert (t.dxf.halign, t.dxf.valign) == (0, 1) and t.dxf.rotation == 0  # BOTTOM_LEFT
    box = text_box(t.dxf.text, (0.0, 0.0), h, 0.0, widen=1.0)
    x0, y0, _, _ = box.bounds
    at = tuple(t.dxf.align_point)[:2]
    return shapely.affinity.translate(box, at[0] - x0, at[1] - y0)


# --------------------------------------------------------------------------- #
# OpenSCAD and Inkscape (issue 20): true size, or the reader table says why not
# --------------------------------------------------------------------------- #

PX = 25.4 / 96.0
"""Inkscape's SVG user unit (a CSS pixel), mm."""


def _inkscape_svg(path, tmp_path, scalemethod="file"):
    """Inkscape's own DXF import (its ``dxf_input`` extension, run headless with the system's Python)."""
    ext = Path("/usr/share/inkscape/extensions/dxf_input.py")
    if shutil.which("inkscape") is None or not ext.exists():
        if "inkscape" in _installed_by_ci():
            pytest.fail("inkscape is missing although .ci/run installed it")
        pytest.skip("inkscape is not installed (.ci/run installs it with apt-get)")
    proc = subprocess.run(["/usr/bin/python3", str(ext), f"--scalemethod={scalemethod}", str(path)],
                          capture_output=True, text=True, env=dict(os.environ, PYTHONPATH=str(ext.parent)),
                          timeout=120)
    assert proc.returncode == 0, proc.stderr[-2000:]
    svg = tmp_path / (path.stem + ".svg")
    svg.write_text(proc.stdout)
    return svg


def _cut_area(doc):
    return sum(p.area for p in _polygons(doc, "CUT"))


@pytest.mark.parametrize("part", ["box", "cup", "square_to_round"])
@pytest.mark.parametrize("options", [{}, {"version": "R12"}, {"units": "in"}, {"seam_allowance": 10.0}])
def test_inkscape_reads_the_machine_profile_at_true_size(notched, tmp_path, part, options):
    """Inkscape's DXF import, scaling "read from file" ($MEASUREMENT): every CUT ring at its area."""
    from .readers.svg_rings import rings

    path = tmp_path / f"{part}.dxf"
    patterns.write(notched[part], path, **options)
    svg = _inkscape_svg(path, tmp_path)
    found = sorted(shapely.Polygon(r).area * PX**2 for r in rings(svg, "CUT"))
    scale = patterns.Unit(options.get("units", "mm")).mm
    expected = sorted(p.area * scale**2 for p in _polygons(read(path), "CUT"))
    assert found == pytest.approx(expected, rel=1e-3)


@pytest.mark.parametrize("part", ["box", "cup", "square_to_round"])
def test_inkscape_reads_the_astm_profile_at_true_size(notched, tmp_path, part):
    from .readers.svg_rings import symbol_rings

    path = tmp_path / f"{part}_astm.dxf"
    patterns.write(notched[part], path, profile="astm", seam_allowance=10.0)
    svg = _inkscape_svg(path, tmp_path)
    doc = read(path)
    for name, ents in _block_entities(doc).items():
        (cut,) = [e for e in ents if e.dxftype() == "POLYLINE" and e.dxf.layer == "1"]
        area = shapely.Polygon([tuple(v.dxf.location)[:2] for v in cut.vertices]).area
        biggest = max(shapely.Polygon(r).area for r in symbol_rings(svg)[name]) * PX**2
        assert biggest == pytest.approx(area, rel=1e-3)


def test_inkscape_takes_a_cm_file_for_mm(plate, tmp_path):
    """The reader table's caveat, measured: Inkscape's "read from file" knows only $MEASUREMENT
    (metric or imperial), so a drawing in cm comes in 10 times too small."""
    from .readers.svg_rings import rings

    path = tmp_path / "plate_cm.dxf"
    patterns.write(plate, path, units="cm")
    svg = _inkscape_svg(path, tmp_path)
    found = sum(shapely.Polygon(r).area for r in rings(svg, "CUT")) * PX**2
    assert found == pytest.approx(_cut_area(read(path)), rel=1e-3)  # the numbers as mm: 1/100 of the area


def _openscad_svg(path, tmp_path, layer):
    if shutil.which("openscad") is None:
        if "openscad" in _installed_by_ci():
            pytest.fail("openscad is missing although .ci/run installed it")
        pytest.skip("openscad is not installed (.ci/run installs it with apt-get)")
    scad, svg = tmp_path / "import.scad", tmp_path / "import.svg"
    scad.write_text(f'import("{path}", layer="{layer}");\n')
    proc = subprocess.run(["openscad", "-o", str(svg), str(scad)], capture_output=True, text=True, timeout=300)
    return proc, svg


@pytest.mark.parametrize("part", ["box", "cup", "square_to_round"])
def test_openscad_imports_the_machine_profile_at_true_size(notched, tmp_path, part):
    """OpenSCAD's import() of the CUT layer (R2000): the union of what it read has the panels' area."""
    from .readers.svg_rings import rings

    path = tmp_path / f"{part}.dxf"
    patterns.write(notched[part], path)
    proc, svg = _openscad_svg(path, tmp_path, "CUT")
    assert proc.returncode == 0, proc.stderr[-2000:]
    union = shapely.union_all([shapely.Polygon(r) for r in rings(svg)])
    assert union.area == pytest.approx(_cut_area(read(path)), rel=1e-3)


@pytest.mark.parametrize("options", [{"version": "R12"}, {"profile": "astm"}])
def test_openscad_cannot_import_polylines(plate, tmp_path, options):
    """The reader table's caveat, measured: OpenSCAD 2021.01 has no POLYLINE, the only polyline R12 and
    ASTM D6673 have, so it imports nothing from them (it names the entity it skips)."""
    path = tmp_path / "plate.dxf"
    patterns.write(plate, path, **options)
    proc, svg = _openscad_svg(path, tmp_path, "1" if options.get("profile") == "astm" else "CUT")
    assert "Unsupported DXF Entity 'POLYLINE'" in proc.stderr or "Unsupported DXF Entity 'INSERT'" in proc.stderr
    assert not svg.exists()  # "not a 2D object": nothing to export


@pytest.mark.parametrize("part", ["box", "cup", "square_to_round"])
@pytest.mark.parametrize("options", [{"version": "R12"}, {"profile": "astm"}])
def test_freecad_reads_r12_and_astm_at_true_size(notched, tmp_path, part, options):
    """FreeCAD's importer chains each piece's cut line into a closed wire at the panel's area and
    length (ASTM: the piece blocks exploded into one object)."""
    _need("freecadcmd")
    path = tmp_path / f"{part}.dxf"
    pattern = notched[part]
    patterns.write(pattern, path, **options)
    proc = subprocess.run(["freecadcmd", str(READERS / "freecad_layers.py")], capture_output=True, text=True,
                          env=dict(_qt_env(tmp_path), DXF=str(path)), timeout=300)
    lines = [x for x in proc.stdout.splitlines() if "RESULT " in x]
    assert lines, proc.stdout[-2000:] + proc.stderr[-2000:]
    layers = json.loads(lines[-1].split("RESULT ", 1)[1])
    if options.get("profile") == "astm":  # one object: the cut lines, and the zero-area notch and point marks
        wires = [w for layer in layers.values() for w in layer["closed_wires"] if w["area"] > 1e-6]
    else:
        wires = layers["CUT"]["closed_wires"]
    found = sorted((w["area"], w["length"]) for w in wires)
    expected = sorted(ring_numbers(flat.uv[loop]) for flat in pattern.panels for loop in flat.loops)
    assert len(found) == len(expected)
    np.testing.assert_allclose(found, expected, rtol=1e-6)


@pytest.mark.parametrize("part", ["box", "cup", "square_to_round"])
@pytest.mark.parametrize("options", [{}, {"version": "R12"}, {"units": "in"},
                                     {"profile": "astm", "seam_allowance": 10.0}])
def test_librecad_prints_at_true_size(notched, tmp_path, part, options):
    """LibreCAD's ``dxf2pdf --scale 1`` (1:1 on paper): the red CUT lines it strokes close into the
    cut outlines, each at its area within 0.1 % (LibreCAD rounds every point to its 1200 dpi grid,
    0.02 mm: 0.03-0.06 % of these areas); an inch file prints in inches (1 unit = 25.4 mm on paper).
    ASTM pieces (blocks, every layer black): the outer rings of what it draws are the cut outlines."""
    from .readers.pdf_paths import segments

    _need("librecad")
    path = tmp_path / f"{part}.dxf"
    patterns.write(notched[part], path, **options)
    proc = subprocess.run(["librecad", "dxf2pdf", "--scale", "1", str(path)], capture_output=True, text=True,
                          env=_qt_env(tmp_path), timeout=120)
    assert proc.returncode == 0, proc.stderr[-2000:]
    drawn = segments(path.with_suffix(".pdf"))
    scale = patterns.Unit(options.get("units", "mm")).mm
    if options.get("profile") == "astm":
        lines = np.concatenate(list(drawn.values()))
        faces = shapely.union_all(list(shapely.polygonize([shapely.LineString(s) for s in lines]).geoms))
        rings = [shapely.Polygon(g.exterior) for g in getattr(faces, "geoms", [faces])]
        expected = []
        for ents in _block_entities(read(path)).values():
            (cut,) = [e for e in ents if e.dxftype() == "POLYLINE" and e.dxf.layer == "1"]
            expected.append(shapely.Polygon([tuple(v.dxf.location)[:2] for v in cut.vertices]))
    else:
        red = drawn[(1.0, 0.0, 0.0)]  # ACI 1, the CUT layer's colour
        rings = list(shapely.polygonize([shapely.LineString(s) for s in red]).geoms)
        expected = [shapely.affinity.scale(p, scale, scale, origin=(0, 0)) for p in _polygons(read(path), "CUT")]
    found = sorted(rings, key=lambda g: g.area)
    expected = sorted(expected, key=lambda g: g.area)
    assert len(found) == len(expected)
    for got, want in zip(found, expected):
        assert got.area == pytest.approx(want.area, rel=1e-3)


def _dxf2gcode(path, tmp_path):
    _need("dxf2gcode")
    proc = subprocess.run(["/usr/bin/python3", str(READERS / "dxf2gcode_contours.py"), str(path)],
                          capture_output=True, text=True, env=_qt_env(tmp_path), timeout=120)
    assert proc.returncode == 0, proc.stderr[-2000:]
    return json.loads(proc.stdout.strip().splitlines()[-1])


@pytest.mark.parametrize("part", ["box", "cup", "square_to_round"])
@pytest.mark.parametrize("options", [{}, {"version": "R12"}, {"units": "in"}, {"seam_allowance": 10.0}])
def test_dxf2gcode_reads_the_machine_profile_at_true_size(notched, tmp_path, part, options):
    """dxf2gcode's reader: each CUT contour closed, at the area of the ring ezdxf reads back (in the
    file's unit), and the unit taken from the header: metric for mm, imperial for inches."""
    path = tmp_path / f"{part}.dxf"
    patterns.write(notched[part], path, **options)
    found = _dxf2gcode(path, tmp_path)
    expected = sorted(p.area for p in _polygons(read(path), "CUT"))
    assert found["entities"]["CUT"]["closed"] == found["entities"]["CUT"]["contours"] == len(expected)
    np.testing.assert_allclose(found["entities"]["CUT"]["areas"], expected, rtol=1e-3)
    assert found["metric"] is (options.get("units", "mm") != "in")


def test_dxf2gcode_takes_a_cm_file_for_mm(plate, tmp_path):
    """The reader table's caveat, measured: dxf2gcode knows inches ($INSUNITS 1) and millimetres
    ($INSUNITS 4), and takes any other metric file ($MEASUREMENT 1) for millimetres."""
    path = tmp_path / "plate_cm.dxf"
    patterns.write(plate, path, units="cm")
    found = _dxf2gcode(path, tmp_path)
    assert found["metric"] is True  # read as mm: 1/10 of the size
    np.testing.assert_allclose(found["entities"]["CUT"]["areas"], sorted(p.area for p in _polygons(read(path), "CUT")),
                               rtol=1e-3)


@pytest.mark.parametrize("part", ["box", "cup", "square_to_round"])
def test_dxf2gcode_finds_each_astm_piece_closed(notched, tmp_path, part):
    _need("dxf2gcode")
    path = tmp_path / f"{part}_astm.dxf"
    patterns.write(notched[part], path, profile="astm", seam_allowance=10.0)
    found = _dxf2gcode(path, tmp_path)
    pieces = {name: layers for name, layers in found["blocks"].items() if not name.startswith("$")}
    assert sorted(pieces) == sorted(flat.name for flat in notched[part].panels)
    cut_lines = {name: ents for name, ents in _block_entities(read(path)).items()}
    for name, layers in pieces.items():
        assert layers["1"]["contours"] == layers["1"]["closed"] == 1
        (cut,) = [e for e in cut_lines[name] if e.dxftype() == "POLYLINE" and e.dxf.layer == "1"]
        area = shapely.Polygon([tuple(v.dxf.location)[:2] for v in cut.vertices]).area
        assert layers["1"]["areas"][0] == pytest.approx(area, rel=1e-3)  # true size


@pytest.mark.parametrize(("part", "allowance"), [
    ("box", 0.0), ("box", 10.0), ("box", "per seam"), ("square_to_round", 0.0), ("square_to_round", 10.0),
    ("square_to_round", "per seam"), ("plate", 0.0), ("plate", 10.0)])
def test_notches_along_the_seams_point_in_too(notched, tmp_path, part, allowance):
    """Notches every 40 mm of seam (not only at the ends, where the outline has corners), and with an
    allowance that changes from seam to seam (5 mm, 15 mm along the longest): each starts on the cut
    line and runs into the piece, square to its seam, within the allowance."""
    from patterns.pieces.notches import notch_positions

    pattern = notched[part]
    pattern = pattern.placed([(0.0, 1000.0 * k, 0.0) for k in range(len(pattern.panels))])
    if allowance == "per seam":
        longest = max(pattern.seams, key=lambda fs: fs.length).seam.id
        allowance = {None: 5.0, longest: 15.0}
    path = tmp_path / f"{part}.dxf"
    patterns.write(pattern, path, seam_allowance=allowance, notch_spacing=40.0)
    doc = read(path)
    cuts = _pieces(doc, "CUT")  # with their holes: notches on a hole's seam start on the hole's cut line
    sews = _pieces(doc, "SEW") if allowance else cuts
    lines = _notch_lines(doc)
    assert len(lines) > 4 * len(pattern.seams)  # more than the ends
    # each where notch_positions puts it, or half a millimetre along its seam (at a step of the cut line)
    shift = drawing_shift(doc.modelspace(), pattern, "SEW" if allowance else "CUT")
    marks = np.array([point + shift for fs in pattern.seams for side in (0, 1)
                      for _, point, _ in notch_positions(fs, side, pattern.panels[fs.seam.panels[side]].uv, 40.0)])
    ends = lines.reshape(-1, 2)
    assert len(lines) == len(marks)
    assert max(np.linalg.norm(marks - e, axis=1).min() for e in ends) > 1.0  # the outer ends: on the cut line
    inner = [min(np.linalg.norm(marks - a, axis=1).min(), np.linalg.norm(marks - b, axis=1).min()) for a, b in lines]
    assert max(inner) <= 0.5 + 1e-6
    for a, b in lines:
        mid = shapely.Point((a + b) / 2)
        cut = cuts[int(np.argmin([c.distance(mid) for c in cuts]))]
        sew = sews[int(np.argmin([s.distance(mid) for s in sews]))]
        on_cut = [cut.boundary.distance(shapely.Point(p)) < 1e-6 for p in (a, b)]
        assert any(on_cut)
        outer, inner = (a, b) if on_cut[0] else (b, a)
        if allowance:  # ends on the seam line (as drawn: its straight runs one segment within 0.001 mm)
            assert sew.boundary.distance(shapely.Point(inner)) < 1e-3
        for t in (0.25, 0.5, 0.75):
            q = shapely.Point(outer + t * (inner - outer))
            assert cut.contains(q) and cut.boundary.distance(q) > 1e-3
            if allowance:
                assert not sew.buffer(-1e-6).contains(q)
