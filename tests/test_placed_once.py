"""Labels placed and bends numbered once, when the pieces are made, and every writer only translates (issue 47,
item 2): the calls counted, the numbers the files carry compared with each other, and the labels a nest moved
checked against the moved piece with shapely.

The counters wrap the real functions (nothing is replaced): ``_placer`` places all of one piece's labels,
``flange_depths`` measures one bend's flanges for the bending order.
"""

from __future__ import annotations

import csv
import json
import re

import build123d as bd
import ezdxf
import numpy as np
import pytest
import shapely

import patterns
import patterns.bendsheet
import patterns.pieces.labels
from patterns.cli import main
from patterns.pieces.labels import text_box

from .conftest import SAMPLES
from .test_unfold import corrugated


@pytest.fixture
def counted(monkeypatch):
    """``{name: calls}`` of the label placer and the flange measure, counted while the test runs."""
    calls = {"placer": 0, "flange_depths": 0}
    placer, depths = patterns.pieces.labels._placer, patterns.bendsheet.flange_depths

    def counting_placer(*args, **kwargs):
        calls["placer"] += 1
        return placer(*args, **kwargs)

    def counting_depths(*args, **kwargs):
        calls["flange_depths"] += 1
        return depths(*args, **kwargs)

    monkeypatch.setattr(patterns.pieces.labels, "_placer", counting_placer)
    monkeypatch.setattr(patterns.bendsheet, "flange_depths", counting_depths)
    return calls


@pytest.fixture(scope="module")
def wavy(tmp_path_factory):
    path = tmp_path_factory.mktemp("wavy") / "wavy.step"
    bd.export_step(corrugated(waves=3, width=40.0)[0], str(path))
    return path


def test_an_unfold_that_writes_everything_numbers_its_bends_once_and_places_its_labels_once(wavy, tmp_path,
                                                                                             counted, capsys):
    """DXF, report, bend sheet and preview of one blank: one placing of its labels, one flange measure per bend
    (it was five orders and four placings)."""
    code = main(["unfold", str(wavy), "-o", str(tmp_path / "b.dxf"), "--report", str(tmp_path / "r.json"),
                 "--bend-sheet", str(tmp_path / "b.csv"), "--preview", str(tmp_path / "p.png")])
    assert code == 0, capsys.readouterr()
    report = json.loads((tmp_path / "r.json").read_text())
    (piece,) = report["pieces"]
    bends = len(piece["bends"])
    assert bends == 6
    assert counted == {"placer": 1, "flange_depths": bends}
    # the numbers the DXF's labels, the bend sheet, the report's blank and its piece carry are one numbering
    rows = list(csv.DictReader((tmp_path / "b.csv").open()))
    sheet = {(round(float(r["x1_mm"]), 3), round(float(r["y1_mm"]), 3)): int(r["sequence"]) for r in rows}
    drawn = {(round(b["line"][0][0], 3), round(b["line"][0][1], 3)): b["sequence"] for b in piece["bends"]}
    assert sheet == drawn and sorted(sheet.values()) == list(range(1, bends + 1))
    texts = [e.dxf.text for e in ezdxf.readfile(tmp_path / "b.dxf").modelspace().query("TEXT")]
    numbers = sorted(int(m.group(1)) for t in texts if (m := re.match(r"(\d+) (UP|DOWN) ", t)))
    assert numbers == list(range(1, bends + 1))
    assert sorted(b["sequence"] for b in report["blanks"][0]["bends"]) == list(range(1, bends + 1))


def test_a_flatten_that_writes_dxf_svg_and_report_places_each_pieces_labels_once(tmp_path, counted):
    pattern = patterns.flatten(patterns.load(SAMPLES / "cup.step"))
    drawing = patterns.pieces.drawing_of(pattern)
    assert counted["placer"] == len(drawing.pieces) == len(pattern.panels)
    _, checked = patterns.audit.checked_drawing(pattern, drawing, patterns.CheckOptions())
    for name in ("cup.dxf", "cup.svg"):
        patterns.write(drawing, tmp_path / name)
    patterns.write(checked, tmp_path / "cup.json")
    patterns.write(drawing, tmp_path / "cup_astm.dxf", profile="astm")  # ASTM places its own title block only
    assert counted["placer"] == len(pattern.panels)
    patterns.write(drawing, tmp_path / "cup_cm.dxf", units="cm")  # a drawing made for mm, written in cm: anew
    assert counted["placer"] == 2 * len(pattern.panels)
    said = json.loads((tmp_path / "cup.json").read_text())["pieces"]
    for kept, written in zip(drawing.pieces, said):
        assert [label.text for label in kept.labels.placed] == [label["text"] for label in written["labels"]]


def test_a_drawing_in_centimetres_is_labelled_once_in_centimetres(tmp_path, counted):
    """``patterns flatten -o x.dxf --units cm --report``: the seam labels are placed for their cm text, once per
    piece; the DXF and the report say the same texts, and each DXF text's glyphs lie inside their piece."""
    from ezdxf.addons import text2path

    step = tmp_path / "box.step"
    bd.export_step(bd.Box(200, 100, 50) - bd.Cylinder(20, 50), str(step))
    assert main(["flatten", str(step), "-o", str(tmp_path / "cm.dxf"), "--units", "cm", "--report",
                 str(tmp_path / "r.json")]) == 0
    report = json.loads((tmp_path / "r.json").read_text())
    assert counted["placer"] == len(report["pieces"])
    seam = re.compile(r"S(\d+) 3D ([\d.]+) FLAT ([\d.]+) CM")
    doc = ezdxf.readfile(tmp_path / "cm.dxf")
    texts = [t for t in doc.modelspace().query("TEXT") if seam.fullmatch(t.dxf.text)]
    said = [label["text"] for piece in report["pieces"] for label in piece["labels"] if label["kind"] == "seam"]
    assert sorted(t.dxf.text for t in texts) == sorted(said) and len(said) == 2 * len(report["seams"])
    for text in texts:
        number, three_d, _ = seam.fullmatch(text.dxf.text).groups()
        (length,) = [s["length_3d"] for s in report["seams"] if s["id"] == int(number)]
        assert float(three_d) == pytest.approx(length / 10, abs=5e-5)
    cuts = [shapely.Polygon([p[:2] for p in e.get_points("xy")])
            for e in doc.modelspace().query("LWPOLYLINE[layer=='CUT']")]
    for text in doc.modelspace().query("TEXT"):
        glyphs = shapely.MultiPoint([(v.x, v.y) for p in text2path.make_paths_from_entity(text)
                                     for v in p.flattening(0.0001)]).convex_hull
        assert any(c.contains(glyphs) for c in cuts), text.dxf.text


def test_labels_a_nest_turned_lie_inside_their_piece_clear_of_each_other():
    """Every piece of a nest, turned by the nester, keeps the labels placed when it was made, moved with it:
    each label's box (its own text, height and angle) inside the piece's finished outline, no two crossing."""
    pattern = patterns.flatten(patterns.load(SAMPLES / "cup.step"))
    flat = patterns.pieces.drawing_of(pattern)
    nest = patterns.layout(pattern, width=900.0, time_limit=1, rotations="free", copies=2, cache=False)
    turned = [p for p in nest.drawing().pieces if abs(np.degrees(p.placement.angle)) > 1]
    assert turned
    for piece in nest.drawing().pieces:
        placed = piece.labels.placed
        boxes = [text_box(label.text, label.at, label.height, label.angle) for label in placed]
        grown = piece.finished.buffer(1e-6)
        assert all(grown.contains(b) for b in boxes), piece.name
        assert not any(a.intersection(b).area > 1e-6 for i, a in enumerate(boxes) for b in boxes[i + 1:]), piece.name
        if piece.source.copy == 0:  # the piece itself: its labels are the unnested piece's, moved
            (original,) = [p for p in flat.pieces if p.name == piece.name]
            assert [label.text for label in placed] == [label.text for label in original.labels.placed]


def test_the_command_line_prints_the_labels_the_file_leaves_out(tmp_path, capsys):
    """An 8 mm cube: its faces hold few labels at 2 mm. The run's printout names the same left-out labels as
    the report's pieces (the first ten, then how many more), worked out once, on the pieces as written."""
    step = tmp_path / "cube.step"
    bd.export_step(bd.Box(8, 8, 8), str(step))
    assert main(["flatten", str(step), "-o", str(tmp_path / "cube.dxf"), "--report", str(tmp_path / "r.json")]) == 0
    out = capsys.readouterr().out.splitlines()
    report = json.loads((tmp_path / "r.json").read_text())
    notes = [f["message"] for piece in report["pieces"] for f in piece["findings"] if f["code"] == "label-left-out"]
    printed = [line[len("  note: "):] for line in out if "label" in line and line.startswith("  note: ")]
    assert len(notes) > 10 and printed == notes[:10]
    assert f"  ... and {len(notes) - 10} more labels left out (the report lists them)" in out
