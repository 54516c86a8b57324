"""patterns.check: the report's numbers against independent computations, overlaps
caught with their place, the JSON report, the heat map."""

import json

import numpy as np
import pytest
import shapely

import patterns
from patterns import surfaces
from patterns.audit import Code, Severity
from patterns.errors import ExportError, InputError

from .conftest import SAMPLES


@pytest.fixture(scope="module")
def hopper():
    return patterns.flatten(patterns.load(SAMPLES / "hopper.step"))


@pytest.fixture(scope="module")
def cup():
    return patterns.flatten(patterns.load(SAMPLES / "cup.step"))


def independent_principal_strains(vertices, faces, uv):
    """Both principal strains per triangle ``(m, 2)`` by an SVD of the 3D -> 2D Jacobian
    (orthonormal frame from the first edge and the normal), and the 3D areas."""
    p, q = vertices[faces], uv[faces]
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    x = e1 / np.linalg.norm(e1, axis=1, keepdims=True)
    n = np.cross(e1, e2)
    area = 0.5 * np.linalg.norm(n, axis=1)
    y = np.cross(n / np.linalg.norm(n, axis=1, keepdims=True), x)
    ref = np.stack([np.stack([(e1 * x).sum(1), (e2 * x).sum(1)], -1),
                    np.stack([(e1 * y).sum(1), (e2 * y).sum(1)], -1)], -2)  # columns: edges in 2D frame
    flat = np.stack([q[:, 1] - q[:, 0], q[:, 2] - q[:, 0]], -1)  # (m, 2, 2) columns
    jac = flat @ np.linalg.inv(ref)
    s = np.linalg.svd(jac, compute_uv=False)  # (m, 2) descending
    return s - 1, area


def independent_triangle_strain(vertices, faces, uv):
    """The dominant (larger-magnitude) principal strain per triangle, and the 3D areas."""
    strain, area = independent_principal_strains(vertices, faces, uv)
    dominant = np.where(np.abs(strain[:, 0]) >= np.abs(strain[:, 1]), strain[:, 0], strain[:, 1])
    return dominant, area


def test_developable_sample_has_no_strain_and_no_mismatch(hopper):
    report = patterns.check(hopper)
    assert report.ok and report.findings == ()
    (panel,) = report.panels
    assert panel.strain_max < 1e-3 and panel.strain_rms < 1e-4
    # An exact development has no strain, whichever way it is counted (its chords' would show ~1e-5)
    assert (panel.edge_strain_rms, panel.edge_strain_max) == (0.0, 0.0)
    # Exact development: the flat area is the true one, the 3D triangles (chords) a hair smaller.
    assert panel.area_flat == pytest.approx(panel.area_3d, rel=1e-4)
    (seam,) = report.seams
    assert seam.panels == ("face0", "face0") and seam.cad_edge is not None
    assert abs(seam.mismatch) < 1e-3 and abs(seam.mismatch_percent) < 1e-4  # measured 1.1e-4 mm on 447 mm
    assert seam.length_flat[0] == pytest.approx(seam.length_3d, rel=1e-4)


def test_doubly_curved_strain_statistics_equal_an_independent_computation(cup):
    report = patterns.check(cup, max_strain=0.03)
    for flat, numbers in zip(cup.panels, report.panels):
        strain, area = independent_principal_strains(flat.vertices, flat.faces, flat.uv)
        mag = np.abs(strain).max(axis=1)
        assert numbers.strain_max == pytest.approx(mag.max(), rel=1e-9)
        worst = np.argmax(mag)
        np.testing.assert_allclose(numbers.strain_max_at, flat.uv[flat.faces[worst]].mean(axis=0), atol=1e-9)
        # RMS of both principal strains, weighted by 3D area.
        assert numbers.strain_rms == pytest.approx(np.sqrt(np.sum(area[:, None] * strain**2) / (2 * area.sum())),
                                                   rel=1e-9)
        order = np.argsort(mag)
        cum = np.cumsum(area[order]) / area.sum()
        assert numbers.strain_p95 == pytest.approx(mag[order][np.searchsorted(cum, 0.95)], rel=1e-9)
        assert numbers.strain_p99 == pytest.approx(mag[order][np.searchsorted(cum, 0.99)], rel=1e-9)
        assert numbers.share_above_limit == pytest.approx(area[mag > 0.03].sum() / area.sum(), rel=1e-9)
        assert numbers.area_3d == pytest.approx(area.sum(), rel=1e-12)
        assert numbers.share_above_limit > 0.05  # a quarter sphere cannot be laid flat within 3 %
    # The strain limit is a finding with the worst place named, and the report is not ok.
    limits = [f for f in report.findings if f.code is Code.STRAIN_ABOVE_LIMIT]
    assert len(limits) == 4 and not report.ok
    for f, flat in zip(limits, cup.panels):
        dominant, _ = independent_triangle_strain(flat.vertices, flat.faces, flat.uv)
        worst = np.argmax(np.abs(dominant))
        np.testing.assert_allclose(f.points[0], flat.uv[flat.faces[worst]].mean(axis=0), atol=1e-9)
        assert set(f.faces.tolist()) == set(np.flatnonzero(np.abs(dominant) > 0.03).tolist())
    # Mating seams: flat lengths on both sides, mismatch in mm and %.
    for seam, fs in zip(report.seams, cup.seams):
        assert seam.length_flat == pytest.approx(fs.flat_lengths)
        assert seam.mismatch == pytest.approx(fs.flat_lengths[0] - fs.flat_lengths[1])
        assert seam.mismatch_percent == pytest.approx(100 * seam.mismatch / seam.length_3d)


def test_strain_direction_points_along_the_stretch():
    # A flat square stretched 10 % along a direction at 30 degrees in the plane.
    p, f = surfaces.disk_mesh(200)
    v = np.column_stack([p * 50, np.zeros(len(p))])
    t = np.radians(30)
    d = np.array([np.cos(t), np.sin(t)])
    uv = p * 50 + 0.1 * np.outer(p * 50 @ d, d)
    ts = patterns.measure.triangle_strains(v, f, uv)
    np.testing.assert_allclose(ts.dominant, 0.1, atol=1e-12)
    np.testing.assert_allclose(ts.direction, t, atol=1e-9)
    np.testing.assert_allclose(ts.area_change, 0.1, atol=1e-12)


def test_overlapping_layout_is_caught_with_the_place_named(cup):
    a = cup.panels[0]
    width = np.ptp(a.uv[:, 0])
    # Panel 1 is put 40 % of a width to the right of panel 0: they overlap.
    apart = [(0.0, 3 * width * k, 0.0) for k in range(4)]
    assert patterns.check(cup.placed(apart)).ok
    shifted = list(apart)
    shifted[1] = (0.0, 0.4 * width, 0.0)
    report = well_formed(patterns.check(cup.placed(shifted)), cup)
    (finding,) = [f for f in report.findings if f.code is Code.PANELS_OVERLAP]
    assert finding.severity is Severity.ERROR and finding.panels == ("face0", "face1") and not report.ok
    import shapely

    placed = cup.placed(shifted)
    p0 = shapely.Polygon(placed.panels[0].uv[placed.panels[0].loops[0]])
    p1 = shapely.Polygon(placed.panels[1].uv[placed.panels[1].loops[0]])
    common = p0.intersection(p1)
    assert common.area > 0
    assert shapely.contains_xy(common.buffer(1e-6), *finding.points[0])
    assert f"{common.area:.1f} mm^2" in finding.message


def test_folded_flattening_is_caught_with_the_triangles_named(cup):
    flat = cup.panels[0]
    uv = np.array(flat.uv)
    # Push one interior vertex across its neighbours: its fan folds.
    boundary = np.zeros(len(uv), dtype=bool)
    boundary[np.concatenate(flat.loops)] = True
    vtx = int(np.flatnonzero(~boundary)[len(uv) // 3])
    fan = np.flatnonzero((flat.faces == vtx).any(axis=1))
    uv[vtx] += 3 * np.ptp(uv[flat.faces[fan]].reshape(-1, 2), axis=0)
    broken = patterns.flatten_mesh(flat.vertices, flat.faces, method="isometric")
    from dataclasses import replace

    folded_result = replace(broken, uv=uv, overlap=patterns.overlap_verdict(uv, flat.faces, flat.loops))
    bad = replace(cup, panels=(replace(flat, flattening=folded_result),) + cup.panels[1:])
    report = patterns.check(bad)
    (finding,) = [f for f in report.findings if f.code is Code.FOLDED_TRIANGLES]
    expected = np.flatnonzero(patterns.measure.signed_areas(uv, flat.faces) <= 0)
    assert len(expected) > 0 and set(finding.faces.tolist()) == set(expected.tolist())
    assert set(finding.faces.tolist()) <= set(fan.tolist())
    np.testing.assert_allclose(finding.points, uv[flat.faces[expected]].mean(axis=1))
    assert finding.panels == ("face0",) and not report.ok
    assert report.panels[0].n_folded == len(expected) and not report.panels[0].one_to_one


def test_crossing_outline_is_caught_at_the_crossing():
    # A flat strip whose flattening is bent round so far that its ends cross.
    st, f = surfaces.grid_mesh(60, 4)
    s_, t_ = st[:, 0] * 600.0, st[:, 1] * 20.0
    v = np.column_stack([s_, t_, np.zeros(len(st))])
    r = patterns.flatten_mesh(v, f, method="isometric")
    angle = s_ / 600.0 * 2.4 * np.pi
    radius = 100.0 + t_
    uv = np.column_stack([radius * np.cos(angle), radius * np.sin(angle)])
    from patterns.audit import boundary_crossings

    crossings = boundary_crossings(uv, r.loops)
    assert crossings and crossings[0][0] == crossings[0][1] == 0
    pts = crossings[0][2]
    # Every reported point lies on the flat outline, at a true crossing.
    import shapely

    ring = shapely.LineString(uv[np.r_[r.loops[0], r.loops[0][:1]]])
    assert np.all(shapely.distance(shapely.points(pts), ring) < 1e-9)


def test_seam_mismatch_limit(cup):
    free = patterns.flatten(cup.model, seams="free")
    report = patterns.check(free, max_seam_mismatch=0.001)
    worst = max(abs(s.mismatch) for s in report.seams)
    found = [f for f in well_formed(report, free).findings if f.code is Code.SEAM_MISMATCH_ABOVE_LIMIT]
    assert len(found) == sum(abs(s.mismatch) > 0.001 for s in report.seams) >= 1
    for f in found:
        (row,) = [s for s in report.seams if s.id == f.seam]
        assert f.panels == row.panels and abs(row.mismatch) > 0.001
        assert f.message == (f"seam {row.id} ({row.panels[0]} / {row.panels[1]}): flat lengths "
                             f"{row.length_flat[0]:.2f} and {row.length_flat[1]:.2f} mm differ by "
                             f"{abs(row.mismatch):.2f} mm (limit 0.001 mm)")
    assert worst > 0.001
    assert patterns.check(free, max_seam_mismatch=10.0).ok


def test_seams_held_at_their_length_and_a_seam_that_was_not(cup):
    """Seam-true flattening (the default): each side as long as the 3D polyline it
    is laid along, so both sides equal; a relaxation stopped early is reported."""
    report = patterns.check(cup, max_seam_mismatch=0.01)
    assert report.ok
    for s in report.seams:
        assert s.length_held == pytest.approx((s.length_3d_polyline, s.length_3d_polyline), rel=1e-12)
        for flat in s.length_flat:
            assert flat == pytest.approx(s.length_3d_polyline, rel=2e-4)
    short = patterns.flatten(cup.model, max_iterations=2)
    report = well_formed(patterns.check(short), short)
    findings = [f for f in report.findings if f.code is Code.SEAM_LENGTH_NOT_KEPT]
    assert findings and all(f.severity is Severity.LIMIT and f.seam is not None for f in findings)
    for f in findings:  # the side furthest off its held length, with its numbers
        (row,) = [s for s in report.seams if s.id == f.seam]
        side = int(np.argmax([abs(row.length_flat[k] / row.length_held[k] - 1) for k in (0, 1)]))
        got, want = row.length_flat[side], row.length_held[side]
        assert abs(got / want - 1) > 1e-3
        # the cause that occurred, as the panel's own flattening says it: here the iterations ran out
        flattening = short.panels[[p.name for p in short.panels].index(row.panels[side])].flattening
        assert flattening.n_folded == 0 and not flattening.converged
        cause = (f"the relaxation stopped after {flattening.iterations} iterations, before the held lengths were "
                 f"reached: give max_iterations more")
        assert f.message == (f"seam {row.id} ({row.panels[0]} / {row.panels[1]}): could not be held at its length "
                             f"({cause}): {got:.2f} mm flat on {row.panels[side]}'s side, {want:.2f} mm wanted "
                             f"({100 * (got / want - 1):+.2f} %)")


def test_json_report_round_trips_with_its_schema(cup, tmp_path):
    report = patterns.check(cup, max_strain=0.03)
    path = tmp_path / "cup.json"
    patterns.write(cup, path, max_strain=0.03)
    doc = json.loads(path.read_text())
    assert doc["schema"] == "patterns.report/5" and doc["ok"] is False and doc["pattern"] == "cup.step"
    assert doc["limits"] == {"max_strain": 0.03, "max_seam_mismatch": None, "area_tolerance": 0.05,
                             "max_distortion": 2.0}
    assert [p["name"] for p in doc["panels"]] == ["face0", "face1", "face2", "face3"]
    for p, numbers in zip(doc["panels"], report.panels):
        assert p["strain_rms"] == numbers.strain_rms and p["area_3d"] == numbers.area_3d
    for s, numbers in zip(doc["seams"], report.seams):
        assert s["length_flat"] == list(numbers.length_flat) and s["mismatch"] == numbers.mismatch
        assert s["length_held"] == list(numbers.length_held)
    assert {f["code"] for f in doc["findings"]} == {"strain-above-limit"}
    assert all(len(f["points"][0]) == 2 for f in doc["findings"])
    # every point where the DXF of the same pattern draws it: each finding's worst triangle inside its piece
    pieces = {p["name"]: shapely.Polygon(np.array(p["outline"])[:, :2]) for p in doc["pieces"]}
    for f in doc["findings"]:
        (name,) = f["panels"]
        assert pieces[name].contains(shapely.Point(f["points"][0]))
        assert f in [g for p in doc["pieces"] if p["name"] == name for g in p["findings"]]
    with pytest.raises(ExportError):
        patterns.write(cup, tmp_path / "missing" / "r.json")
    assert not (tmp_path / "missing").exists()


@pytest.mark.parametrize("suffix", [".png", ".svg"])
def test_heat_map_is_written(cup, tmp_path, suffix):
    path = tmp_path / f"cup{suffix}"
    patterns.heat_map(cup, path, max_strain=0.05)
    data = path.read_bytes()
    if suffix == ".png":
        assert data[:8] == b"\x89PNG\r\n\x1a\n"
        import matplotlib.image

        img = matplotlib.image.imread(path)
        assert img.shape[0] > 500 and img.shape[1] > 800
        # Both ends of the diverging scale are used: red (stretched) and blue (compressed) pixels.
        rgb = img[..., :3]
        assert np.any((rgb[..., 0] > 0.6) & (rgb[..., 2] < 0.4)) and np.any((rgb[..., 2] > 0.6) & (rgb[..., 0] < 0.4))
    else:
        text = data.decode()
        assert text.lstrip().startswith("<?xml") and "<svg" in text
        for name in ("face0", "face1", "face2", "face3", "s0"):
            assert name in text
    leftovers = [p for p in tmp_path.iterdir() if p.name.endswith(".part")]
    assert leftovers == []


def test_bad_check_input(cup, tmp_path):
    with pytest.raises(InputError, match="max_strain"):
        patterns.check(cup, max_strain=-1)
    with pytest.raises(InputError, match="takes a patterns.Pattern"):
        patterns.check("cup")
    with pytest.raises(InputError, match="heat maps are written as"):
        patterns.heat_map(cup, tmp_path / "x.jpg")
    with pytest.raises(InputError, match="placements"):
        cup.placed([(0, 0, 0)])


@pytest.mark.parametrize(("stretch", "expected", "opposite"), [(1.02, (103, 0, 31), (5, 48, 97)),
                                                               (0.98, (5, 48, 97), (103, 0, 31))])
def test_heat_map_colours_a_known_strain(tmp_path, stretch, expected, opposite):
    """A panel stretched by 2 % everywhere (flat longer than the surface) is drawn in the scale's
    red end at a 2 % limit, one squeezed by 2 % in its blue end (RdBu_r: (103, 0, 31) and (5, 48, 97))."""
    import dataclasses

    from PIL import Image

    exact = patterns.flatten(patterns.load(SAMPLES / "hopper.step"))
    flat = exact.panels[0]
    scaled = dataclasses.replace(flat.flattening, uv=flat.flattening.uv * stretch, method="relaxed")
    pattern = dataclasses.replace(exact, panels=(dataclasses.replace(flat, flattening=scaled),), seams=())
    assert np.allclose(pattern.panels[0].strains.dominant, stretch - 1.0, atol=1e-3)  # the chords
    path = tmp_path / "heat.png"
    patterns.heat_map(pattern, path, max_strain=0.02)
    pixels = np.asarray(Image.open(path).convert("RGB")).reshape(-1, 3).astype(int)

    def share(colour):
        return np.mean(np.abs(pixels - np.array(colour)).max(axis=1) <= 6)

    assert share(expected) > 0.05  # the panel (and the end of the colour bar)
    assert share(expected) > 20 * share(opposite)  # the other end only on the colour bar


# --------------------------------------------------------------------------- #
# Every finding code, produced (issue 17: codes no test made)
# --------------------------------------------------------------------------- #


def _with_uv(pattern, index, uv):
    """The pattern with panel ``index`` laid at ``uv`` instead (its overlap verdict recomputed)."""
    from dataclasses import replace

    flat = pattern.panels[index]
    moved = replace(flat.flattening, uv=uv, overlap=patterns.overlap_verdict(uv, flat.faces, flat.loops))
    panels = list(pattern.panels)
    panels[index] = replace(flat, flattening=moved)
    return replace(pattern, panels=tuple(panels))


@pytest.fixture(scope="module")
def holed():
    """A plate with a round hole through it: (pattern, index of a panel with a hole)."""
    import build123d as bd

    pattern = patterns.flatten(patterns.load(bd.Box(200, 100, 50) - bd.Cylinder(20, 50), max_edge=10))
    return pattern, next(i for i, flat in enumerate(pattern.panels) if len(flat.loops) == 2)


def well_formed(report, pattern):
    """Every finding as documented (patterns.audit.Finding): a Code and a Severity, the names of the
    pattern's panels it is about, points (k, 2) float64 and faces (j,) int64 of that panel (read-only),
    the seam's id or None, a one-line message starting with what it is about."""
    names = [flat.name for flat in pattern.panels]
    seams = {fs.seam.id for fs in pattern.seams}
    for f in report.findings:
        assert isinstance(f.code, Code) and isinstance(f.severity, Severity)
        assert isinstance(f.panels, tuple) and all(name in names for name in f.panels), f
        assert f.points.dtype == np.float64 and f.points.ndim == 2 and f.points.shape[1] == 2
        assert f.faces.dtype == np.int64 and f.faces.ndim == 1
        assert not f.points.flags.writeable and not f.faces.flags.writeable
        if len(f.faces):
            assert f.faces.max() < len(pattern.panels[names.index(f.panels[0])].faces)
        assert f.seam is None or f.seam in seams
        assert "\n" not in f.message
        if f.seam is not None:
            assert f.message.startswith(f"seam {f.seam} ({f.panels[0]} / {f.panels[1]}): ")
        elif len(f.panels) == 2:
            assert f.message.startswith(f"panels {f.panels[0]} and {f.panels[1]} ")
        else:
            assert f.message.startswith(f"panel {f.panels[0]}: ")
    return report


def _codes(pattern):
    return {f.code for f in well_formed(patterns.check(pattern), pattern).findings}


def test_outline_crossing_itself_is_a_finding():
    from patterns.reading import mesh_model

    st, f = surfaces.grid_mesh(60, 4)
    s_, t_ = st[:, 0] * 600.0, st[:, 1] * 20.0
    strip = patterns.flatten(mesh_model(np.column_stack([s_, t_, np.zeros(len(st))]), f), method="isometric")
    angle, radius = s_ / 600.0 * 2.4 * np.pi, 100.0 + t_  # bent round past a full turn: the ends cross
    bent = _with_uv(strip, 0, np.column_stack([radius * np.cos(angle), radius * np.sin(angle)]))
    assert Code.OUTLINE_CROSSES_ITSELF in _codes(bent) and Code.OUTLINE_CROSSES_ITSELF not in _codes(strip)
    (found,) = [f for f in patterns.check(bent).findings if f.code is Code.OUTLINE_CROSSES_ITSELF]
    assert found.message == (f"panel {strip.panels[0].name}: its outline crosses itself at {len(found.points)} points "
                             f"(first: ({found.points[0, 0]:.1f}, {found.points[0, 1]:.1f}) mm)")


def test_a_mirrored_panel_is_inside_out(cup):
    uv = np.array(cup.panels[0].uv) * [-1.0, 1.0]  # a mirror image: the outline runs clockwise
    codes = _codes(_with_uv(cup, 0, uv))
    assert Code.INSIDE_OUT in codes and Code.INSIDE_OUT not in _codes(cup)


@pytest.mark.parametrize(("how", "code", "words"), [
    ("far", Code.HOLE_OUTSIDE_OUTLINE, "hole 1 lies outside the outline, near ("),
    ("onto the edge", Code.HOLE_CROSSES_OUTLINE, "hole 1 crosses the outline at "),
    ("twisted", Code.HOLE_CROSSES_OUTLINE, "hole 1 crosses itself at 1 points")])
def test_a_misplaced_hole_is_a_finding(holed, how, code, words):
    pattern, i = holed
    flat = pattern.panels[i]
    uv = np.array(flat.uv)
    hole = flat.loops[1]
    centre = uv[hole].mean(axis=0)
    if how == "onto the edge":  # the hole's centre onto the outline: it straddles the edge
        outline = uv[flat.loops[0]]
        uv[hole] += outline[np.argmin(np.linalg.norm(outline - centre, axis=1))] - centre
    elif how == "far":
        uv[hole] += [1000.0, 0.0]
    else:  # two neighbours of the hole's ring swapped: the ring crosses itself once, between them
        uv[hole[[3, 4]]] = uv[hole[[4, 3]]]
    moved = _with_uv(pattern, i, uv)
    assert code in _codes(moved)
    assert code not in _codes(pattern)
    (found,) = [f for f in patterns.check(moved).findings if f.code is code]
    assert found.message.startswith(f"panel {flat.name}: {words}")


def test_a_panel_laid_at_the_wrong_size_is_not_usable(cup):
    """Scaled by 0.9 (the flat piece 19 % smaller than the surface it is cut for) a panel is an error
    whatever limit was asked; the message's change is the shapely area of the scaled outline against
    the surface's area.  Stretched 2.2 times one way and squeezed as much the other (the area kept)
    it is grossly distorted instead."""
    flat = cup.panels[0]
    small = _with_uv(cup, 0, flat.uv * 0.9)
    (found,) = [f for f in patterns.check(small).findings if f.code is Code.AREA_NOT_KEPT]
    area_3d = float(np.sum(np.linalg.norm(np.cross(*(flat.vertices[flat.faces[:, k]] - flat.vertices[flat.faces[:, 0]]
                                                        for k in (1, 2))), axis=1)) / 2)
    change = shapely.Polygon(flat.uv[flat.loops[0]] * 0.9).area / area_3d - 1
    assert found.severity is Severity.ERROR and found.panels == (flat.name,)
    assert f"is {abs(change):.1%} smaller than its 3D area" in found.message
    assert Code.AREA_NOT_KEPT not in _codes(cup) and not patterns.check(small).ok
    assert Code.AREA_NOT_KEPT not in _codes(_with_uv(cup, 0, flat.uv * 0.99))  # 2 % smaller: within 5 %
    assert Code.AREA_NOT_KEPT not in {f.code for f in patterns.check(small, area_tolerance=None).findings}
    skewed = _with_uv(cup, 0, flat.uv * [2.2, 1 / 2.2])
    codes = _codes(skewed)
    assert Code.GROSSLY_DISTORTED in codes and Code.AREA_NOT_KEPT not in codes
    (gross,) = [f for f in patterns.check(skewed).findings if f.code is Code.GROSSLY_DISTORTED]
    assert "100.0% of its area is laid flat at more than 2 times its size" in gross.message
    assert len(gross.faces) == len(flat.faces)
    assert Code.GROSSLY_DISTORTED not in _codes(_with_uv(cup, 0, flat.uv * [1.7, 1 / 1.7]))  # x 1.7 x its 12 %: < 2
    assert Code.GROSSLY_DISTORTED not in _codes(cup)
    assert Code.GROSSLY_DISTORTED not in {f.code for f in patterns.check(skewed, max_distortion=None).findings}


def test_two_placed_panels_that_overlap_are_found(cup):
    """A pattern of just two panels, placed overlapping: the overlap is found (and not once placed apart)."""
    from dataclasses import replace

    two = replace(cup, panels=cup.panels[:2], seams=())
    width = np.ptp(cup.panels[0].uv[:, 0])
    assert Code.PANELS_OVERLAP in _codes(two.placed([(0.0, 0.0, 0.0), (0.0, 0.4 * width, 0.0)]))
    assert Code.PANELS_OVERLAP not in _codes(two.placed([(0.0, 0.0, 0.0), (0.0, 3 * width, 0.0)]))


def test_a_panel_squeezed_to_less_than_half_is_grossly_distorted(cup):
    """Squeezed to 0.4 of its width (stretched nowhere), the panel is laid at 1/2.5 of its size across:
    grossly distorted, as a panel stretched 2.5 times would be; the area finding is placed at the worst
    strain the panel's report gives."""
    flat = cup.panels[0]
    for squeeze in ([0.4, 1.0], [1.0, 0.4]):
        squeezed = _with_uv(cup, 0, flat.uv * squeeze)
        report = well_formed(patterns.check(squeezed), squeezed)
        codes = {f.code for f in report.findings}
        assert Code.GROSSLY_DISTORTED in codes and Code.AREA_NOT_KEPT in codes
        (area,) = [f for f in report.findings if f.code is Code.AREA_NOT_KEPT]
        np.testing.assert_array_equal(area.points, [report.panels[0].strain_max_at])


def test_a_collapsed_triangle_counts_as_folded_in_the_report():
    """A triangle laid flat with no area (a vertex on the opposite side) is folded: the report's
    n_folded counts it, as the signed areas say."""
    from patterns.reading import mesh_model

    st, f = surfaces.grid_mesh(6, 6)
    v = np.column_stack([st * 50.0, np.zeros(len(st))])
    plane = patterns.flatten(mesh_model(v, f), method="isometric")
    flat = plane.panels[0]
    uv = np.array(flat.uv)
    boundary = np.zeros(len(uv), dtype=bool)
    boundary[np.concatenate(flat.loops)] = True
    a, b, c = next(t for t in flat.faces if not boundary[t].any())  # an interior triangle
    uv[c] = (uv[a] + uv[b]) / 2
    collapsed = _with_uv(plane, 0, uv)
    sa = patterns.measure.signed_areas(uv, flat.faces)
    assert np.any(sa == 0.0)
    report = well_formed(patterns.check(collapsed), collapsed)
    assert report.panels[0].n_folded == int(np.count_nonzero(sa <= 0.0)) > 0


def test_a_speck_laid_at_the_wrong_size_is_not_usable_either():
    """The area rule holds at any size: a 1 x 0.5 mm piece laid at 0.9 of its size is 19 % short."""
    from patterns.reading import mesh_model

    st, f = surfaces.grid_mesh(3, 3)
    speck = patterns.flatten(mesh_model(np.column_stack([st * [1.0, 0.5], np.zeros(len(st))]), f),
                             method="isometric")
    assert speck.panels[0].area == pytest.approx(0.5, rel=1e-9)
    small = _with_uv(speck, 0, speck.panels[0].uv * 0.9)
    (found,) = [f for f in patterns.check(small).findings if f.code is Code.AREA_NOT_KEPT]
    assert "is 19.0% smaller than its 3D area 0.5 mm^2" in found.message
    assert Code.AREA_NOT_KEPT not in _codes(speck)


def test_a_report_made_by_hand_says_loading_did_nothing(cup):
    """A Report built without its loading (a plugin's own): its dict says nothing was done."""
    from patterns.audit import Report

    made = Report(pattern="by hand", panels=(), seams=(), findings=())
    assert made.to_dict()["loading"] == {"welded": 0, "unused": 0, "cuts": 0, "split": 0, "units": "mm",
                                         "said": str(patterns.Bookkeeping())}


def test_an_options_record_is_honoured_and_findings_come_errors_first(cup):
    """check(pattern, CheckOptions(...)) judges by the record, as check(pattern, **keywords) does; the
    findings come errors first, then exceeded limits, then notes."""
    from patterns.audit import CheckOptions

    squeezed = _with_uv(cup, 0, cup.panels[0].uv * [1.0, 0.4])  # an error (area), limits (strain)
    short = patterns.flatten(cup.model, max_iterations=2)  # notes (not converged)
    from dataclasses import replace

    mixed = replace(squeezed, panels=squeezed.panels[:1] + short.panels[1:])
    by_record = patterns.check(mixed, CheckOptions(max_strain=0.001))
    by_keyword = patterns.check(mixed, max_strain=0.001)
    assert [f.message for f in by_record.findings] == [f.message for f in by_keyword.findings]
    assert by_record.max_strain == 0.001 and patterns.check(mixed).max_strain != 0.001
    severities = [f.severity for f in by_record.findings]
    assert {Severity.ERROR, Severity.LIMIT, Severity.NOTE} <= set(severities)
    rank = {Severity.ERROR: 0, Severity.LIMIT: 1, Severity.NOTE: 2}
    assert [rank[x] for x in severities] == sorted(rank[x] for x in severities)


def test_a_seam_finding_is_placed_at_the_seam_s_middle(cup):
    """A seam's finding points at the middle of the seam as laid flat (on its first panel): on the flat
    polyline, half way along it (within one segment)."""
    free = patterns.flatten(cup.model, seams="free")
    report = patterns.check(free, max_seam_mismatch=0.001)
    found = [f for f in report.findings if f.code is Code.SEAM_MISMATCH_ABOVE_LIMIT]
    assert found
    for f in found:
        (fs,) = [fs for fs in free.seams if fs.seam.id == f.seam]
        line = shapely.LineString(free.panels[fs.seam.panels[0]].uv[fs.seam.vertices[0]])
        at = shapely.Point(f.points[0])
        assert line.distance(at) < 1e-9
        step = max(np.linalg.norm(np.diff(np.asarray(line.coords), axis=0), axis=1))
        assert abs(line.project(at) - line.length / 2) <= step


def test_a_relaxation_stopped_early_is_a_note(cup):
    short = patterns.flatten(cup.model, max_iterations=2)
    found = [f for f in patterns.check(short).findings if f.code is Code.NOT_CONVERGED]
    assert found and all(f.severity is Severity.NOTE for f in found)
    assert Code.NOT_CONVERGED not in _codes(cup)


def test_every_finding_code_is_produced_by_a_test():
    """Each Code appears in some test of this suite (besides this one)."""
    import pathlib

    here = pathlib.Path(__file__).parent
    text = "".join(p.read_text() for p in here.glob("test_*.py")).replace(
        test_every_finding_code_is_produced_by_a_test.__doc__, "")
    missing = [c.name for c in Code if f"Code.{c.name}" not in text]  # Code.X or patterns.Code.X
    assert not missing, missing


def test_the_json_report_is_the_documented_schema(cup, tmp_path):
    """The report of the cup at 3 % has exactly the keys, units and (rounded) numbers of the
    example in docs/report.md, is indented by two spaces in the order shown, and a folder that
    does not exist is refused naming the report."""
    import json
    import pathlib
    import re

    doc = (pathlib.Path(__file__).parent.parent / "docs" / "report.md").read_text()
    example = json.loads(re.search(r"```json\n(.*?)\n```", doc, re.S).group(1))
    path = tmp_path / "cup.json"
    patterns.write(cup, path, max_strain=0.03)
    text = path.read_text(encoding="utf-8")
    got = json.loads(text)
    assert list(got) == list(example)  # the same keys, in the documented order
    assert text.startswith('{\n  "schema": "patterns.report/5",\n  "pattern": "cup.step"') and text.endswith("}\n")
    assert got["units"] == example["units"] and got["limits"] == example["limits"]
    for key in ("panels", "seams", "findings"):
        assert set(got[key][0]) == set(example[key][0]), key
    for key in ("panels", "seams"):
        for name, value in example[key][0].items():
            if isinstance(value, float) or (isinstance(value, list) and value and isinstance(value[0], float)):
                assert got[key][0][name] == pytest.approx(value, abs=1e-4), name
            else:
                assert got[key][0][name] == value, name
    assert got["findings"][0]["code"] == example["findings"][0]["code"]
    assert got["findings"][0]["message"] == example["findings"][0]["message"]
    with pytest.raises(patterns.ExportError, match="cannot write the report"):
        patterns.write(cup, tmp_path / "missing" / "cup.json")
