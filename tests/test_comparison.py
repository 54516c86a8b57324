"""Where a blank and another CAD's flat pattern differ: ``BlankComparison.differences``.

The drawings are written by ezdxf with known features (a slot, holes of other sizes, holes only one of
them has), so every place, size and distance is known in closed form; ours is also turned and moved, and
the places must come out in the reference drawing's coordinates all the same.
"""

import json

import build123d as bd
import ezdxf
import numpy as np
import pytest

import patterns
from patterns.cli import main

RECT = [(0, 0), (100, 0), (100, 60), (0, 60)]
# The reference's outline has a slot 0.5 wide and 2 deep in its top edge, between x 10 and 10.5.
SLOTTED = [(0, 0), (100, 0), (100, 60), (10.5, 60), (10.5, 58), (10, 58), (10, 60), (0, 60)]
SAMPLING = 0.02  # the comparison measures contours resampled this finely (mm)


def _drawing(path, outline, circles, *, turn=0.0, shift=(0.0, 0.0)):
    """A closed LWPOLYLINE and CIRCLEs ``(x, y, r)``, turned by ``turn`` degrees about the origin, then
    moved by ``shift``, written by ezdxf."""
    c, s = np.cos(np.radians(turn)), np.sin(np.radians(turn))

    def moved(x, y):
        return (c * x - s * y + shift[0], s * x + c * y + shift[1])

    doc = ezdxf.new("R2000")
    msp = doc.modelspace()
    msp.add_lwpolyline([moved(x, y) for x, y in outline], close=True)
    for x, y, r in circles:
        msp.add_circle(moved(x, y), r)
    doc.saveas(path)
    return path


@pytest.mark.parametrize("turn, shift", [(0.0, (0.0, 0.0)), (90.0, (200.0, 10.0)), (-33.0, (-5.0, 70.0))])
def test_each_place_that_differs_is_found_where_the_reference_has_it(tmp_path, turn, shift):
    ours = _drawing(tmp_path / "ours.dxf", RECT, [(20, 20, 2.1), (80, 40, 1.5), (60, 15, 3.0)], turn=turn, shift=shift)
    theirs = _drawing(tmp_path / "theirs.dxf", SLOTTED, [(20, 20, 0.75), (60, 15, 3.0), (40, 45, 2.5)])
    c = patterns.compare_blank(ours, theirs)
    assert not c.mirrored
    by_kind = {d.kind: d for d in c.differences}
    assert sorted(by_kind) == ["hole", "hole-ours", "hole-reference", "outline"]  # one each; the Ø 6 at (60, 15) agrees
    assert len(c.differences) == 4
    slot = by_kind["outline"]
    assert slot.distance == pytest.approx(2.0, abs=SAMPLING)  # the slot's depth
    assert 10.0 <= slot.x <= 10.5 and 58.0 <= slot.y <= 60.0
    # what lies more than 0.1 mm from the other outline: the slot's two sides below 0.1 mm of the top edge,
    # its bottom, and the stretch of our edge across its mouth more than 0.1 mm from either side
    assert slot.length == pytest.approx(2 * (2.0 - 0.1) + 0.5 + (0.5 - 2 * 0.1), abs=5 * SAMPLING)
    hole = by_kind["hole"]
    assert (hole.x, hole.y) == pytest.approx((20.0, 20.0), abs=1e-6)
    assert (hole.size, hole.size_reference) == pytest.approx((4.2, 1.5), rel=1e-3)
    assert hole.distance == pytest.approx(2.1 - 0.75, abs=SAMPLING)
    extra, missing = by_kind["hole-ours"], by_kind["hole-reference"]
    assert (extra.x, extra.y, extra.size, extra.size_reference) == pytest.approx((80.0, 40.0, 3.0, 0.0), abs=1e-2)
    assert (missing.x, missing.y, missing.size, missing.size_reference) == pytest.approx((40.0, 45.0, 0.0, 5.0),
                                                                                        abs=1e-2)
    assert [d.distance for d in c.differences] == sorted((d.distance for d in c.differences), reverse=True)
    assert c.to_dict()["differences"][0] == {
        "kind": c.differences[0].kind, "x_mm": c.differences[0].x, "y_mm": c.differences[0].y,
        "distance_mm": c.differences[0].distance, "length_mm": c.differences[0].length,
        "size_mm": c.differences[0].size, "size_reference_mm": c.differences[0].size_reference}


def test_the_same_drawing_differs_nowhere(tmp_path):
    ours = _drawing(tmp_path / "ours.dxf", SLOTTED, [(20, 20, 2.1), (60, 15, 3.0)], turn=180.0, shift=(7, 7))
    theirs = _drawing(tmp_path / "theirs.dxf", SLOTTED, [(20, 20, 2.1), (60, 15, 3.0)])
    c = patterns.compare_blank(ours, theirs)
    assert c.differences == () and c.hausdorff_all < SAMPLING  # the contours resampled from other starts


def test_two_holes_drawn_off_centre_are_one_hole_moved(tmp_path):
    """A hole 0.3 mm from where the reference has it (its centre inside the other) is one hole, 0.3 mm apart;
    a hole as large but 10 mm away is two: one only ours, one only theirs."""
    ours = _drawing(tmp_path / "ours.dxf", RECT, [(20.3, 20, 2.0), (70, 30, 2.0), (50, 10, 1.0), (90, 50, 1.0)])
    theirs = _drawing(tmp_path / "theirs.dxf", RECT, [(20, 20, 2.0), (80, 30, 2.0), (50, 10, 1.0), (90, 50, 1.0)])
    c = patterns.compare_blank(ours, theirs)
    kinds = sorted((d.kind, round(d.x), round(d.y)) for d in c.differences)
    assert kinds == [("hole", 20, 20), ("hole-ours", 70, 30), ("hole-reference", 80, 30)]
    (moved,) = [d for d in c.differences if d.kind == "hole"]
    assert moved.distance == pytest.approx(0.3, abs=SAMPLING)


def test_the_command_line_says_where_and_the_report_lists_them(tmp_path, capsys):
    """``patterns unfold PART --compare THEIRS.dxf`` names each place in one line; the report has them all."""
    bd.export_step(bd.Box(100, 60, 2), str(tmp_path / "plate.step"))
    theirs = _drawing(tmp_path / "theirs.dxf", RECT, [(70, 30, 2.0)])
    report = tmp_path / "plate.json"
    assert main(["unfold", str(tmp_path / "plate.step"), "-o", str(tmp_path / "plate.dxf"), "--compare", str(theirs),
                 "--report", str(report)]) == 0
    out = capsys.readouterr().out
    assert "differs: hole at x 70.00, y 30.00 mm: none in the blank, Ø 4.00 in theirs.dxf" in out
    (entry,) = json.loads(report.read_text())["comparison"]["differences"]
    assert entry["kind"] == "hole-reference" and entry["size_reference_mm"] == pytest.approx(4.0, rel=1e-3)  # arcs read as chords
    assert (entry["x_mm"], entry["y_mm"]) == pytest.approx((70.0, 30.0), abs=1e-6)
