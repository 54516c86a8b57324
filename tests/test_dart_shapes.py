"""Darts on curved shapes other than spheres (issue 36): the surface's curvature, and a report that
never says the limit was met when it was not."""

import itertools

import numpy as np
import pytest

import patterns
from patterns import samples
from patterns.measure import angle_defects, triangle_strains

LIMIT = 0.03


def test_angle_defects_are_a_cones_deficit_and_nothing_on_a_plane_or_a_cylinder():
    """Gaussian curvature gathered at the vertices: a cone's apex holds 2 pi (1 - sin a) for a
    half-angle a (its surface unrolls to a sector of 2 pi sin a); a plane's and a cylinder's
    interior vertices hold none."""
    n, alpha = 24, np.radians(35.0)
    ring = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    cone = np.vstack([[0.0, 0.0, 0.0], np.column_stack([np.sin(alpha) * np.cos(ring), np.sin(alpha) * np.sin(ring),
                                                          np.full(n, -np.cos(alpha))]) * 50.0])
    faces = np.array([[0, 1 + i, 1 + (i + 1) % n] for i in range(n)])
    rim = np.arange(1, n + 1)
    d = angle_defects(cone, faces, loops=[rim])
    # The apex angles of the fan, exactly: each triangle's apex angle from its chord.
    chord = 2 * np.sin(alpha) * np.sin(np.pi / n)
    assert d[0] == pytest.approx(2 * np.pi - n * 2 * np.arcsin(chord / 2), rel=1e-12)
    assert d[0] == pytest.approx(2 * np.pi * (1 - np.sin(alpha)), rel=4e-3)  # 24 chords: 0.26 % off the smooth cone
    assert np.all(d[rim] == 0.0)
    # A cylinder of radius 40 (8 x 12 grid, closed round) and a plane: no defect inside.
    theta, z = np.meshgrid(np.linspace(0, 2 * np.pi, 12, endpoint=False), np.linspace(0, 100, 8))
    cyl = np.column_stack([40 * np.cos(theta.ravel()), 40 * np.sin(theta.ravel()), z.ravel()])
    quads = [(r * 12 + c, r * 12 + (c + 1) % 12, (r + 1) * 12 + (c + 1) % 12, (r + 1) * 12 + c)
             for r in range(7) for c in range(12)]
    tri = np.array([t for a, b, c, e in quads for t in ((a, b, c), (a, c, e))])
    inside = np.arange(12, 12 * 7)
    assert np.abs(angle_defects(cyl, tri)[inside]).max() < 1e-12
    plane = cyl.copy()
    plane[:, 0], plane[:, 1] = theta.ravel() * 40, z.ravel() * 0 + plane[:, 2]
    plane[:, 2] = 0.0
    flat_quads = [(r * 12 + c, r * 12 + c + 1, (r + 1) * 12 + c + 1, (r + 1) * 12 + c) for r in range(7) for c in range(11)]
    flat_tri = np.array([t for a, b, c, e in flat_quads for t in ((a, b, c), (a, c, e))])
    interior = [r * 12 + c for r in range(1, 7) for c in range(1, 11)]
    assert np.abs(angle_defects(plane, flat_tri)[interior]).max() < 1e-12


def test_the_gore_bound_of_a_spherical_cap_is_the_analytic_one():
    """k >= C sqrt(K / limit) / 4 over the cap's circles: on a cap of half-angle a of a sphere, the
    rim's circle 2 pi R sin a and K = 1 / R^2 give pi sin a / (2 sqrt(limit)) (9.07 for a hemisphere
    at 3 %), whatever the radius; a plane asks for none."""
    from patterns import surfaces
    from patterns.flattening.curvature import gore_bound

    for radius, half_angle in ((150.0, 90.0), (80.0, 60.0)):
        v, f = surfaces.spherical_cap(radius=radius, half_angle=half_angle, n_faces=6000)
        plain = patterns.flatten_mesh(v, f)
        expected = np.pi * np.sin(np.radians(half_angle)) / (2 * np.sqrt(LIMIT))
        assert gore_bound(plain, LIMIT) == pytest.approx(expected, rel=0.1)  # measured: within 8 %
        assert gore_bound(plain, 4 * LIMIT) == pytest.approx(gore_bound(plain, LIMIT) / 2, rel=1e-12)
    x, y = np.meshgrid(np.linspace(0, 100, 11), np.linspace(0, 50, 6))
    grid = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    quads = [(r * 11 + c, r * 11 + c + 1, (r + 1) * 11 + c + 1, (r + 1) * 11 + c) for r in range(5) for c in range(10)]
    tri = np.array([t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))])
    assert gore_bound(patterns.flatten_mesh(grid, tri), LIMIT) == 0.0


def profile_gore_bound(r, z, limit) -> float:
    """The gore bound of a surface of revolution from its profile (r, z), sampled finely: the
    parallel's length 2 pi r, K = (profile curvature) (sine of the normal's angle to the axis) / r;
    max over the profile of pi r sqrt(K / limit) / 2."""
    dr, dz = np.gradient(r), np.gradient(z)
    ddr, ddz = np.gradient(dr), np.gradient(dz)
    kappa = np.abs(dr * ddz - dz * ddr) / (dr ** 2 + dz ** 2) ** 1.5
    with np.errstate(divide="ignore", invalid="ignore"):
        k = np.pi * r / 2 * np.sqrt(np.maximum(kappa * np.abs(dz) / np.hypot(dr, dz) / r, 0.0) / limit)
    return float(np.nanmax(k[2:-2]))


def worst(flat) -> float:
    return float(triangle_strains(flat.vertices, flat.faces, flat.uv).magnitude.max())


@pytest.mark.slow
@pytest.mark.parametrize("name", ["prolate dome", "freeform cup"])
def test_a_prolate_dome_and_an_asymmetric_cup_meet_the_limit(name):
    """Curvature where it is: at the prolate dome's top (its sides are nearly a cylinder), in the
    asymmetric cup towards +x. At most 12 darts, every triangle within 3 % (measured here), one-to-one,
    legs that sew, and a report that says it is ok."""
    model = patterns.load(samples.DOMES[name]())
    pattern = patterns.flatten(model, max_strain=LIMIT)
    (flat,) = pattern.panels
    assert 1 <= len(flat.darts) <= 12 and worst(flat) <= LIMIT
    assert flat.flattening.one_to_one and flat.flattening.n_folded == 0
    for dart in flat.darts:
        a, b = dart.leg_lengths(flat.uv)
        assert abs(a - b) < 0.1
    assert flat.dart_search.met and flat.dart_search.sewn
    report = patterns.check(pattern)
    assert report.ok
    (note,) = [f.message for f in report.findings if f.code is patterns.Code.DARTS]
    assert "to keep the strain within the limit" in note


def bowl_profile():
    import build123d as bd

    profile = bd.Edge.make_spline([(0, 0, 0), (60, 0, 8), (90, 0, 30), (100, 0, 60)])
    points = np.array([tuple(profile.position_at(t)) for t in np.linspace(0, 1, 4001)])
    return points[:, 0], points[:, 2]


def oblate_profile():
    theta = np.linspace(0, np.pi / 2, 4001)
    return 150 * np.cos(theta), 90 * np.sin(theta)


@pytest.mark.slow
@pytest.mark.parametrize("name, profile", [("spline bowl", bowl_profile), ("oblate dome", oblate_profile)])
def test_where_twelve_darts_are_too_few_the_report_says_so_and_why(name, profile):
    """Darts only (``max_gores=0``): the issue's bowl (a spline through (0, 0), (60, 8), (90, 30), (100, 60) revolved) and oblate
    dome (a quarter ellipse 150 x 90 revolved): their curvature asks for 12.7 and 15.1 balanced gores
    at 3 % (the gore bound, computed here from the profile), and darts take about 1.2 times as many
    (a hemisphere: 11 against 9.07), so 12 darts do not bring them within it. At most 12 darts,
    one-to-one, the strain at least halved against the dartless flattening, legs that sew (or a note
    that says how far apart they are), and a note that says the limit was not met, with the worst
    triangle's strain as measured here and the number of darts the curvature asks for."""
    model = patterns.load(samples.DOMES[name]())
    (plain,) = patterns.flatten(model).panels
    pattern = patterns.flatten(model, max_strain=LIMIT, max_gores=0)  # darts only: the panel is not parted
    (flat,) = pattern.panels
    assert 1 <= len(flat.darts) <= 12
    assert flat.flattening.one_to_one and flat.flattening.n_folded == 0
    assert worst(flat) < 0.5 * worst(plain)
    search = flat.dart_search
    apart = max(abs(a - b) for a, b in (dart.leg_lengths(flat.uv) for dart in flat.darts))
    if search.sewn:
        assert apart < 0.1
    assert search.worst == pytest.approx(worst(flat), rel=1e-12) and search.met == (worst(flat) <= LIMIT)
    assert search.before == pytest.approx(worst(plain), rel=1e-9)
    expected = profile_gore_bound(*profile(), LIMIT)
    assert 1.2 * expected > 12 and search.needed == pytest.approx(expected, rel=0.1)
    report = patterns.check(pattern)
    (note,) = [f.message for f in report.findings if f.code is patterns.Code.DARTS]
    if not search.met:
        assert not report.ok and "within the limit" not in note
        assert f"best reached is {worst(flat):.2%}" in note and "was not met within 12 darts" in note
        assert f"asks for about {search.needed:.1f} darts" in note and "allow more darts, or cut gores" in note
    # Legs that could not be sewn to one length are said, with how far apart they are (measured here).
    assert ("could not be held to equal lengths" in note) == (not search.sewn)
    if not search.sewn:
        assert f"up to {apart:.2f} mm apart" in note


def test_a_saddle_is_slashed_and_its_wedges_become_inserts_every_piece_within_the_limit(tmp_path):
    """Negative curvature everywhere (z = (x^2 - y^2) / 400): a dart would take out material a saddle
    does not have to spare; it is slashed from its outline instead, each slash's wedge cut out as an
    insert sewn back into it. Every piece within 3 % (measured here), one-to-one, no dart; the pieces
    are the surface cut up (their 3D areas add up to the face's); each insert's two seams are as long
    flat as in 3D and their sides equal (within 0.2 mm, from the points); the DXF, read back, has
    every piece at its flat area; the note names the inserts and the slashes' tips."""
    import ezdxf
    import shapely

    model = patterns.load(samples.DOMES["saddle"]())
    (plain,) = patterns.flatten(model).panels
    assert worst(plain) > LIMIT
    pattern = patterns.flatten(model, max_strain=LIMIT)
    main, *inserts = pattern.panels
    assert main.name == model.panels[0].name and main.panel.insert_into is None
    assert 1 <= len(inserts) <= 12 and all(p.panel.insert_into == main.name for p in inserts)
    assert all(worst(p) <= LIMIT and not p.darts and p.flattening.one_to_one for p in pattern.panels)
    assert sum(p.panel.area for p in pattern.panels) == pytest.approx(model.panels[0].area, rel=1e-9)
    assert len(pattern.seams) == 2 * len(inserts)
    for fs in pattern.seams:
        assert fs.seam.panels[0] == 0 or fs.seam.panels[1] == 0
        in_3d = float(np.linalg.norm(np.diff(fs.seam.points, axis=0), axis=1).sum())
        sides = [np.linalg.norm(np.diff(pattern.panels[p].uv[np.asarray(idx)], axis=0), axis=1).sum()
                 for p, idx in zip(fs.seam.panels, fs.seam.vertices)]
        assert abs(sides[0] - sides[1]) < 0.2 and abs(sides[0] - in_3d) < 0.2
    report = patterns.check(pattern)
    assert report.ok
    (note,) = [f for f in report.findings if f.code is patterns.Code.INSERTS]
    assert all(p.name in note.message for p in inserts) and "not met" not in note.message
    assert len(note.points) == len(inserts)  # one tip to a slash
    assert not [f for f in report.findings if f.code is patterns.Code.DARTS]
    patterns.write(pattern, tmp_path / "saddle.dxf")
    msp = ezdxf.readfile(tmp_path / "saddle.dxf").modelspace()
    read = sorted(shapely.Polygon(e.get_points("xy")).area for e in msp.query('LWPOLYLINE[layer=="CUT"]'))
    np.testing.assert_allclose(read, sorted(p.area for p in pattern.panels), rtol=1e-4)  # DXF: 0.001 mm
    # Too few slashes allowed: the note says the limit was not met, and the worst piece.
    short = patterns.flatten(model, max_strain=LIMIT, max_darts=2)
    (note,) = [f.message for f in patterns.check(short).findings if f.code is patterns.Code.INSERTS]
    worst_piece = max(short.panels, key=worst)
    assert 1 < len(short.panels) <= 3 and worst(worst_piece) > LIMIT
    assert f"not met: the worst piece reaches {worst(worst_piece):.2%} (panel {worst_piece.name})" in note


def test_a_saddle_in_gores_meets_the_limit():
    """``gores=True`` on the saddle: every piece within 3 %, the two sides of every new seam equal."""
    model = patterns.load(samples.DOMES["saddle"]())
    gored = patterns.flatten(model, max_strain=LIMIT, gores=True)
    assert len(gored.panels) > 1 and all(worst(p) <= LIMIT for p in gored.panels)
    assert not any(p.panel.insert_into for p in gored.panels)
    for fs in gored.seams[len(model.seams):]:
        sides = [np.linalg.norm(np.diff(gored.panels[p].uv[np.asarray(idx)], axis=0), axis=1).sum()
                 for p, idx in zip(fs.seam.panels, fs.seam.vertices)]
        assert abs(sides[0] - sides[1]) < 0.2
    assert patterns.check(gored).ok


def _sides(pattern, fs):
    """A seam's two flat lengths, from its points on each piece (numpy polylines)."""
    return [float(np.linalg.norm(np.diff(pattern.panels[p].uv[np.asarray(idx)], axis=0), axis=1).sum())
            for p, idx in zip(fs.seam.panels, fs.seam.vertices)]


def assert_cut_up_and_sewn(pattern, face):
    """The pieces are ``face`` cut up (their 3D areas add up to its area) and every seam is as long
    flat on both sides as in 3D (0.2 mm, from the points)."""
    assert sum(p.panel.area for p in pattern.panels) == pytest.approx(face.area, rel=1e-9)
    for fs in pattern.seams:
        in_3d = float(np.linalg.norm(np.diff(fs.seam.points, axis=0), axis=1).sum())
        a, b = _sides(pattern, fs)
        assert abs(a - b) < 0.2 and abs(a - in_3d) < 0.2


@pytest.mark.slow
@pytest.mark.parametrize("name", ["spline bowl", "oblate dome"])
def test_the_bowl_and_the_oblate_dome_in_gores_meet_the_limit(name):
    """Issue 36: the issue's bowl and oblate dome in gores at 3 %: every gore within it (its own
    triangles' SVD strains), one-to-one, no darts; the gores are the face cut up (their 3D areas add
    up to the face's); each cut as long flat on both sides as in 3D (0.2 mm, from the points); at
    most ``max_gores`` (24), more than 12 darts' worth (their gore bound asks for 12-14 balanced
    gores, and held gores need more); the note names the gores and does not say "not met"."""
    model = patterns.load(samples.DOMES[name]())
    pattern = patterns.flatten(model, max_strain=LIMIT, gores=True)
    face = model.panels[0].name
    assert 12 < len(pattern.panels) <= 24 and all(p.panel.gore_of == face for p in pattern.panels)
    assert all(worst(p) <= LIMIT and p.flattening.one_to_one and not p.darts for p in pattern.panels)
    assert_cut_up_and_sewn(pattern, model.panels[0])
    report = patterns.check(pattern)
    assert report.ok
    (note,) = [f for f in report.findings if f.code is patterns.Code.GORES]
    assert f"split into {len(pattern.panels)} gores" in note.message and "not met" not in note.message
    assert set(note.panels) == {p.name for p in pattern.panels}


@pytest.mark.slow
@pytest.mark.parametrize("name", ["spline bowl", "ellipsoid", "torus patch"])
def test_where_darts_alone_fall_short_the_panel_is_parted_and_every_piece_meets_the_limit(name):
    """Issue 36's acceptance, with darts (``max_strain`` alone, the defaults): every piece within 3 %
    (its own triangles' SVD strains), one-to-one, at most 12 darts each, legs that sew to one length,
    the pieces the face cut up (3D areas add up), every seam as long flat on both sides as in 3D
    (0.2 mm, from the points), and a report that is ok.  The bowl and the ellipsoid ask for more
    darts than 12 (1.2 x their gore bounds 11.9 and 12.0; the oblate dome's 13.7 likewise, measured in
    benchmarks/darts.py): they are parted into 3 or 4 pieces (a bound of at most 4 a piece, 3 at
    least) with darts, the note says so with each piece's darts; the torus patch, which darts do not bring within the limit in pieces either
    (docs/garments.md), ends in dartless gores, and the note says that."""
    model = patterns.load(samples.DOMES[name]())
    pattern = patterns.flatten(model, max_strain=LIMIT)
    face = model.panels[0].name
    assert len(pattern.panels) > 1 and all(p.panel.gore_of == face for p in pattern.panels)
    for p in pattern.panels:
        assert worst(p) <= LIMIT and p.flattening.one_to_one and p.flattening.n_folded == 0
        assert len(p.darts) <= 12 and (not p.darts or p.dart_search.met)
        for dart in p.darts:
            a, b = dart.leg_lengths(p.uv)
            assert abs(a - b) < 0.1
    assert_cut_up_and_sewn(pattern, model.panels[0])
    report = patterns.check(pattern)
    assert report.ok
    (note,) = [f for f in report.findings if f.code is patterns.Code.GORES]
    assert "not met" not in note.message and set(note.panels) == {p.name for p in pattern.panels}
    darts = [len(p.darts) for p in pattern.panels]
    if name == "torus patch":
        assert not any(darts) and f"split into {len(pattern.panels)} gores" in note.message
    else:
        assert 3 <= len(pattern.panels) <= 4 and all(darts)
        assert f"split into {len(pattern.panels)} pieces" in note.message
        assert f"with {', '.join(map(str, darts))} darts" in note.message


@pytest.mark.slow
@pytest.mark.parametrize("gores", [False, True])
def test_a_seats_saddle_shaped_waist_is_slashed_and_its_dome_parted(gores):
    """A seat (a dome beside a saddle-shaped waist, one face; positive curvature outweighs the
    negative, so the face is not saddle-shaped as a whole and is not slashed): parted, the piece at
    the waist (x < 0) is slashed and given inserts, not darted, the others are darted or within the
    limit as they are (in gores, ``gores=True``: the same, and no piece darted).  Every piece
    (inserts included) within 3 %, one-to-one; each insert sewn into a piece cut from the seat;
    every seam as long flat on both sides as in 3D (0.2 mm); the report ok."""
    model = patterns.load(samples.DOMES["seat"]())
    face = model.panels[0]
    defects = angle_defects(face.vertices, face.faces, loops=face.loops)
    assert np.maximum(defects, 0).sum() > np.maximum(-defects, 0).sum() > 0.5  # mixed, mostly positive
    pattern = patterns.flatten(model, max_strain=LIMIT, gores=gores)
    inserts = [p for p in pattern.panels if p.panel.insert_into is not None]
    pieces = [p for p in pattern.panels if p.panel.gore_of == face.name]
    assert inserts and len(pieces) + len(inserts) == len(pattern.panels)
    (slashed,) = {p.panel.insert_into for p in inserts}
    (waist,) = [p for p in pieces if p.name == slashed]
    assert not waist.darts and waist.panel.vertices[:, 0].mean() < 0  # the waist is at x = -70 mm, the dome at +70
    for p in pattern.panels:
        assert worst(p) <= LIMIT and p.flattening.one_to_one and len(p.darts) <= (0 if gores else 12)
    assert_cut_up_and_sewn(pattern, model.panels[0])
    assert patterns.check(pattern).ok


def test_where_the_gores_allowed_are_too_few_the_note_says_so_with_the_worst_strain_and_where():
    """The freeform cup (3 gores meet 3 %) allowed 2: the note says the limit was not met, with the
    worst gore's strain and the centre of its worst triangle (both measured here), and "allow more gores"."""
    from patterns.measure import triangle_strains

    model = patterns.load(samples.DOMES["freeform cup"]())
    pattern = patterns.flatten(model, max_strain=LIMIT, gores=True, max_gores=2)
    assert len(pattern.panels) == 2 and all(p.panel.gore_of == model.panels[0].name for p in pattern.panels)
    first = max(pattern.panels, key=worst)
    assert worst(first) > LIMIT
    report = patterns.check(pattern)
    assert not report.ok
    (note,) = [f for f in report.findings if f.code is patterns.Code.GORES]
    assert note.panels[0] == first.name
    assert f"not met: the worst gore reaches {worst(first):.2%}" in note.message
    assert "allow more gores (max_gores)" in note.message
    mag = triangle_strains(first.vertices, first.faces, first.uv).magnitude
    np.testing.assert_allclose(note.points[0], first.uv[first.faces[np.argmax(mag)]].mean(axis=0), atol=1e-9)


def test_a_cut_that_starts_inside_a_seam_parts_the_seam_too():
    """A cut from the middle of a seam (a slash or a gore line may start there) parts the seam: each
    run lies on one piece, the first keeps the seam's id and the others come after the model's seams,
    their points are the seam's own (sharing the point where the cut starts) and their lengths add up
    to the seam's; flattened, both sides of every seam stay as long as each other."""
    from patterns.cut import insert_line
    from patterns.flattening.split import split_panel

    model = patterns.load(samples.cup())  # four quarter-sphere panels sewn round a pole
    panel = model.panels[0]
    layout = patterns.flatten_mesh(panel.vertices, panel.faces)
    seam = max(model.seams_of(0), key=lambda s: len(s.points))
    side = seam.panels.index(0)
    middle = int(seam.vertices[side][len(seam.points) // 2])
    outline = np.asarray(layout.loops[0])
    far = int(outline[np.argmax(np.linalg.norm(layout.uv[outline] - layout.uv[middle], axis=1))])
    cut = insert_line(layout.vertices, layout.faces, layout.uv, layout.uv[middle], layout.uv[far])
    assert cut.path[0] == middle and cut.path[-1] == far
    split = split_panel(model, 0, (cut.vertices, cut.faces, [cut.path]))
    assert split is not None and len(split.panels) == len(model.panels) + 1
    assert [s.id for s in split.seams] == list(range(len(split.seams)))
    for s in split.seams:  # every side on one piece, at the seam's own points
        for p, idx in zip(s.panels, s.vertices):
            assert np.array_equal(split.panels[p].vertices[idx], s.points)
    runs = [s for s in split.seams if s.cad_edge == seam.cad_edge and s.cad_edge is not None]
    assert len(runs) == 2 and runs[0].id == seam.id and runs[1].id >= len(model.seams)
    assert np.array_equal(np.vstack([runs[0].points, runs[1].points[1:]]), seam.points)
    assert sum(r.length for r in runs) == pytest.approx(seam.length, rel=1e-12)
    pattern = patterns.flatten(split)
    for fs in pattern.seams:
        assert abs(fs.flat_lengths[0] - fs.flat_lengths[1]) < 0.01


def test_gores_need_at_least_one_gore_and_max_gores_0_keeps_darts_on_one_panel(tmp_path):
    """``max_gores=0`` means darts on the one panel only; with ``gores=True`` it is a contradiction,
    refused before any work (a patterns exception in the library, one line and exit 2 on the command
    line, nothing written)."""
    import subprocess
    import sys

    model = patterns.load(samples.DOMES["freeform cup"]())
    with pytest.raises(patterns.InputError, match="gores needs max_gores 1 or more"):
        patterns.flatten(model, max_strain=LIMIT, gores=True, max_gores=0)
    step = tmp_path / "cup.step"
    import build123d as bd

    bd.export_step(samples.DOMES["freeform cup"](), str(step))
    out = tmp_path / "cup.dxf"
    run = subprocess.run([sys.executable, "-m", "patterns", "flatten", str(step), "-o", str(out),
                          "--dart-strain", "0.03", "--gores", "--max-gores", "0"], capture_output=True, text=True,
                         check=False)
    assert run.returncode == 2 and len(run.stderr.strip().splitlines()) == 1 and "max-gores" in run.stderr
    assert not out.exists()


def test_a_panel_that_one_dart_cannot_bring_within_the_limit_is_parted_and_the_note_says_so():
    """The freeform cup allowed one dart: its curvature asks for about 1.2 x its gore bound (3.2), so
    no dart is tried on the one panel; it is parted into max(3, ceil(bound / 4)) pieces (the rule,
    docs/garments.md), each within 3 % (its own triangles' SVD strains) with at most one dart,
    one-to-one, the face cut up and sewn true; the note names the pieces.  With ``max_gores=0`` the
    one panel stays, with at most one dart, and the report says the limit was not met."""
    from patterns.flattening.curvature import gore_bound

    model = patterns.load(samples.DOMES["freeform cup"]())
    (plain,) = patterns.flatten(model).panels
    bound = gore_bound(plain.flattening, LIMIT)
    assert 1.2 * bound > 1
    pattern = patterns.flatten(model, max_strain=LIMIT, max_darts=1)
    assert len(pattern.panels) == max(3, int(np.ceil(bound / 4)))
    for p in pattern.panels:
        assert p.panel.gore_of == model.panels[0].name and len(p.darts) <= 1
        assert worst(p) <= LIMIT and p.flattening.one_to_one
    assert_cut_up_and_sewn(pattern, model.panels[0])
    report = patterns.check(pattern)
    assert report.ok
    (note,) = [f for f in report.findings if f.code is patterns.Code.GORES]
    assert set(note.panels) == {p.name for p in pattern.panels} and "not met" not in note.message
    (alone,) = patterns.flatten(model, max_strain=LIMIT, max_darts=1, max_gores=0).panels
    assert len(alone.darts) <= 1 and worst(alone) > LIMIT and not alone.dart_search.met


def test_progress_moves_through_the_search_and_never_back():
    """``flatten(progress=)`` while the freeform cup is parted into pieces with a dart each: every call is
    ``(done, total)`` in floats of the model's one panel, never back, ending at ``(1, 1)``; the search (the
    first half of the bar) moves with each flattening it makes (the dartless panel, then each piece): past
    ``k / (k + 1)`` of its half once ``k`` are done, so past ``(n - 1) / n`` of it by the last of ``n``
    pieces (within the bar's 0.001 step); and the pieces are bit for bit those of a run with no progress."""
    model = patterns.load(samples.DOMES["freeform cup"]())
    calls = []
    pattern = patterns.flatten(model, max_strain=LIMIT, max_darts=1, progress=lambda d, n: calls.append((d, n)))
    assert all(type(d) is float and n == 1.0 for d, n in calls) and calls[-1] == (1.0, 1.0)
    assert all(a[0] < b[0] for a, b in itertools.pairwise(calls))
    n = len(pattern.panels)  # n flattenings done as the last piece starts: the dartless panel and n - 1 pieces
    assert n >= 3 and max(d for d, _ in calls if d < 0.5) >= 0.5 * (n - 1) / n
    plain = patterns.flatten(model, max_strain=LIMIT, max_darts=1)
    for a, b in zip(pattern.panels, plain.panels, strict=True):
        assert np.array_equal(a.flattening.uv, b.flattening.uv) and np.array_equal(a.flattening.faces, b.flattening.faces)


def test_every_flattening_moves_the_bar_however_few_its_iterations():
    """The bar counts a stage's flattenings by the engine's call as each starts (``progress(0, 1)``), not by its
    share dropping: three real flattenings of one iteration each in one stage (each ends at share 1, so the
    share never drops) fill it to ``k / (k + 1)`` after ``k`` = 3 (3/4 of the span), and a fourth stage's
    flattening starts from its own span's foot; the bar was at 1/2 after the three when only a drop counted."""
    from patterns.flattening.engine import flatten_mesh
    from patterns.flattening.progress import Bar
    from patterns.surfaces import paraboloid_dish

    vertices, faces = paraboloid_dish(n_faces=200)
    calls = []
    bar = Bar(lambda d, n: calls.append(d), 4)
    bar.span(0.0, 2.0)
    for _ in range(3):
        flatten_mesh(vertices, faces, max_iterations=1, progress=bar.engine)
    assert calls[-1] == pytest.approx(2.0 * 3 / 4, abs=1e-12)
    bar.span(2.0, 4.0)
    flatten_mesh(vertices, faces, max_iterations=1, progress=bar.engine)
    assert calls[-1] == pytest.approx(2.0 + 2.0 * 1 / 2, abs=1e-12)
    bar.finish()
    assert calls[-1] == 4.0 and all(a < b for a, b in itertools.pairwise(calls))


@pytest.mark.slow  # 24 s
def test_a_piece_count_that_cannot_meet_the_limit_stops_early_and_finishes_to_the_same_pieces():
    """``parting`` stops a piece count at its first piece above the limit (the count cannot meet it: every
    piece must) and finishes it only when asked for the closest: the freeform cup at 1 % with one dart a
    piece meets it in neither 3 nor 4 pieces; each count stopped after fewer pieces than it has, and
    ``closest()`` is, bit for bit, the count :func:`~patterns.flattening.inserts.relieved` gives closest
    when every piece of every count is done (on a tie the first), as ``parted`` returns it."""
    from patterns.flattening.gores import gore_paths
    from patterns.flattening.inserts import relieved
    from patterns.flattening.panels import _flat_panel
    from patterns.flattening.parted import parted, parting
    from patterns.flattening.settings import FlattenOptions
    from patterns.flattening.split import split_panel

    limit, max_darts = 0.01, 1
    model = patterns.load(samples.DOMES["freeform cup"]())
    opts = FlattenOptions.of(None, {"max_strain": limit, "max_darts": max_darts}, name=model.name)

    def flat(m, p):
        return _flat_panel(m, p, opts, 0.0, {})

    result = flat(model, 0).flattening
    found = parting(model, 0, result, limit, max_darts, 24, flat)
    assert found.met is None and len(found.tried) == 2
    counts = []
    for stopped, _ in found.tried:
        n = len(stopped.model.panels)
        assert stopped.worst > limit and len(stopped.darted) < n  # stopped before its last piece
        counts.append(n)
    full = []
    for n in counts:  # every piece of each count, from scratch
        split = split_panel(model, 0, gore_paths(result, n, limit))
        full.append(relieved(split, 0, n, limit, flat, max_slashes=max_darts, max_darts=max_darts))
    want = min(full, key=lambda r: r.worst)
    got = found.closest()
    assert got.worst == want.worst and sorted(got.darted) == sorted(want.darted)
    for name, darted in want.darted.items():
        assert np.array_equal(got.darted[name].flattening.uv, darted.flattening.uv)
    again = parted(model, 0, result, limit, max_darts, 24, flat)
    assert again.worst == want.worst
