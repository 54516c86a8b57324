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


def _drawing(path, outline, circles, *, turn=0.0, shift=(0.0, 0.0), mirror=False, slots=()):
    """A closed LWPOLYLINE and CIRCLEs ``(x, y, r)`` (and closed LWPOLYLINE ``slots``), mirrored in x = 0 if
    asked, turned by ``turn`` degrees about the origin, then moved by ``shift``, written by ezdxf."""
    c, s = np.cos(np.radians(turn)), np.sin(np.radians(turn))

    def moved(x, y):
        x = -x if mirror else x
        return (c * x - s * y + shift[0], s * x + c * y + shift[1])

    doc = ezdxf.new("R2000")
    msp = doc.modelspace()
    msp.add_lwpolyline([moved(x, y) for x, y in outline], close=True)
    for x, y, r in circles:
        msp.add_circle(moved(x, y), r)
    for slot in slots:
        msp.add_lwpolyline([moved(x, y) for x, y in slot], close=True)
    doc.saveas(path)
    return path


@pytest.mark.parametrize("turn, shift, mirror", [(0.0, (0.0, 0.0), False), (90.0, (200.0, 10.0), False),
                                                (-33.0, (-5.0, 70.0), False), (37.0, (300.0, -40.0), True)])
def test_each_place_that_differs_is_found_where_the_reference_has_it(tmp_path, turn, shift, mirror):
    ours = _drawing(tmp_path / "ours.dxf", RECT, [(20, 20, 2.1), (80, 40, 1.5), (60, 15, 3.0)], turn=turn, shift=shift,
                    mirror=mirror)
    theirs = _drawing(tmp_path / "theirs.dxf", SLOTTED, [(20, 20, 0.75), (60, 15, 3.0), (40, 45, 2.5)])
    c = patterns.compare_blank(ours, theirs)
    assert c.mirrored is mirror
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
    lines = {d.kind: d.describe("theirs.dxf") for d in c.differences}
    # the wording (the numbers are checked above)
    assert lines["outline"] == (f"outline at x {slot.x:.2f}, y {slot.y:.2f} mm: up to {slot.distance:.3f} mm apart "
                                f"over {slot.length:.1f} mm")
    assert lines["hole"] == ("hole at x 20.00, y 20.00 mm: Ø 4.20 in the blank, Ø 1.50 in theirs.dxf "
                             f"({hole.distance:.3f} mm apart)")
    assert lines["hole-ours"] == f"hole at x {extra.x:.2f}, y {extra.y:.2f} mm: Ø 3.00 in the blank, none in theirs.dxf"
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


@pytest.mark.parametrize("case", ["moved beside a small hole", "slot made longer"])
def test_a_hole_is_paired_with_its_own_not_a_nearer_small_one(tmp_path, case):
    """Of the reference holes a hole could be (its centre inside theirs, or theirs inside it) it is paired
    with the one most alike, and its distance is the pair's own Hausdorff distance (closed form here)."""
    if case == "moved beside a small hole":
        ours = _drawing(tmp_path / "ours.dxf", RECT, [(52.5, 30, 3.0), (10, 10, 1.0)])
        theirs = _drawing(tmp_path / "theirs.dxf", RECT, [(50, 30, 3.0), (54.5, 31, 0.3), (10, 10, 1.0)])
        want = [("hole", 50.0, 30.0, 2.5), ("hole-reference", 54.5, 31.0, 0.6)]
    else:
        wide = [(0, 0), (120, 0), (120, 60), (0, 60)]
        ours = _drawing(tmp_path / "ours.dxf", wide, [(55, 34.5, 1.0)],
                        slots=[[(10, 28), (100, 28), (100, 32), (10, 32)]])
        theirs = _drawing(tmp_path / "theirs.dxf", wide, [(55, 34.5, 1.0)],
                          slots=[[(10, 28), (90, 28), (90, 32), (10, 32)]])
        want = [("hole", 50.0, 30.0, 10.0)]
    c = patterns.compare_blank(ours, theirs)
    got = sorted((d.kind, d.x, d.y, d.distance) for d in c.differences)
    assert [g[0] for g in got] == [w[0] for w in want]
    for g, w in zip(got, want):
        assert g[1:3] == pytest.approx(w[1:3], abs=1e-3) and g[3] == pytest.approx(w[3], abs=SAMPLING)


def test_stretches_of_the_outline_apart_are_one_place_within_a_millimetre(tmp_path):
    """Two slots in the reference's top edge: 0.7 mm apart they are one place, 1.5 mm apart two."""
    for gap, places in ((0.7, 1), (1.5, 2)):
        x = 30.0 + 0.5 + gap
        top = [(x + 0.5, 60), (x + 0.5, 58), (x, 58), (x, 60), (30.5, 60), (30.5, 58), (30, 58), (30, 60)]
        theirs = _drawing(tmp_path / "theirs.dxf", [(0, 0), (100, 0), (100, 60), *top, (0, 60)], [(20, 20, 2.0)])
        ours = _drawing(tmp_path / "ours.dxf", RECT, [(20, 20, 2.0)])
        c = patterns.compare_blank(ours, theirs)
        assert [d.kind for d in c.differences] == ["outline"] * places, gap
        assert all(d.distance == pytest.approx(2.0, abs=SAMPLING) for d in c.differences)


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


def test_the_command_line_shows_ten_places_and_counts_the_rest(tmp_path, capsys):
    bd.export_step(bd.Box(100, 60, 2), str(tmp_path / "plate.step"))
    circles = [(10 + 8 * k, 30, 1.5) for k in range(11)] + [(10, 50, 1.0)]  # twelve holes the plate has not
    theirs = _drawing(tmp_path / "theirs.dxf", RECT, circles)
    assert main(["unfold", str(tmp_path / "plate.step"), "-o", str(tmp_path / "plate.dxf"), "--compare",
                 str(theirs)]) == 0
    out = capsys.readouterr().out
    assert out.count("differs: hole at") == 10
    assert "differs: 2 more places (the report lists every one)" in out
