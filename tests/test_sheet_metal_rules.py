"""A service bureau's checks of a blank (``patterns.sheetmetal.rules``): holes near bends, short flanges,
bends without relief, open contours.

The parts are drawn in build123d with known dimensions, and every measured distance is checked against the
hand computation from them: the bend zone's width ``pi / 2 (r + K t)``, the clearance ``3 t - allowance / 2``
(half a 6 t V-die from the bend's centre line), the flange's outside length ``flat + (r + t) tan(a / 2)``
against ``3 t / cos(a / 2)``.  The report is read back from the JSON the command line and ``patterns.write``
write.
"""

from __future__ import annotations

import json
from dataclasses import replace

import build123d as bd
import numpy as np
import pytest

import patterns
from patterns.cli import main
from patterns.sheetmetal.rules import manufacturability, open_contours

from .test_unfold import bent_strip

T, R, K, WIDTH = 1.0, 1.0, 0.47, 40.0  # the sheet, inside radius, K-factor and the flange's width, mm
ALLOWANCE = np.pi / 2 * (R + K * T)  # the 90 degree bend's developed width: 2.3091 mm
CLEARANCE = 3 * T - ALLOWANCE / 2  # half a 6 t V-die from the centre line, from the zone's edge: 1.8455 mm (> 1.5 t)


def bent(*, la: float, lb: float, r: float = R, t: float = T, width: float = WIDTH, angle: float = 90.0):
    """A strip bent once about the y axis: the base along -x (z in [-t, 0], la long), the bend's inside
    tangent line at x = 0, the flange lb long beyond the bend; y in [0, width] (test_unfold's strip)."""
    return bent_strip(la=la, lb=lb, r=r, t=t, width=width, angle=angle)


def _plate(x0, x1, y0, y1):
    return bd.Pos((x0 + x1) / 2, (y0 + y1) / 2, -T / 2) * bd.Box(x1 - x0, y1 - y0, T)


def tab(*, ears: float = 10.0, slot: float = 0.5, depth: float = 2.5, hole=None, la: float = 40.0,
        side: float = 20.0):
    """An L bracket whose 40 mm flange rises from a wider 80 mm base: the base runs on ``side`` mm past each
    end of the bend, and ``ears`` mm past its tangent line beside the flange; a relief slot ``slot`` mm wide cuts
    ``depth`` mm into the base at each end of the bend (none when ``slot`` is 0); ``hole`` = ((x, y), radius)."""
    part = bent(la=la, lb=20.0)
    part += _plate(-la, ears, -side, -slot) + _plate(-la, ears, WIDTH + slot, WIDTH + side)
    if slot:
        part += _plate(-la, -depth, -slot, 0) + _plate(-la, -depth, WIDTH, WIDTH + slot)
    if hole is not None:
        (x, y), radius = hole
        part -= bd.Pos(x, y, 0) * bd.Cylinder(radius, 4 * T)
    return part.clean()


def _beyond_the_end(gap: float, radius: float = 1.5):
    """A hole in the base beyond the end of the bend, level with the middle of its zone, ``gap`` mm from it."""
    return tab(hole=((ALLOWANCE / 2, WIDTH + gap + radius), radius))


def _codes(findings) -> list:
    return [f["code"] if isinstance(f, dict) else f.code.value for f in findings]


def test_a_hole_1_mm_beyond_the_end_of_a_bend_is_near_it_in_the_json_report(tmp_path, capsys):
    step = tmp_path / "L.step"
    bd.export_step(_beyond_the_end(1.0), str(step))
    assert main(["unfold", str(step), "-o", str(tmp_path / "l.dxf"), "--report", str(tmp_path / "l.json"),
                 "--k-factor", str(K)]) == 0  # a note: the blank is still cut
    assert (tmp_path / "l.dxf").is_file()
    assert "note: L: hole 0 (Ø 3.00 mm)" in capsys.readouterr().out
    blank = patterns.unfold(step, k_factor=K)
    patterns.write(blank, tmp_path / "api.json")
    for report in (json.loads((tmp_path / "l.json").read_text()), json.loads((tmp_path / "api.json").read_text())):
        (entry,) = report["blanks"]
        assert entry["ok"] and _codes(entry["findings"]) == ["hole-near-bend"]
        (finding,) = entry["findings"]
        assert finding["severity"] == "note"
        here, there = np.array(finding["points"])  # the hole's nearest point and the zone's
        assert np.linalg.norm(here - there) == pytest.approx(1.0, abs=2e-3)  # the circle sampled within 1 µm
        assert "hole 0 (Ø 3.00 mm)" in finding["message"] and "1.00 mm from the bend's zone" in finding["message"]
        assert f"needs {CLEARANCE:.2f} mm" in finding["message"] and finding["message"].startswith("L: ")
    # the zone's point lies on the zone's end: half the allowance from the bend's centre line at most, at its end
    (bend,) = blank.bends
    (finding,) = blank.findings
    end = min(bend.line, key=lambda p: np.linalg.norm(p - finding.points[1]))
    assert np.linalg.norm(finding.points[1] - end) <= ALLOWANCE / 2 + 1e-6


@pytest.mark.parametrize("gap, near", [(1.80, True), (1.90, False), (10.0, False)])
def test_a_hole_is_near_a_bend_within_half_a_6t_die_of_its_centre_line(gap, near):
    """The clearance is 3 t - allowance / 2 = 1.8455 mm from the zone here: 1.80 is too near, 1.90 is not; a hole
    10 mm away, and the bend relieved by its slots, give no finding at all."""
    blank = patterns.unfold(_beyond_the_end(gap), k_factor=K)
    assert _codes(blank.findings) == ([patterns.Code.HOLE_NEAR_BEND.value] if near else [])
    assert blank.ok
    if near:
        assert np.linalg.norm(np.subtract(*blank.findings[0].points)) == pytest.approx(gap, abs=2e-3)


@pytest.mark.parametrize("flat, short", [(2.2, True), (2.3, False)])
def test_a_flange_too_short_for_a_6t_die(flat, short):
    """A 90 degree flange's outside length is its flat beyond the zone plus (r + t) tan 45 = 2 mm; a 6 mm V-die
    needs 3 t / cos 45 = 4.243 mm: 2.2 mm of flat (4.2 mm outside) is short, 2.3 mm (4.3 mm) is not."""
    blank = patterns.unfold(bent(la=40.0, lb=flat), k_factor=K)
    assert _codes(blank.findings) == ([patterns.Code.SHORT_FLANGE.value] if short else [])
    if short:
        (finding,) = blank.findings
        assert np.linalg.norm(np.subtract(*finding.points)) == pytest.approx(flat, abs=1e-6)
        need = 3 * T / np.cos(np.pi / 4)
        assert f"is {flat + (R + T):.2f} mm long outside the bend ({flat:.2f} mm flat" in finding.message
        assert f"needs {need:.2f} mm" in finding.message and "UP 90.0° R1" in finding.message


def _box(x0, x1, y0, y1, z0, z1):
    return bd.Pos((x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2) * bd.Box(x1 - x0, y1 - y0, z1 - z0)


def test_a_flange_is_as_long_as_most_of_it():
    """The flange's length is the median over the bend: a 20 mm flange notched down to 1 mm over its last 2 mm
    at each end is long enough; a 2.2 mm flange with one 20 mm tab over a quarter of its width is short."""
    notched = bent(la=40.0, lb=20.0) - _box(R - 1, R + T + 1, -1, 2, R + 1, R + 30) \
        - _box(R - 1, R + T + 1, WIDTH - 2, WIDTH + 1, R + 1, R + 30)
    assert patterns.unfold(notched.clean(), k_factor=K).findings == ()
    tabbed = bent(la=40.0, lb=2.2) + _box(R, R + T, 15, 25, R + 1, R + 20)
    blank = patterns.unfold(tabbed.clean(), k_factor=K)
    assert _codes(blank.findings) == ["short-flange"]
    assert np.linalg.norm(np.subtract(*blank.findings[0].points)) == pytest.approx(2.2, abs=1e-6)


def test_a_bend_ending_beside_unbent_material_needs_a_relief():
    """A 40 mm flange off the edge of an 80 mm base, no relief: both ends of the bend tear into the base; the
    findings sit at the zone's corners on the base's side: 40 mm apart, half the allowance from the bend line."""
    blank = patterns.unfold(tab(ears=0.0, slot=0.0), k_factor=K)
    assert _codes(blank.findings) == [patterns.Code.MISSING_RELIEF.value] * 2
    (bend,) = blank.bends
    a, b = bend.line
    u = (b - a) / np.linalg.norm(b - a)
    corners = np.array([f.points[0] for f in blank.findings])
    assert np.linalg.norm(corners[0] - corners[1]) == pytest.approx(WIDTH, abs=1e-6)
    across = (corners - a) @ np.array([-u[1], u[0]])
    assert np.abs(across) == pytest.approx([ALLOWANCE / 2] * 2, abs=1e-6) and across[0] * across[1] > 0
    assert sorted((corners - a) @ u) == pytest.approx([0.0, WIDTH], abs=1e-6)
    assert all("cut a relief at least 0.50 mm wide and 2.51 mm deep" in f.message for f in blank.findings)


def test_a_relief_cut_at_each_end_of_the_bend_is_enough():
    """The same flange with a 0.5 mm slot 2.5 mm into the base at each end of the bend: no finding."""
    assert patterns.unfold(tab(ears=0.0, slot=0.5, depth=2.5), k_factor=K).findings == ()


def test_an_open_contour_is_an_error_and_nothing_is_written(tmp_path):
    """Where the cut contour stops, a blank is not cut: an error with both ends of the gap."""
    blank = patterns.unfold(bent(la=40.0, lb=20.0), k_factor=K)
    (finding,) = open_contours([[(10.0, 0.0), (10.0, 0.5)]], blank.name)
    assert finding.code is patterns.Code.OPEN_CONTOUR and finding.error
    assert finding.points.tolist() == [[10.0, 0.0], [10.0, 0.5]] and "0.500 mm" in finding.message
    broken = replace(blank, findings=(finding,))
    assert blank.ok and not broken.ok
    with pytest.raises(patterns.ExportError):
        patterns.write(broken, tmp_path / "open.dxf")
    assert not (tmp_path / "open.dxf").exists()


def test_the_rules_never_mutate_the_blank_and_take_their_die():
    """``manufacturability`` reads the blank; a wider die (8 t) asks more: the 1.9 mm hole is then too near
    (4 t - allowance / 2 = 2.85 mm)."""
    blank = patterns.unfold(_beyond_the_end(1.9), k_factor=K)
    before = blank.to_dict()
    assert manufacturability(blank) == ()
    (finding,) = manufacturability(blank, die_width=8.0)
    assert f"needs {4 * T - ALLOWANCE / 2:.2f} mm" in finding.message
    assert blank.to_dict() == before


def test_a_hole_that_bites_into_a_bend_zone_is_near_it_at_0_mm():
    """A Ø3 hole drilled 0.5 mm past the base's tangent line cuts into the bend from one side: it is the worst
    case of a hole near a bend (0 mm), not a relief (which would cross the zone, or run over its end)."""
    blank = patterns.unfold(tab(hole=((-1.0, WIDTH / 2), 1.5)), k_factor=K)
    near = [f for f in blank.findings if f.code is patterns.Code.HOLE_NEAR_BEND]
    assert len(near) == 1 and "inside the bend's zone" in near[0].message
    assert np.linalg.norm(np.subtract(*near[0].points)) == pytest.approx(0.0, abs=1e-9)
