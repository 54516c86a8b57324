"""Sheet metal: exact unrolling, thickness and K-factor, bend lines, arcs -- checked
against blanks computed from the drawing, not from the code under test."""

from math import hypot, pi

import build123d as bd
import ezdxf
import numpy as np
import pytest
import shapely

import patterns
from patterns.errors import InputError
from patterns.pieces.arcs import arc_points, fit_arcs

from .conftest import SAMPLES

# The hopper sample: radius 100 at z = 0 to radius 300 at z = 400.
R1, R2, H = 100.0, 300.0, 400.0
SLANT = hypot(R2 - R1, H)
SIN_A = (R2 - R1) / SLANT


def dxf_cut_contours(path, step=0.5):
    """CUT contours of a DXF file: points (vertices, and arcs sampled every ``step`` mm) and segment counts."""
    doc = ezdxf.readfile(path)
    out = []
    for e in doc.modelspace().query('LWPOLYLINE[layer=="CUT"]'):
        pts = np.array([(x, y, b) for x, y, _, _, b in e.get_points("xyseb")])
        out.append((arc_points(pts, step=step), len(pts)))
    return out


def sector_distance(points, s_in, s_out, t0, t1):
    """Exact distance of points to the outline of the annular sector (apex at the origin)."""
    r = np.hypot(points[:, 0], points[:, 1])
    t = np.arctan2(points[:, 1], points[:, 0])
    t = t0 + np.mod(t - t0, 2 * pi)
    inside = t <= t1
    out = []
    for s in (s_in, s_out):  # the two arcs
        ends = np.array([[s * np.cos(t0), s * np.sin(t0)], [s * np.cos(t1), s * np.sin(t1)]])
        to_ends = np.min(np.linalg.norm(points[:, None, :] - ends[None], axis=2), axis=1)
        out.append(np.where(inside, np.abs(r - s), to_ends))
    for a in (t0, t1):  # the two straight edges
        d = np.array([np.cos(a), np.sin(a)])
        along = np.clip(points @ d, s_in, s_out)
        out.append(np.linalg.norm(points - along[:, None] * d, axis=1))
    return np.min(out, axis=0)


def distance_both_ways(a_pts, b_pts):
    ra, rb = shapely.LinearRing(a_pts), shapely.LinearRing(b_pts)
    return max(shapely.distance(shapely.points(a_pts), rb).max(), shapely.distance(shapely.points(b_pts), ra).max())


def annular_sector(s_in, s_out, t0, t1, step=0.01):
    """The analytic blank of a cone frustum: points every ``step`` mm along its outline."""
    arc_out = np.linspace(t0, t1, int((t1 - t0) * s_out / step) + 2)
    arc_in = np.linspace(t1, t0, int((t1 - t0) * s_in / step) + 2)
    edge = np.linspace(0, 1, int((s_out - s_in) / step) + 2)[1:-1]
    return np.vstack([
        np.column_stack([s_out * np.cos(arc_out), s_out * np.sin(arc_out)]),
        np.outer(s_out + (s_in - s_out) * edge, [np.cos(t1), np.sin(t1)]),
        np.column_stack([s_in * np.cos(arc_in), s_in * np.sin(arc_in)]),
        np.outer(s_in + (s_out - s_in) * edge, [np.cos(t0), np.sin(t0)]),
    ])


@pytest.fixture(scope="module")
def hopper():
    # Chords within 0.02 mm of the surface: the developed arcs then sag < 0.01 mm.
    return patterns.flatten(patterns.load(SAMPLES / "hopper.step", chord_tolerance=0.02)).placed([(0.0, 0.0, 0.0)])


@pytest.mark.parametrize("arcs", [False, True])
def test_cone_frustum_blank_is_the_analytic_annular_sector(hopper, tmp_path, arcs):
    flat = hopper.panels[0]
    assert flat.flattening.method == "exact"
    path = tmp_path / "hopper.dxf"
    patterns.write(hopper, path, arcs=arcs)
    (contour, segments), = dxf_cut_contours(path)
    # The file holds the drawing moved into the first quadrant: move it back by the same shift
    # (lower-left corners of the contour and of the flattened outline; the arcs' sag < 0.01 mm).
    contour = contour - (contour.min(axis=0) - flat.uv[flat.loops[0]].min(axis=0))
    # The blank from the drawing: radii R/sin a about the apex, angle 2 pi sin a.
    s_in, s_out = R1 / SIN_A, R2 / SIN_A
    t0 = float(np.min(np.unwrap(np.arctan2(contour[:, 1], contour[:, 0]))))
    t1 = t0 + 2 * pi * SIN_A
    # Both ways: the contour (its points and its segments' middles) to the exact
    # blank, and the blank (every 0.5 mm) to the contour.
    probe = np.vstack([contour, 0.5 * (contour + np.roll(contour, -1, axis=0))])
    assert sector_distance(probe, s_in, s_out, t0 - 1e-9, t1 + 1e-9).max() < 0.05  # mm, on a 600 mm part
    blank = annular_sector(s_in, s_out, t0, t1, step=0.5)
    assert shapely.distance(shapely.points(blank), shapely.LinearRing(contour)).max() < 0.05
    if arcs:
        plain = len(flat.outline())
        assert plain >= 10 * segments  # measured: 816 segments -> 4 (two arcs, two lines)


def test_arcs_stay_within_tolerance_and_closed():
    rng = np.random.default_rng(4)
    t = np.linspace(0, 2 * pi, 400, endpoint=False)
    # A rounded slot: two half circles and two straight sides, with round-off noise.
    loop = np.column_stack([100 * np.cos(t), 40 * np.sin(t)])
    loop = loop + rng.normal(scale=1e-4, size=loop.shape)
    fitted = fit_arcs(loop, 0.01)
    assert len(fitted) < len(loop) / 5
    dense = arc_points(fitted, step=0.005)
    assert distance_both_ways(dense, loop) < 0.01 + 1e-3
    assert set(map(tuple, fitted[:, :2])) <= set(map(tuple, loop))  # vertices are outline points


def test_rolled_cylinder_blank_length_with_thickness_and_k_factor(tmp_path):
    model = patterns.load(SAMPLES / "rolled_cylinder.step")
    pattern = patterns.flatten(model, thickness=2.0, k_factor=0.44, reference="inside").placed([(0.0, 0.0, 0.0)])
    flat = pattern.panels[0]
    width = np.ptp(flat.uv[:, 0])
    assert width == pytest.approx(2 * pi * (250.0 + 0.44 * 2.0), abs=0.01)
    assert np.ptp(flat.uv[:, 1]) == pytest.approx(500.0, abs=1e-9)
    path = tmp_path / "cylinder.dxf"
    patterns.write(pattern, path, arcs=True)
    (contour, segments), = dxf_cut_contours(path, step=0.5)
    x0, y0 = contour.min(axis=0)
    rect = np.array([[x0, y0], [x0 + width, y0], [x0 + width, y0 + 500], [x0, y0 + 500]])
    dense_rect = np.vstack([np.linspace(rect[i], rect[(i + 1) % 4], 200, endpoint=False) for i in range(4)])
    assert distance_both_ways(contour, dense_rect) < 0.01
    assert segments == 4
    # Outside and mid references, and no thickness.
    for reference, radius in (("outside", 250.0 - 2.0 + 0.88), ("mid", 250.0 - 1.0 + 0.88)):
        p = patterns.flatten(model, thickness=2.0, k_factor=0.44, reference=reference)
        assert np.ptp(p.panels[0].uv[:, 0]) == pytest.approx(2 * pi * radius, abs=0.01)
    assert np.ptp(patterns.flatten(model).panels[0].uv[:, 0]) == pytest.approx(2 * pi * 250.0, abs=1e-6)


def test_cone_neutral_surface_with_thickness():
    model = patterns.load(SAMPLES / "hopper.step")
    t, k = 3.0, 0.4
    flat = patterns.flatten(model, thickness=t, k_factor=k, reference="inside").panels[0]
    # The neutral cone: the surface moved k t outwards, normal to the generator,
    # so every slant distance from the (moved) apex grows by k t / tan a.
    cot = (H / SLANT) / SIN_A
    r = np.hypot(flat.uv[:, 0], flat.uv[:, 1])
    assert r.min() == pytest.approx(R1 / SIN_A + k * t * cot, abs=1e-6)
    assert r.max() == pytest.approx(R2 / SIN_A + k * t * cot, abs=1e-6)
    theta = np.unwrap(np.arctan2(flat.uv[flat.loops[0], 1], flat.uv[flat.loops[0], 0]))
    assert np.ptp(theta) == pytest.approx(2 * pi * SIN_A, abs=1e-9)


def test_planar_faces_and_holes_unroll_exactly():
    part = bd.Box(300, 200, 10) - bd.Cylinder(30, 10)
    pattern = patterns.flatten(patterns.load(part))
    methods = {f.flattening.method for f in pattern.panels}
    assert methods == {"exact"}
    planar = [f for f in pattern.panels if f.panel.surface.kind.value == "plane"]
    assert len(planar) == 6
    for flat in planar:
        assert flat.flattening.distortion.edge_strain_max < 1e-12
        assert flat.area == pytest.approx(flat.panel.area, rel=1e-12)
    (wall,) = [f for f in pattern.panels if f.panel.surface.kind.value == "cylinder"]
    # Its points are exact; only a chord across the curved surface is shorter in 3D than flat.
    assert np.ptp(wall.uv[:, 0]) == pytest.approx(2 * pi * 30, abs=1e-9)
    assert np.ptp(wall.uv[:, 1]) == pytest.approx(10.0, abs=1e-9)


def test_exact_is_optional_and_the_engine_agrees():
    model = patterns.load(SAMPLES / "rolled_cylinder.step")
    exact = patterns.flatten(model).panels[0]
    engine = patterns.flatten(model, exact=False).panels[0]
    assert engine.flattening.method == "relaxed"
    # The engine unrolls the polyhedral mesh: its width is the chords' sum, a hair short.
    assert np.ptp(engine.uv @ _principal_axes(engine.uv)[:, 0]) == pytest.approx(np.ptp(exact.uv[:, 0]), rel=2e-4)


def _principal_axes(uv):
    c = uv - uv.mean(axis=0)
    _, _, vt = np.linalg.svd(c, full_matrices=False)
    return vt.T


def test_bend_lines_on_the_bend_layer(hopper, tmp_path):
    flat = hopper.panels[0]
    lines = flat.rulings(60.0)
    # Evenly spread over the sector, turning 360 degrees around the axis in all.
    assert len(lines) == 30
    turn = lines[0][2]
    assert turn * (len(lines) + 1) == pytest.approx(360.0)
    for a, b, _ in lines:
        # Rulings run through the apex (the origin of the development) ...
        assert abs(a[0] * b[1] - a[1] * b[0]) < 1e-6 * np.linalg.norm(a) * np.linalg.norm(b)
        # ... from the inner arc to the outer one (clipped by the outline's chords: sag < 0.01 mm).
        assert np.linalg.norm(a) == pytest.approx(R1 / SIN_A, abs=0.01)
        assert np.linalg.norm(b) == pytest.approx(R2 / SIN_A, abs=0.01)
    path = tmp_path / "hopper.dxf"
    patterns.write(hopper, path, bend_spacing=60.0)
    doc = ezdxf.readfile(path)
    assert len(doc.modelspace().query('LINE[layer=="BEND"]')) == 30
    texts = [t.dxf.text for t in doc.modelspace().query('TEXT[layer=="BEND"]')]
    assert texts and all(t == f"BEND {turn:.2f} DEG" for t in texts)
    # each label centred on a bend line, along it, not at its ends
    segments = [(np.array(e.dxf.start)[:2], np.array(e.dxf.end)[:2]) for e in doc.modelspace().query('LINE[layer=="BEND"]')]
    for t in doc.modelspace().query('TEXT[layer=="BEND"]'):
        at = np.array(t.dxf.align_point)[:2]
        a, b = min(segments, key=lambda ab: shapely.LineString(ab).distance(shapely.Point(at)))
        along = (at - a) @ (b - a) / ((b - a) @ (b - a))
        assert shapely.LineString([a, b]).distance(shapely.Point(at)) < 1e-6 and 0.05 < along < 0.95
        assert abs(abs(np.cos(np.radians(t.dxf.rotation) - np.arctan2(*(b - a)[::-1])))) == pytest.approx(1.0)
    names = [t for t in doc.modelspace().query('TEXT[layer=="LABEL"]') if t.dxf.text == hopper.panels[0].name]
    assert len(names) == 1  # the panel's name: 1.2 text heights; a bend label: half of one
    assert {round(t.dxf.height / names[0].dxf.height, 9) for t in doc.modelspace().query('TEXT[layer=="BEND"]')} == {
        round(0.5 / 1.2, 9)}
    cylinder = patterns.flatten(patterns.load(SAMPLES / "rolled_cylinder.step")).panels[0]
    rulings = cylinder.rulings(100.0)
    # Along the axis (its flat direction is averaged over the chord triangles: 2e-5 mm off over 500).
    assert all(abs(a[0] - b[0]) < 1e-4 and abs(abs(a[1] - b[1]) - 500.0) < 1e-6 for a, b, _ in rulings)
    assert patterns.flatten(patterns.load(SAMPLES / "cup.step")).panels[0].rulings(10.0) == []


@pytest.mark.parametrize(
    ("kwargs", "words"),
    [
        ({"thickness": -1.0}, "thickness"),
        ({"thickness": 2.0, "k_factor": 1.5}, "k_factor"),
        ({"thickness": 2.0, "reference": "middle"}, "reference"),
    ],
)
def test_bad_sheet_options(kwargs, words):
    with pytest.raises(InputError, match=words):
        patterns.flatten(patterns.load(SAMPLES / "hopper.step"), **kwargs)


def test_bad_dxf_sheet_options(hopper, tmp_path):
    with pytest.raises(InputError, match="arc_tolerance"):
        patterns.write(hopper, tmp_path / "a.dxf", arcs=True, arc_tolerance=0)
    with pytest.raises(InputError, match="bend_spacing"):
        patterns.write(hopper, tmp_path / "a.dxf", bend_spacing=-5)
    with pytest.raises(InputError, match="machine profile only"):
        patterns.write(hopper, tmp_path / "a.dxf", profile="astm", arcs=True)
    assert list(tmp_path.iterdir()) == []


def test_freeform_thickness_offsets_along_the_normal():
    model = patterns.load(SAMPLES / "cup.step")
    thin = patterns.flatten(model)
    thick = patterns.flatten(model, thickness=2.0, k_factor=0.5, reference="inside")
    # The cup's normals point away from the sphere's centre: the neutral sphere
    # has radius 91, its area (91/90)**2 times the modelled one.
    ratio = sum(f.flattening.distortion.area_3d for f in thick.panels) / sum(
        f.flattening.distortion.area_3d for f in thin.panels)
    assert ratio == pytest.approx((91.0 / 90.0) ** 2, rel=1e-3)


def hand_layout(apex, directrix, n=2000):
    """The sheet-metal worker's triangulation of an oblique cone, done finely:
    true lengths from the apex to n + 1 points of the curve, each triangle laid
    down next to the previous one.  Returns the flat curve, apex at the origin,
    first line along +x."""
    t = np.linspace(0, 1, len(directrix))
    pts = np.column_stack([np.interp(np.linspace(0, 1, n + 1), t, directrix[:, k]) for k in range(3)])
    true = np.linalg.norm(pts - apex, axis=1)
    chords = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    flat = [np.array([true[0], 0.0])]
    angle = 0.0
    for k in range(n):
        a, b, c = true[k], true[k + 1], chords[k]
        angle += np.arccos(np.clip((a * a + b * b - c * c) / (2 * a * b), -1, 1))
        flat.append(b * np.array([np.cos(angle), np.sin(angle)]))
    return np.array(flat)


def _distance_to_polyline(points, polyline):
    """(k, 3) points, (m, 3) polyline -> (k,) distance of each point to the polyline, mm."""
    a, b = polyline[:-1], polyline[1:]
    ab = b - a
    t = np.einsum("kmi,mi->km", points[:, None] - a[None], ab) / np.einsum("mi,mi->m", ab, ab)
    nearest = a[None] + np.clip(t, 0, 1)[..., None] * ab[None]
    return np.linalg.norm(points[:, None] - nearest, axis=2).min(axis=1)


def test_square_to_round_is_unrolled_exactly_like_the_hand_layout(tmp_path):
    model = patterns.load(SAMPLES / "square_to_round.step")
    pattern = patterns.flatten(model)
    kinds = sorted(f.panel.surface.kind.value for f in pattern.panels)
    assert kinds == ["general cone"] * 4 + ["plane"] * 4
    assert all(f.flattening.method == "exact" for f in pattern.panels)
    # Every seam (the corner-to-circle lines) is as long flat as in 3D, on both sides.
    assert len(pattern.seams) == 8
    for fs in pattern.seams:
        assert fs.flat_lengths == pytest.approx((fs.seam.polyline_length,) * 2, rel=1e-9)
    for flat in pattern.panels:
        if flat.panel.surface.kind.value != "general cone":
            continue
        surface = flat.panel.surface
        hand = hand_layout(surface.origin, surface.directrix)
        # Put our flat piece in the hand layout's frame: apex at the origin, the
        # line to the directrix's first point along +x (a rigid motion).
        s3 = np.linalg.norm(flat.vertices - surface.origin, axis=1)
        apex_index = int(np.argmin(s3))
        assert s3[apex_index] < 1e-9
        uv = flat.uv - flat.uv[apex_index]
        first = int(np.argmin(np.linalg.norm(flat.vertices - surface.directrix[0], axis=1)))
        turn = -np.arctan2(uv[first, 1], uv[first, 0])
        rot = np.array([[np.cos(turn), -np.sin(turn)], [np.sin(turn), np.cos(turn)]])
        uv = uv @ rot.T
        last = uv[int(np.argmin(np.linalg.norm(flat.vertices - surface.directrix[-1], axis=1)))]
        if uv[first, 0] * last[1] - uv[first, 1] * last[0] < 0:
            uv[:, 1] = -uv[:, 1]  # the hand layout turns counter-clockwise
        loop = np.concatenate(flat.loops)
        gap = _distance_to_polyline(flat.vertices[loop], surface.directrix)
        curve_pts = loop[gap < 1e-6 * 500]  # the outline's points on the round end's curve
        assert len(curve_pts) > 20
        d = shapely.distance(shapely.points(uv[curve_pts]), shapely.LineString(hand))
        assert d.max() < 0.05  # mm, on a 500 mm part (measured: round-off)
    path = tmp_path / "s2r.dxf"
    patterns.write(pattern, path, bend_spacing=50.0)
    bend = ezdxf.readfile(path).modelspace().query('LINE[layer=="BEND"]')
    lines = [r for f in pattern.panels for r in f.rulings(50.0)]
    assert len(bend) == len(lines) > 0
    # The fold between the facets on either side of each triangulation line: a few
    # degrees to twenty here, symmetric across each corner.
    folds = [r[2] for r in pattern.panels[1].rulings(50.0)]
    assert all(0 < x < 30 for x in folds) and folds == pytest.approx(folds[::-1], abs=1e-6)
