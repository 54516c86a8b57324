"""The torture set widened to what shops meet: hems, jogs, cuts across a bend, flanges nearly touching, formed
features (issue: "Widen the torture set to what shops meet").

Every part is built here with build123d, in mm, and every reference is computed by hand from the dimensions
chosen, never from the unfolder:

* a sheet bent along a centre line of straight runs and bends develops to ``sum(L) + sum(angle (r + K t))``
  (the neutral layer: flat lengths plus each bend's neutral arc), times its width;
* a slot across a bend develops to the same neutral lengths (its sides are square to the bend axis);
* a round hole drilled along a bend's bisector develops, on the neutral layer, to the curve traced by
  intersecting the drill with the neutral surface (closed form per point, :func:`_drilled_trace`);
* a tray corner whose flanges stop 0.3 mm apart develops to its base, bend zones and flanges, and must be one
  simple contour (no self-overlap);
* a dimple and a louver (spheres and tori: formed, doubly curved) have no developed length at all: the unfold
  must refuse them or name their formed faces, never flatten them silently.

A drilled hole's wall is not square to the sheet: the unfold draws its trace on the neutral layer and says so
(an ``oblique-cut`` note with both areas).
"""

from __future__ import annotations

import re
from pathlib import Path

import build123d as bd
import numpy as np
import pytest
import shapely

import patterns
from patterns.cli import main
from patterns.errors import InputError

# --------------------------------------------------------------------------- #
# Builders (pure functions, mm)
# --------------------------------------------------------------------------- #


def _rotate(v, a):
    return np.array([v[0] * np.cos(a) - v[1] * np.sin(a), v[0] * np.sin(a) + v[1] * np.cos(a)])


def profile_solid(segments, *, t: float, width: float):
    """A sheet of thickness ``t`` laid t/2 either side of a centre line in the x-z plane, extruded ``width``
    along +y.  ``segments``: ``("line", length)`` or ``("arc", turn degrees (+ left, - right), inside radius)``,
    tangent one to the next.  The centre line starts at (0, -t/2) heading +x (the first flat is z in [-t, 0])."""
    p, phi = np.array([0.0, -t / 2]), 0.0
    left, right = [], []  # ("line", a, b) or ("arc", a, mid, b) per segment, each skin
    for seg in segments:
        h = np.array([np.cos(phi), np.sin(phi)])
        n = np.array([-h[1], h[0]])
        if seg[0] == "line":
            q = p + seg[1] * h
            left.append(("line", p + t / 2 * n, q + t / 2 * n))
            right.append(("line", p - t / 2 * n, q - t / 2 * n))
            p = q
        else:
            turn, r = np.radians(seg[1]), seg[2]
            c = p + np.sign(turn) * (r + t / 2) * n  # the bend axis
            for side, off in ((left, t / 2), (right, -t / 2)):
                a0 = p + off * n
                side.append(("arc", a0, c + _rotate(a0 - c, turn / 2), c + _rotate(a0 - c, turn)))
            p = c + _rotate(p - c, turn)
            phi += turn

    def to3(v):
        return float(v[0]), 0.0, float(v[1])

    def edge(piece, reverse=False):
        pts = piece[1:][::-1] if reverse else piece[1:]
        if piece[0] == "line":
            return bd.Edge.make_line(to3(pts[0]), to3(pts[1]))
        return bd.Edge.make_three_point_arc(*map(to3, pts))

    edges = [edge(s) for s in left] + [bd.Edge.make_line(to3(left[-1][-1]), to3(right[-1][-1]))]
    edges += [edge(s, reverse=True) for s in right[::-1]] + [bd.Edge.make_line(to3(right[0][1]), to3(left[0][1]))]
    return bd.extrude(bd.Face(bd.Wire(edges)), amount=width, dir=(0, 1, 0))


def developed_length(segments, *, t: float, k: float) -> float:
    """The neutral layer's length: every straight run plus ``|angle| (r + k t)`` per bend."""
    return sum(s[1] if s[0] == "line" else np.radians(abs(s[1])) * (s[2] + k * t) for s in segments)


PROFILES = {  # (segments, thickness, width): hems and jogs
    # 180 degrees back on itself, inside radius 1 = t: the return flange 2 mm (2 r) above the base
    "open_hem": ([("line", 40.0), ("arc", 180.0, 1.0), ("line", 12.0)], 1.0, 30.0),
    # 180 degrees, inside radius 0.01 mm: the two flanges 0.02 mm apart (build123d makes it down to 1e-4 mm)
    "closed_hem": ([("line", 40.0), ("arc", 180.0, 0.01), ("line", 12.0)], 1.0, 30.0),
    # 225 degrees about R2: the return flange leans back towards the base (1.3 mm clear of it)
    "teardrop_hem": ([("line", 40.0), ("arc", 225.0, 2.0), ("line", 3.0)], 1.0, 30.0),
    # a Z jog: up 60, a 1 mm web, down 60 (R1.5, t 1.5): offset 2 (r + t/2)(1 - cos 60) + sin 60 = 3.12 mm = 2.1 t
    "jog": ([("line", 30.0), ("arc", 60.0, 1.5), ("line", 1.0), ("arc", -60.0, 1.5), ("line", 30.0)], 1.5, 40.0),
    # an S jog: up 90 and straight down 90 with no flat between (offset 2 (r + t/2) = 4.5 mm = 3 t)
    "s_jog": ([("line", 30.0), ("arc", 90.0, 1.5), ("arc", -90.0, 1.5), ("line", 30.0)], 1.5, 40.0),
}


def profile_part(name: str):
    segments, t, width = PROFILES[name]
    return profile_solid(segments, t=t, width=width)


# the L strip the cuts go across: flange A 40 (x in [0, 40], z in [-t, 0]), a 90-degree bend about the axis
# x = 40, z = r, flange B 30 high above z = r (x in [40 + r, 40 + r + t]); 40 wide (y in [0, 40])
LA, LB, R_L, T_L, W_L = 40.0, 30.0, 2.0, 1.5, 40.0
L_SEGMENTS = [("line", LA), ("arc", 90.0, R_L), ("line", LB)]


def slot_across_bend(*, a=10.0, h=15.0, w=6.0, y0=17.0):
    """The L strip with an obround slot ``w`` wide across its bend: straight sides in the planes y = y0 and
    y0 + w (square to the bend axis), a round end drilled square to flange A ``a`` before the bend, the other
    drilled square to flange B at height ``h`` (z, from flange A's inside face)."""
    part = profile_solid(L_SEGMENTS, t=T_L, width=W_L)
    yc = y0 + w / 2
    box = bd.Pos(LA - a, y0, -T_L - 5) * bd.Box(a + R_L + T_L + 5, w, h + T_L + 5,
                                                align=(bd.Align.MIN, bd.Align.MIN, bd.Align.MIN))
    end_a = bd.Pos(LA - a, yc, 0) * bd.Cylinder(w / 2, 4 * T_L)
    end_b = bd.Pos(LA + R_L + T_L / 2, yc, h) * bd.Rot(0, 90, 0) * bd.Cylinder(w / 2, 4 * T_L)
    return part - box - end_a - end_b


def hole_across_bend(*, d=10.0, yc=20.0):
    """The L strip with a round hole of diameter ``d`` drilled through the bend along its outside bisector
    (direction (1, 0, -1) / sqrt 2 through the bend axis): it cuts the bend and both flanges."""
    part = profile_solid(L_SEGMENTS, t=T_L, width=W_L)
    drill = bd.Cylinder(d / 2, 40, align=(bd.Align.CENTER, bd.Align.CENTER, bd.Align.CENTER))
    return part - bd.Pos(LA, yc, R_L) * bd.Rot(0, 135, 0) * drill


def _drilled_trace(delta: float, *, k: float, d=10.0, n=20000) -> float:
    """The developed area of the drilled hole's trace on the layer ``delta`` mm into the sheet from the inside
    skin (0: inside skin, k t: neutral layer, t: outside skin), each layer developed as the neutral layer is
    (flange A from the bend's start, the bend by its angle times r + k t, flange B after it).

    A line of the drill's wall, a = (d/2) sin(psi) off the axis across the bend (along (1, 0, 1) / sqrt 2) and
    (d/2) cos(psi) along it, meets the layer (radius rho = r + delta about the bend axis) in the bend where
    lambda = sqrt(rho^2 - a^2) (X = (a + lambda) / sqrt 2 > 0, Z = (a - lambda) / sqrt 2 < 0), on flange A at
    X = sqrt 2 a + rho when a <= -rho / sqrt 2, on flange B at Z = sqrt 2 a - rho when a >= rho / sqrt 2."""
    rn, rho, s2 = R_L + k * T_L, R_L + delta, np.sqrt(2.0)
    psi = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    a, y = d / 2 * np.sin(psi), d / 2 * np.cos(psi)
    lam = np.sqrt(np.clip(rho**2 - a**2, 0.0, None))
    x_, z_ = (a + lam) / s2, (a - lam) / s2
    in_bend = (np.abs(a) < rho) & (x_ > 0) & (z_ < 0)
    s = np.where(in_bend, np.arctan2(x_, -z_) * rn,
                 np.where(a < 0, s2 * a + rho, np.pi / 2 * rn + s2 * a - rho))
    assert np.all(in_bend | (a <= -rho / s2) | (a >= rho / s2))
    return 0.5 * abs(float(np.dot(s, np.roll(y, -1)) - np.dot(y, np.roll(s, -1))))


def near_corner(*, L=40.0, H=15.0, r=1.0, t=1.0, g=0.3):
    """A tray corner: a base L x L (z in [-t, 0]), a flange bent up 90 degrees (inside radius r) to height H on
    its x = L edge and another on its y = L edge; the bends stop at the corner (an open relief).  Flange 1
    runs on past the corner to y = L + r + t (flush with flange 2's outside); flange 2 stops ``g`` short of
    flange 1's inside face (at x = L + r - g)."""
    prof = [("line", L), ("arc", 90.0, r), ("line", H - r)]
    along_x = profile_solid(prof, t=t, width=L)
    along_y = bd.Rot(0, 0, 90) * bd.mirror(profile_solid(prof, t=t, width=L), bd.Plane.XZ)
    run_on_1 = bd.Pos(L + r, L, r) * bd.Box(t, r + t, H - r, align=(bd.Align.MIN, bd.Align.MIN, bd.Align.MIN))
    run_on_2 = bd.Pos(L, L + r, r) * bd.Box(r - g, t, H - r, align=(bd.Align.MIN, bd.Align.MIN, bd.Align.MIN))
    return (along_x + along_y + run_on_1 + run_on_2).clean()


def _round_form(*, a, f, rs, t, up):
    """The section (x = radius, z) of a round formed feature of constant thickness t, radius 0 to a + 5: one
    skin flat out from radius a, a torus fillet (radius f) then a spherical cap (radius rs) to the axis; the
    other skin its offset by t (fillet f - t, cap rs + t).  Pressed down from a sheet z in [-t, 0], or
    mirrored (``up``: a sheet z in [0, t], raised)."""
    zc = -f + np.sqrt((f + rs) ** 2 - a**2)  # the cap's centre (0, zc): tangent to the fillet circle (a, -f)
    c1, c2 = np.array([a, -f]), np.array([0.0, zc])
    beta = np.arcsin(a / (f + rs))  # the angle the fillet turns through
    sgn = -1.0 if up else 1.0

    def P(v):
        return float(v[0]), 0.0, float(sgn * v[1])

    def arc(c, rad, a0, a1):
        return bd.Edge.make_three_point_arc(*(P(c + rad * np.array([np.cos(x), np.sin(x)]))
                                              for x in (a0, 0.5 * (a0 + a1), a1)))

    rim = a + 5.0
    edges = [bd.Edge.make_line(P((rim, 0.0)), P((a, 0.0))),
             arc(c1, f, np.pi / 2, np.pi / 2 + beta), arc(c2, rs, -np.pi / 2 + beta, -np.pi / 2),
             bd.Edge.make_line(P((0.0, zc - rs)), P((0.0, zc - rs - t))),
             arc(c2, rs + t, -np.pi / 2, -np.pi / 2 + beta), arc(c1, f - t, np.pi / 2 + beta, np.pi / 2),
             bd.Edge.make_line(P((a, -t)), P((rim, -t))), bd.Edge.make_line(P((rim, -t)), P((rim, 0.0)))]
    return bd.Face(bd.Wire(edges))


FORM = {"a": 8.0, "f": 3.0, "rs": 15.0, "t": 1.0}
"""The round form: it leaves the plate at radius 8 on an R3 fillet into an R15 cap, 1.875 mm deep, in 1 mm
sheet (depth rs + f - sqrt((f + rs)^2 - a^2))."""


def dimple(side=60.0):
    """A plate side x side, 1 mm (z in [-1, 0]), with the round form pressed down into its middle (a full
    revolution: one torus and one sphere a skin)."""
    cup = bd.revolve(_round_form(**FORM, up=False), axis=bd.Axis.Z)
    plate = bd.Box(side, side, FORM["t"], align=(bd.Align.CENTER, bd.Align.CENTER, bd.Align.MAX))
    return (plate - bd.Cylinder(FORM["a"] + 5.0, 4.0) + cup).clean()


def louver(side=60.0):
    """A louver: the round form raised as a hood on the half y > 0, lanced along the diameter y = 0 with the
    half y < 0 cut away (the opening under the hood)."""
    hood = bd.Pos(0, 0, -FORM["t"]) * bd.revolve(_round_form(**FORM, up=True), axis=bd.Axis.Z)
    plate = bd.Box(side, side, FORM["t"], align=(bd.Align.CENTER, bd.Align.CENTER, bd.Align.MAX))
    part = plate - bd.Cylinder(FORM["a"] + 5.0, 4.0) + hood
    opening = bd.Pos(0, -FORM["a"], 0) * bd.Box(2 * FORM["a"], 2 * FORM["a"], 40) & bd.Cylinder(FORM["a"], 40)
    return (part - opening).clean()


def _formed_faces(part) -> set:
    return {i for i, f in enumerate(part.faces()) if f.geom_type in (bd.GeomType.SPHERE, bd.GeomType.TORUS)}


def _cli(part, name: str, tmp_path: Path, capsys) -> tuple:
    """``patterns unfold NAME.step -o NAME.dxf --k-factor 0.5``: (exit code, stderr, the DXF or None)."""
    step = tmp_path / f"{name}.step"
    bd.export_step(part, str(step))
    out = tmp_path / f"{name}.dxf"
    code = main(["unfold", str(step), "-o", str(out), "--k-factor", "0.5"])
    return code, capsys.readouterr().err, out if out.exists() else None


# --------------------------------------------------------------------------- #
# Hems and jogs: exact neutral development
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize("k", [0.5, 0.4])
@pytest.mark.parametrize("name", sorted(PROFILES))
def test_hems_and_jogs_develop_to_their_neutral_length(name, k):
    """Area ``(sum L + sum angle (r + k t)) x width``, size the same, one bend per arc with its own angle,
    inside radius and neutral allowance: open hem 40 + 12 + pi (1 + k), closed hem 40 + 12 + pi (0.01 + k),
    teardrop 40 + 3 + 5 pi / 4 (2 + k), jog 30 + 1 + 30 + 2 pi / 3 (1.5 + 1.5 k), S jog 60 + pi (1.5 + 1.5 k)."""
    segments, t, width = PROFILES[name]
    length = developed_length(segments, t=t, k=k)
    blank = patterns.unfold(profile_part(name), k_factor=k, name=name)
    assert blank.ok and blank.holes == ()
    assert blank.thickness == pytest.approx(t, rel=1e-9)
    assert blank.area == pytest.approx(length * width, rel=1e-9)
    assert blank.perimeter == pytest.approx(2 * (length + width), rel=1e-9)
    assert sorted(blank.size) == pytest.approx(sorted([length, width]), abs=1e-6)
    arcs = [s for s in segments if s[0] == "arc"]
    assert len(blank.bends) == len(arcs)
    for bend, (_, angle, r) in zip(sorted(blank.bends, key=lambda b: b.angle), sorted(arcs, key=lambda s: abs(s[1]))):
        assert bend.angle == pytest.approx(abs(angle), abs=1e-9)
        assert bend.inside_radius == pytest.approx(r, abs=1e-9)
        assert bend.allowance == pytest.approx(np.radians(abs(angle)) * (r + k * t), rel=1e-9)
        assert np.linalg.norm(bend.line[1] - bend.line[0]) == pytest.approx(width, abs=1e-6)
    if name in ("jog", "s_jog"):  # one bend up, the other down
        assert sorted(b.direction for b in blank.bends) == ["down", "up"]


def test_s_jog_says_its_bends_have_no_flat_between():
    """The S jog's two bends meet with no flat between them: each is a ``bend-without-flange`` note."""
    blank = patterns.unfold(profile_part("s_jog"), k_factor=0.5, name="s_jog")
    notes = [f for f in blank.findings if f.code is patterns.Code.BEND_WITHOUT_FLANGE]
    assert len(notes) == 2 and all(f.severity is patterns.Severity.NOTE for f in notes)


# --------------------------------------------------------------------------- #
# Cuts across a bend
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize("k", [0.5, 0.4])
def test_slot_across_a_bend_develops_to_its_neutral_length(k):
    """The slot is w = 6 wide and, centre to centre of its round ends, a = 10 on flange A + the bend's neutral
    arc pi / 2 (2 + 1.5 k) + h - r = 15 - 2 on flange B: its area w Lc + pi w^2 / 4; the blank the strip's
    (40 + 30 + pi / 2 (2 + 1.5 k)) x 40 less it.  The bend, cut in two by the slot, is two bends on one line
    (17 mm each side of the slot)."""
    w = 6.0
    allowance = np.pi / 2 * (R_L + k * T_L)
    lc = 10.0 + allowance + (15.0 - R_L)
    slot = w * lc + np.pi * w**2 / 4
    strip = (LA + LB + allowance) * W_L
    blank = patterns.unfold(slot_across_bend(), k_factor=k, name="slot")
    assert blank.ok and len(blank.holes) == 1
    assert blank.holes[0].area == pytest.approx(slot, rel=1e-9)
    assert blank.area == pytest.approx(strip - slot, rel=1e-9)
    assert sorted(blank.size) == pytest.approx(sorted([LA + LB + allowance, W_L]), abs=1e-6)
    assert blank.holes[0].length == pytest.approx(2 * lc + np.pi * w, rel=1e-9)  # arcs as arcs
    assert len(blank.bends) == 2
    a, b = blank.bends
    d = (a.line[1] - a.line[0]) / np.linalg.norm(a.line[1] - a.line[0])
    for end in b.line:  # b's ends on a's line
        v = end - a.line[0]
        assert abs(d[0] * v[1] - d[1] * v[0]) < 1e-6
    assert sorted(np.linalg.norm(x.line[1] - x.line[0]) for x in blank.bends) == pytest.approx([17.0, 17.0], abs=1e-6)


def test_drilled_trace_reference_is_ordered_and_converged():
    """The reference's own checks: the layers' traces shrink from the inside skin out (the drill meets the
    inside skin farther from the bend), and 20000 points converge (to 1e-7 against 80000)."""
    inside, neutral, outside = (_drilled_trace(d, k=0.5) for d in (0.0, 0.75, 1.5))
    assert inside > neutral > outside
    assert neutral == pytest.approx(_drilled_trace(0.75, k=0.5, n=80000), rel=1e-7)  # converged


@pytest.mark.parametrize("k", [0.5, 0.4])
def test_hole_drilled_across_a_bend_develops_on_its_neutral_layer(k):
    """A 10 mm hole drilled along the bend's outside bisector: its blank hole is the drill's trace on the
    neutral layer, developed (:func:`_drilled_trace`, 99.472 mm2 at K 0.5, 100.084 at K 0.4; within 2e-5: the
    blank samples the trace as polylines of 0.02 um chord error), the same which flat face is fixed (the inside
    skin's trace is 114.166 mm2, the outside skin's 85.224), and an ``oblique-cut`` note gives both areas."""
    part = hole_across_bend()
    blank = patterns.unfold(part, k_factor=k, name="hole")
    (hole,) = blank.holes
    neutral = _drilled_trace(k * T_L, k=k)
    assert hole.area == pytest.approx(neutral, rel=2e-5)
    other = patterns.unfold(part, k_factor=k, name="hole", fixed_face=0)  # the inside skin of flange A
    assert other.holes[0].area == pytest.approx(neutral, rel=2e-5)
    assert other.area == pytest.approx(blank.area, rel=1e-6)
    strip = (LA + LB + np.pi / 2 * (R_L + k * T_L)) * W_L
    assert blank.area == pytest.approx(strip - neutral, rel=1e-6)
    for b, skin in ((blank, _drilled_trace(T_L, k=k)), (other, _drilled_trace(0.0, k=k))):
        (note,) = [f for f in b.findings if f.code is patterns.Code.OBLIQUE_CUT]
        assert note.severity is patterns.Severity.NOTE and b.ok
        assert f"neutral layer, {neutral:.2f} mm²" in note.message
        drawn = float(re.search(r"the fixed face's trace ([0-9.]+) mm²", note.message).group(1))
        assert drawn == pytest.approx(skin, rel=1e-3)  # that trace sampled at 1 um chord error
        assert shapely.Point(note.points[0]).within(b.holes[0].polygon)


def test_square_cuts_across_a_bend_are_not_redrawn():
    """The slot's walls are square to the sheet (its sides square to the bend axis, its ends drilled square to
    their flanges): drawn from the fixed face as before, arcs as arcs, and no ``oblique-cut`` note."""
    blank = patterns.unfold(slot_across_bend(), k_factor=0.5, name="slot")
    assert not [f for f in blank.findings if f.code is patterns.Code.OBLIQUE_CUT]
    assert sum(type(p).__name__ == "Arc" for p in blank.holes[0].pieces) == 2


def _neutral_profile(segments, *, t: float, k: float) -> list:
    """The neutral layer of a :func:`profile_solid` profile in the x-z plane, piece by piece, with where each
    piece starts on the blank (``s``, mm along the neutral layer): ``("arc", centre, radius, start angle, turn,
    s)`` within a bend (radius ``r + k t`` about its axis), ``("line", a, b, s)`` along a flat, from where the
    bend before it ends to where the bend after it starts (the same depth as those bends' neutral layers: a flat
    between two bends of different depth, the web of a jog at K 0.4, tilts from one to the other), developed by
    its length along the flat."""
    p, phi, pieces, s = np.array([0.0, -t / 2]), 0.0, [], 0.0
    offsets = []  # the neutral layer's offset from the centre line at each bend, + to the left
    for seg in segments:
        if seg[0] == "arc":
            offsets.append(np.sign(seg[1]) * (t / 2 - k * t))
    bend = 0
    for seg in segments:
        h = np.array([np.cos(phi), np.sin(phi)])
        n = np.array([-h[1], h[0]])
        if seg[0] == "line":
            before = offsets[max(bend - 1, 0)] if bend > 0 else offsets[0]
            after = offsets[bend] if bend < len(offsets) else offsets[-1]
            q = p + seg[1] * h
            pieces.append(("line", p + before * n, q + after * n, s, seg[1]))
            s += seg[1]
            p = q
        else:
            turn, r = np.radians(seg[1]), seg[2]
            c = p + np.sign(turn) * (r + t / 2) * n
            rn = r + k * t
            start = p + offsets[bend] * n - c
            pieces.append(("arc", c, rn, float(np.arctan2(start[1], start[0])), float(turn), s))
            s += abs(turn) * rn
            p = c + _rotate(p - c, turn)
            phi += turn
            bend += 1
    return pieces


def _crossing(pieces: list, c: np.ndarray, a: np.ndarray, keep=None) -> tuple:
    """Where the line ``c + lambda a`` of the x-z plane crosses the neutral layer ``pieces`` (the one crossing,
    of those whose point ``keep(point)`` keeps when given: asserted): ``(s, lambda)``, ``s`` on the blank."""
    found = []
    for piece in pieces:
        if piece[0] == "line":
            _, p0, p1, s0, length = piece
            e = p1 - p0
            m = np.array([[a[0], -e[0]], [a[1], -e[1]]])
            if abs(np.linalg.det(m)) < 1e-15:
                continue
            lam, tau = np.linalg.solve(m, p0 - c)
            if -1e-12 <= tau <= 1 + 1e-12:
                found.append((s0 + tau * length, lam))
        else:
            _, centre, rn, start, turn, s0 = piece
            d = c - centre
            qa, qb, qc = a @ a, d @ a, d @ d - rn * rn
            disc = qb * qb - qa * qc
            for lam in ((-qb - np.sqrt(disc)) / qa, (-qb + np.sqrt(disc)) / qa) if disc >= 0 else ():
                v = d + lam * a
                swept = (np.arctan2(v[1], v[0]) - start) * np.sign(turn) % (2 * np.pi)
                if swept <= abs(turn) + 1e-12:
                    found.append((s0 + swept * rn, lam))
    found = sorted({(round(float(s), 9), round(float(lam), 9)) for s, lam in found
                    if keep is None or keep(c + lam * a)})
    assert len(found) == 1, found
    return found[0]


def _frame(rot) -> list:
    """The tool's own x, y and z (its direction) turned by the build123d location ``rot``: three (3,) unit
    vectors."""
    o = np.array(tuple(rot.position))
    return [np.array(tuple((rot * bd.Location(e)).position)) - o for e in ((1, 0, 0), (0, 1, 0), (0, 0, 1))]


def _cut_trace(segments, *, t: float, k: float, outline: np.ndarray, origin, rot) -> float:
    """The developed area of a straight cut (a drill, a box) through a :func:`profile_solid` part on the neutral
    layer: ``outline`` (n, 2) is the cut's section in the tool's own x and y, the tool turned by ``rot`` (its z
    the cut's direction, any way in space) about ``origin`` (x, y, z); each of its points' lines meets the
    neutral layer (extruded along y) once, found in the x-z plane (:func:`_crossing`), its y followed along."""
    pieces = _neutral_profile(segments, t=t, k=k)
    x_, y_, a = _frame(rot)
    pts = []
    for u, v in outline:
        p = np.asarray(origin, dtype=np.float64) + u * x_ + v * y_
        s, lam = _crossing(pieces, np.array([p[0], p[2]]), np.array([a[0], a[2]]))
        pts.append((s, p[1] + lam * a[1]))
    x, y = np.array(pts).T
    return 0.5 * abs(float(x @ np.roll(y, -1) - y @ np.roll(x, -1)))


def _circle(d: float, n: int = 4000) -> np.ndarray:
    psi = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    return np.column_stack([d / 2 * np.sin(psi), d / 2 * np.cos(psi)])


def _rectangle(w: float, h: float, n: int = 1000) -> np.ndarray:
    u = np.linspace(0.0, 1.0, n, endpoint=False)
    return np.vstack([np.column_stack([-w / 2 + w * u, -h / 2 + 0 * u]), np.column_stack([w / 2 + 0 * u, -h / 2 + h * u]),
                      np.column_stack([w / 2 - w * u, h / 2 + 0 * u]), np.column_stack([-w / 2 + 0 * u, h / 2 - h * u])])


def _drilled(segments, *, t, width, tool, origin, rot):
    """A :func:`profile_solid` part with ``tool`` (centred, along +z) turned by ``rot`` and moved to ``origin``,
    cut out."""
    return profile_solid(segments, t=t, width=width) - bd.Pos(*origin) * rot * tool


def _flat_faces(part, z: float) -> int:
    """The number of the planar face of ``part`` at height ``z`` with an upright normal (a skin of the first
    flat)."""
    return next(i for i, f in enumerate(part.faces()) if f.geom_type == bd.GeomType.PLANE and
                abs(abs(f.normal_at().Z) - 1) < 1e-9 and abs(f.center().Z - z) < 1e-9)


JOG = PROFILES["jog"][0]
_DRILL = {d: bd.Cylinder(d / 2, 40, align=(bd.Align.CENTER,) * 3) for d in (3.0, 4.0, 6.0, 10.0)}
_WINDOW = bd.Box(8.0, 12.0, 40, align=(bd.Align.CENTER,) * 3)
OBLIQUE_CUTS = {  # segments, t, width, tool section, tool, origin, its turn, K-factors
    # the L's bend drilled off its bisector (120 degrees from +z: it leaves through flange B's neutral plane's
    # side), and at 150 degrees through a point off the bend axis
    "L drilled at 120": (L_SEGMENTS, T_L, W_L, _circle(10.0), _DRILL[10.0], (LA, 20.0, R_L), bd.Rot(0, 120, 0),
                         (0.5, 0.4)),
    "L drilled at 150 off the axis": (L_SEGMENTS, T_L, W_L, _circle(10.0), _DRILL[10.0], (LA + 1.0, 20.0, R_L - 1.0),
                                      bd.Rot(0, 150, 0), (0.5, 0.4)),
    # a Ø 4 drilled at 120 degrees into flange A 5 mm before the bend: the inside skin's trace lies on flange A
    # alone, the wall's lines reach the bend's neutral layer
    "L drilled at 120 short of the bend": (L_SEGMENTS, T_L, W_L, _circle(4.0), _DRILL[4.0], (LA - 5.0, 20.0, 0.0),
                                           bd.Rot(0, 120, 0), (0.5,)),
    # an 8 x 12 box window at 135 degrees: plane walls whose lines across the sheet are the box's edges; the same
    # turned 30 degrees about its own axis, and one turned every way: the straight edges of its trace on a flange
    # develop to curves where their lines meet the bend
    "L window at 135": (L_SEGMENTS, T_L, W_L, _rectangle(8.0, 12.0), _WINDOW, (LA, 20.0, R_L), bd.Rot(0, 135, 0),
                        (0.5, 0.4)),
    "L window at 135 spun 30": (L_SEGMENTS, T_L, W_L, _rectangle(8.0, 12.0), _WINDOW, (LA, 20.0, R_L),
                                bd.Rot(0, 135, 0) * bd.Rot(0, 0, 30), (0.4,)),
    "L window turned every way": (L_SEGMENTS, T_L, W_L, _rectangle(8.0, 12.0), _WINDOW, (LA, 20.0, R_L),
                                  bd.Rot(25, 120, 10) * bd.Rot(0, 0, 15), (0.4,)),
    # a Z jog drilled from above (square to both flanges, oblique in the bends and the web) across both bends
    "jog drilled from above": (JOG, 1.5, 40.0, _circle(6.0), _DRILL[6.0], (31.5, 20.0, 1.0), bd.Rot(0, 0, 0),
                               (0.5, 0.4)),
    # a Ø 3 at 135 degrees through the jog's first bend into its web (the hole cuts that bend in two), and one
    # from the web across its second bend: at K 0.3 the web's neutral layer runs from one bend's depth to the
    # other's, and each flange's ends at its bends
    "jog drilled at 135 into the web": (JOG, 1.5, 40.0, _circle(3.0), _DRILL[3.0], (30.0, 20.0, 0.5),
                                        bd.Rot(0, 135, 0), (0.3,)),
    "jog drilled at 135 from the web": (JOG, 1.5, 40.0, _circle(3.0), _DRILL[3.0], (32.5, 20.0, 2.0),
                                        bd.Rot(0, 135, 0), (0.3,)),
}


@pytest.mark.parametrize(("name", "k"), [(name, k) for name in sorted(OBLIQUE_CUTS) for k in OBLIQUE_CUTS[name][-1]])
def test_oblique_cuts_develop_on_the_neutral_layer_either_face_fixed(name, k):
    """Cuts across bends whose walls are straight lines through the sheet at any angle: each blank hole is the
    cut's trace on the neutral layer (:func:`_cut_trace`: every line of the wall met with the neutral arcs and
    flats in closed form, 4000 points: converged to 2e-6), within 1e-5 (the blank's polyline samples the fixed
    face's trace, and the developed trace between samples, at 0.02 um chord error), with the inside or the
    outside skin of the first flat fixed; the blank's area is the developed strip less the hole (1e-6), and an
    ``oblique-cut`` note says so."""
    segments, t, width, section, tool, origin, rot, _ = OBLIQUE_CUTS[name]
    part = _drilled(segments, t=t, width=width, tool=tool, origin=origin, rot=rot)
    neutral = _cut_trace(segments, t=t, k=k, outline=section, origin=origin, rot=rot)
    assert neutral == pytest.approx(_cut_trace(segments, t=t, k=k, outline=section[::2], origin=origin, rot=rot),
                                    rel=2e-6)  # converged
    strip = developed_length(segments, t=t, k=k) * width
    for z in (0.0, -t):
        blank = patterns.unfold(part, k_factor=k, name="cut", fixed_face=_flat_faces(part, z))
        (hole,) = blank.holes
        assert hole.area == pytest.approx(neutral, rel=1e-5), z
        assert blank.area == pytest.approx(strip - neutral, rel=1e-6)
        (note,) = [f for f in blank.findings if f.code is patterns.Code.OBLIQUE_CUT]
        assert f"neutral layer, {neutral:.2f} mm²" in note.message


def test_a_window_under_a_teardrop_hem_is_not_traced_onto_its_return_flange_run_on():
    """A 6 mm wide window cut down and to the left (the tool turned -120° about y) from the teardrop hem's
    inside into its base, the cutter capped at z = 0.6 (inside the hollow, under the return flange).  The wall's
    lines from the top skin near the bend cross the return flange's neutral plane where it would run on past
    the flange's free end, before they reach the base's: that plane ends at the flange's edge, so the hole is
    the wall's trace on the base's and the bend's neutral layer (the line's one crossing below z = 0.6 with the
    closed-form layer, 2000 points a side), within 1e-5, either skin fixed.  It was 96.24 mm² against 34.08
    (+182 %) with the top skin fixed, and the note said it was traced (a review's case)."""
    seg, t, w = PROFILES["teardrop_hem"]
    rot = bd.Rot(0, -120, 0)
    x_, y_, a = _frame(rot)
    left, right = np.array([34.65, 15.0, 0.0]), np.array([40.4, 15.0, 2 - np.sqrt(4 - 0.4**2)])
    origin, half = (left + right) / 2, abs(float((right - left) @ x_)) / 2
    cutter = (bd.Pos(*origin) * rot * bd.Box(2 * half, 6.0, 30, align=(bd.Align.CENTER,) * 3)) & (
        bd.Pos(30, 15, -49.4) * bd.Box(100, 100, 100))
    part = profile_solid(seg, t=t, width=w) - cutter
    pieces = _neutral_profile(seg, t=t, k=0.5)
    pts = []
    for u, v in _rectangle(2 * half, 6.0, 2000):
        p = origin + u * x_ + v * y_
        s, lam = _crossing(pieces, np.array([p[0], p[2]]), np.array([a[0], a[2]]), keep=lambda q: q[1] <= 0.6)
        pts.append((s, p[1] + lam * a[1]))
    x, y = np.array(pts).T
    neutral = 0.5 * abs(float(x @ np.roll(y, -1) - y @ np.roll(x, -1)))
    for z in (0.0, -t):
        blank = patterns.unfold(part, k_factor=0.5, name="cut", fixed_face=_flat_faces(part, z))
        (hole,) = blank.holes
        assert hole.area == pytest.approx(neutral, rel=1e-5), z
        notes = [f.message for f in blank.findings if f.code is patterns.Code.OBLIQUE_CUT]
        # the bottom skin's trace lies on the base alone and its lines reach no bend: drawn as it is (on parallel
        # planes of one flat the traces are translates, of one area), with no note
        assert [f"neutral layer, {neutral:.2f} mm²" in m for m in notes] == ([True] if z == 0.0 else [])


@pytest.mark.parametrize("k", [0.4, 0.5])
def test_a_cut_through_the_gap_of_an_s_jogs_neutral_layer_says_so(k):
    """The S jog's two bends touch with no flat between: at K 0.4 their neutral layers lie at different depths
    (0.6 and 0.9 mm under the top skin) and leave a gap at the tangent line, so a Ø 3 drilled at 135° through
    it has lines that meet no neutral layer: the note says that (not "a counterbore", as it did), and the hole
    is the fixed face's trace.  At K 0.5 the layer is continuous and the hole is traced (the closed form, 1e-5)."""
    seg, t, w = PROFILES["s_jog"]
    origin, rot = (33.0, 20.0, 2.0), bd.Rot(0, 135, 0)
    part = _drilled(seg, t=t, width=w, tool=bd.Cylinder(1.5, 40, align=(bd.Align.CENTER,) * 3), origin=origin,
                    rot=rot)
    for z in (0.0, -t):
        blank = patterns.unfold(part, k_factor=k, name="cut", fixed_face=_flat_faces(part, z))
        (note,) = [f.message for f in blank.findings if f.code is patterns.Code.OBLIQUE_CUT]
        (hole,) = blank.holes
        if k == 0.5:
            neutral = _cut_trace(seg, t=t, k=k, outline=_circle(3.0), origin=origin, rot=rot)
            assert hole.area == pytest.approx(neutral, rel=1e-5) and f"neutral layer, {neutral:.2f} mm²" in note
        else:
            assert "meets no neutral layer" in note and "counterbore" not in note
            assert f"drawn as the fixed face's trace, {hole.area:.2f} mm²" in note


def _outside_trace(*, xc: float, rad: float, floor: float, k: float, n: int = 200000) -> float:
    """The developed area of the L's outside skin inside the vertical cylinder of radius ``rad`` about
    ``x = xc`` and below the plane ``z = floor``: flange A's bottom (x <= LA, a circle's segment) and the bend's
    outside face, each angle ``phi`` from the bottom developed as ``phi (r + k t)`` (trapezoid rule, ``n``)."""
    h = LA - xc  # the segment x <= LA of the circle
    flange = rad * rad * np.arccos(-h / rad) + h * np.sqrt(rad * rad - h * h)
    ro, rn = R_L + T_L, R_L + k * T_L
    top = np.arccos((R_L - floor) / ro)  # where the outside face rises to the floor
    phi = np.linspace(0.0, top, n)
    w = np.sqrt(np.clip(rad * rad - (LA + ro * np.sin(phi) - xc) ** 2, 0.0, None))
    return float(flange + np.trapezoid(2 * w, phi) * rn)


def test_a_counterbore_across_a_bend_is_not_traced_past_its_step():
    """A Ø 7 counterbore 0.5 mm deep drilled up into the bottom of flange A 2 mm before the bend (it runs
    1.5 mm into the bend's outside face, all of it below the counterbore's floor), over a Ø 4 hole.  With the
    outside skin fixed, the cut's wall (the counterbore) stops 0.5 mm in, before the neutral layer (0.75 mm at
    K 0.5): its lines are not followed past the step; the cut is drawn as the outside skin's trace
    (:func:`_outside_trace`) and the note says why.  With the inside skin fixed, the Ø 4 hole's wall reaches the
    neutral layer: its trace there is the hole (:func:`_cut_trace`)."""
    xc, floor = LA - 2.0, -T_L + 0.5
    tool = bd.Cylinder(2.0, 80, align=(bd.Align.CENTER,) * 3) + bd.Pos(0, 0, floor) * bd.Cylinder(
        3.5, 40, align=(bd.Align.CENTER, bd.Align.CENTER, bd.Align.MAX))
    part = _drilled(L_SEGMENTS, t=T_L, width=W_L, tool=tool, origin=(xc, 20.0, 0.0), rot=bd.Rot(0, 0, 0))
    blank = patterns.unfold(part, k_factor=0.5, name="bore", fixed_face=_flat_faces(part, -T_L))
    (note,) = [f for f in blank.findings if f.code is patterns.Code.OBLIQUE_CUT]
    assert "counterbore" in note.message and "not on the neutral layer" in note.message
    (hole,) = blank.holes
    assert hole.area == pytest.approx(_outside_trace(xc=xc, rad=3.5, floor=floor, k=0.5), rel=1e-4)
    inside = patterns.unfold(part, k_factor=0.5, name="bore", fixed_face=_flat_faces(part, 0.0))
    (hole,) = inside.holes
    assert hole.area == pytest.approx(_cut_trace(L_SEGMENTS, t=T_L, k=0.5, outline=_circle(4.0), origin=(
        xc, 20.0, 0.0), rot=bd.Rot(0, 0, 0)), rel=1e-5)


# --------------------------------------------------------------------------- #
# Flanges nearly touching
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize("g", [0.3, 0.2])
@pytest.mark.parametrize("k", [0.5, 0.4])
def test_flanges_nearly_touching_unfold_to_one_simple_contour(k, g):
    """Base 40 x 40, two bends of pi / 2 (1 + k) by 40, flange 1 (15 - 1) x (40 + 1 + 1), flange 2
    (15 - 1) x (40 + 1 - g): the area is their sum, the blank (40 + pi / 2 (1 + k) + 14) square, its outline
    one simple ring with no hole, and no overlap found (apart in the flat: the run-ons sit beside the
    corner's open relief, pi / 2 (1 + k) > r - g)."""
    L, H, r, t = 40.0, 15.0, 1.0, 1.0
    allowance = np.pi / 2 * (r + k * t)
    area = L * L + 2 * allowance * L + (H - r) * (L + r + t) + (H - r) * (L + r - g)
    blank = patterns.unfold(near_corner(g=g), k_factor=k, name="corner")
    assert blank.ok and blank.findings == () and blank.holes == ()
    assert blank.area == pytest.approx(area, rel=1e-9)
    assert blank.size == pytest.approx((L + allowance + H - r,) * 2, abs=1e-6)
    ring = shapely.LinearRing(blank.outline.points())
    assert ring.is_simple and blank.polygon.is_valid
    assert blank.polygon.area == pytest.approx(area, rel=1e-6)


# --------------------------------------------------------------------------- #
# Formed features: reported, never silently flattened
# --------------------------------------------------------------------------- #


def test_round_form_is_of_constant_thickness():
    """The builders' own check: the dimple's solid is the plate (60^2 - pi 13^2) x 1 plus the revolved
    section, and its spherical and toroidal skins are 1 mm apart (R15 / R16 caps, R3 / R2 fillets)."""
    part = dimple()
    radii = sorted(round(f.geom_adaptor().Sphere().Radius(), 9) for f in part.faces()
                   if f.geom_type == bd.GeomType.SPHERE)
    assert radii == [15.0, 16.0]
    section = _round_form(**FORM, up=False)
    ring = bd.revolve(section, axis=bd.Axis.Z).volume
    assert part.volume == pytest.approx((60.0**2 - np.pi * 13.0**2) * 1.0 + ring, rel=1e-9)


def test_dimple_is_refused_not_flattened(tmp_path, capsys):
    """A pressed dimple has no flat blank to develop: ``unfold`` raises one line naming the part, and the
    command exits 2 with nothing written."""
    with pytest.raises(InputError) as info:
        patterns.unfold(dimple(), k_factor=0.5, name="dimple")
    assert "\n" not in str(info.value) and str(info.value).startswith("dimple: ")
    code, err, out = _cli(dimple(), "dimple", tmp_path, capsys)
    assert code == 2 and out is None and err.count("\n") == 1 and err.startswith("patterns: error: dimple: ")


def test_dimple_refusal_names_its_formed_faces():
    """The refusal says what the dimple is: its faces doubly curved (spheres and tori), as the formed cover of
    the torture set is refused (test_torture.py), naming at least one of the formed faces."""
    part = dimple()
    formed = _formed_faces(part)
    with pytest.raises(InputError) as info:
        patterns.unfold(part, k_factor=0.5, name="dimple")
    message = str(info.value)
    assert "doubly curved" in message
    named = {int(x) for x in message.split("faces ", 1)[1].split(" are", 1)[0].replace(",", " ").split()
             if x.isdigit()}
    assert named and named <= formed


def test_louver_hood_is_reported_face_by_face():
    """The louver's hood (a half torus fillet and a half cap on each skin) is not developable: every face the
    blank flattens that is a sphere or a torus is named in a ``meshed-face`` finding with its strain; one
    sphere and one torus (the skin's), none that is not formed."""
    part = louver()
    formed = _formed_faces(part)
    kinds = {i: part.faces()[i].geom_type for i in formed}
    blank = patterns.unfold(part, k_factor=0.5, name="louver")
    named = {int(f.message.split("face ", 1)[1].split(" ", 1)[0]) for f in blank.findings
             if f.code is patterns.Code.MESHED_FACE}
    assert named <= formed
    assert sorted(kinds[i].name for i in named) == ["SPHERE", "TORUS"]
    assert all("not developable" in f.message and "strain" in f.message for f in blank.findings
               if f.code is patterns.Code.MESHED_FACE)


def test_louver_cut_contour_is_closed_and_written_as_drawn(tmp_path, capsys):
    """Whatever the blank is, its cut contour is closed piece to piece (each piece starts where the one
    before ends, within 10 nm), and the DXF read back holds the blank's own area (1e-5)."""
    blank = patterns.unfold(louver(), k_factor=0.5, name="louver")
    for loop in (blank.outline, *blank.holes):
        ends = [(p.points()[-1], q.points()[0]) for p, q in zip(loop.pieces, loop.pieces[1:] + loop.pieces[:1])]
        assert max(np.linalg.norm(a - b) for a, b in ends) < 1e-5
    code, err, out = _cli(louver(), "louver", tmp_path, capsys)
    assert code == 0 and err == ""
    assert patterns.read_flat_pattern(out).area == pytest.approx(blank.area, rel=1e-5)


# --------------------------------------------------------------------------- #
# The command line
# --------------------------------------------------------------------------- #

CLI_CASES = {**{name: (lambda name=name: profile_part(name)) for name in PROFILES},
             "slot": slot_across_bend, "corner": near_corner, "hole": hole_across_bend}


def _reference_area(name: str) -> float:
    if name in PROFILES:
        segments, t, width = PROFILES[name]
        return developed_length(segments, t=t, k=0.5) * width
    allowance = np.pi / 2 * (R_L + 0.5 * T_L)
    if name == "slot":
        return (LA + LB + allowance) * W_L - (6.0 * (10.0 + allowance + 13.0) + 9.0 * np.pi)
    if name == "hole":
        return (LA + LB + allowance) * W_L - _drilled_trace(0.5 * T_L, k=0.5)
    allowance = np.pi / 2 * 1.5  # the corner: r 1, t 1
    return 40.0**2 + 2 * allowance * 40.0 + 14.0 * 42.0 + 14.0 * 40.7


@pytest.mark.parametrize("name", sorted(CLI_CASES))
def test_cli_writes_the_developed_blank(name, tmp_path, capsys):
    """``patterns unfold PART.step -o PART.dxf --k-factor 0.5`` exits 0, says nothing on stderr, and the DXF
    read back holds the hand-computed area (1e-5: the DXF's arcs read back as polylines)."""
    code, err, out = _cli(CLI_CASES[name](), name, tmp_path, capsys)
    assert code == 0 and err == ""
    assert patterns.read_flat_pattern(out).area == pytest.approx(_reference_area(name), rel=1e-5)
