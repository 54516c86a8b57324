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
    report, checked = patterns.audit.checked_drawing(pattern, drawing, patterns.CheckOptions())
    for name in ("cup.dxf", "cup.svg", "cup_cm.dxf"):
        patterns.write(drawing, tmp_path / name, units="cm" if "cm" in name else "mm")
    patterns.write(checked, tmp_path / "cup.json")
    patterns.write(drawing, tmp_path / "cup_astm.dxf", profile="astm")  # ASTM places its own title block only
    assert counted["placer"] == len(pattern.panels)
    said = json.loads((tmp_path / "cup.json").read_text())["pieces"]
    for kept, written in zip(drawing.pieces, said):
        assert [label.text for label in kept.labels.placed] == [label["text"] for label in written["labels"]]


def test_a_seam_label_in_centimetres_is_drawn_where_the_millimetre_one_is(tmp_path):
    """The place is kept for the widest unit's text: the cm file's seam labels sit where the mm file's do,
    say the same lengths in cm, and their glyphs lie inside their piece (read back, drawn by ezdxf)."""
    from ezdxf.addons import text2path

    pattern = patterns.flatten(patterns.load(bd.Box(200, 100, 50) - bd.Cylinder(20, 50)))
    patterns.write(pattern, tmp_path / "mm.dxf")
    patterns.write(pattern, tmp_path / "cm.dxf", units="cm")
    seam = re.compile(r"S(\d+) 3D ([\d.]+) FLAT ([\d.]+) (MM|CM)")
    mm = [(t.dxf.text, np.array(t.dxf.align_point)[:2]) for t in ezdxf.readfile(tmp_path / "mm.dxf").modelspace()
          .query("TEXT") if seam.fullmatch(t.dxf.text)]
    cm = ezdxf.readfile(tmp_path / "cm.dxf")
    cuts = [shapely.Polygon([p[:2] for p in e.get_points("xy")]) for e in cm.modelspace().query("LWPOLYLINE[layer=='CUT']")]
    seams = [t for t in cm.modelspace().query("TEXT") if seam.fullmatch(t.dxf.text)]
    assert len(seams) == len(mm) == 2 * len(pattern.seams)
    for text in seams:
        number, three_d, flat, unit = seam.fullmatch(text.dxf.text).groups()
        assert unit == "CM"
        at = np.array(text.dxf.align_point)[:2] * 10
        twins = [k for k, where in mm if np.allclose(where, at, atol=1e-6)]
        assert twins == [f"S{number} 3D {float(three_d) * 10:.2f} FLAT {float(flat) * 10:.2f} MM"], text.dxf.text
        glyphs = shapely.MultiPoint([(v.x, v.y) for p in text2path.make_paths_from_entity(text)
                                     for v in p.flattening(0.001)]).convex_hull
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
