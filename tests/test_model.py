"""patterns.load and patterns.flatten: CAD files, build123d objects and mesh files
become panels joined by seams; the samples round-trip; bad input gets one named error."""

from math import hypot, pi, sqrt

import build123d as bd
import numpy as np
import pytest
import trimesh

import patterns
from patterns import surfaces
from patterns.errors import CadError, InputError, MeshTopologyError

from .conftest import SAMPLES
from .helpers import independent_one_to_one

# Each sample: panels, seams, and every seam's exact length from the drawing
# (independent of OpenCascade's lengths).
DUCT_RULING = sqrt(2 * (200 - 150 / sqrt(2)) ** 2 + 300**2)
EXPECTED = {
    "duct_transition.step": (4, [DUCT_RULING] * 4),
    "hopper.step": (1, [hypot(300 - 100, 400)]),
    "cup.step": (4, [pi / 2 * 90] * 4),
    "hull_panel.step": (1, []),
}


def min_angles(vertices, faces):
    p = vertices[faces]
    out = []
    for k in range(3):
        a = p[:, (k + 1) % 3] - p[:, k]
        b = p[:, (k + 2) % 3] - p[:, k]
        cos = np.einsum("ij,ij->i", a, b) / (np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1))
        out.append(np.degrees(np.arccos(np.clip(cos, -1, 1))))
    return np.min(out, axis=0)


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_samples_match_their_cad_topology_and_round_trip(name):
    model = patterns.load(SAMPLES / name)
    n_panels, lengths = EXPECTED[name]
    assert len(model.panels) == n_panels
    assert len(model.seams) == len(lengths)
    np.testing.assert_allclose(sorted(s.length for s in model.seams), sorted(lengths), rtol=1e-6)
    shape = bd.import_step(SAMPLES / name)
    assert len(shape.faces()) == sum(len(p.cad_faces) for p in model.panels)
    for seam in model.seams:
        # The CAD edge the seam comes from has the same length, and both sides
        # carry the same ordered 3D points.
        assert seam.length == pytest.approx(shape.edges()[seam.cad_edge].length, rel=1e-9)
        for side in (0, 1):
            np.testing.assert_array_equal(model.panels[seam.panels[side]].vertices[seam.vertices[side]], seam.points)
        assert seam.polyline_length <= seam.length * (1 + 1e-12)
    pattern = patterns.flatten(model)
    assert pattern.one_to_one
    for flat in pattern.panels:
        assert independent_one_to_one(flat.faces, flat.uv)
        assert flat.flattening.n_folded == 0
        # 1:1 -- the flat area is the 3D area within the part's own strain.
        d = flat.flattening.distortion
        assert abs(flat.area / flat.panel.area - 1) < 3 * d.edge_strain_rms + 1e-6
        # Well-shaped triangles (OpenCascade's own are slivers of 4-9 degrees on these).
        assert np.percentile(min_angles(flat.vertices, flat.faces), 1) > 20


def test_sample_strain_and_seam_numbers():
    """Measured numbers of the samples (regression guards, with the physics behind them)."""
    hopper = patterns.flatten(patterns.load(SAMPLES / "hopper.step"))
    # A cone is developable: only the chords' discretisation error remains.
    assert hopper.panels[0].flattening.distortion.edge_strain_max < 1e-3
    (seam,) = hopper.seams
    assert seam.seam.closes_panel and seam.seam.cad_edge is not None
    assert seam.flat_lengths[0] == pytest.approx(seam.length, rel=1e-4)
    assert abs(seam.mismatch) < 1e-6 * seam.length
    model = patterns.load(SAMPLES / "cup.step")
    # A quarter sphere is not developable.  Laid flat with its seams free, its
    # least-strain layout stretches the edges (a gore of positive curvature
    # opens up): the seams come out long.
    free = patterns.flatten(model, seams="free")
    for s in free.seams:
        assert s.flat_lengths[0] > 1.02 * s.length
    # Held at their length (the default), every seam is as long flat as its 3D
    # polyline on both sides, so the sides match.
    cup = patterns.flatten(model)
    for s in cup.seams:
        for side in (0, 1):
            assert s.flat_lengths[side] == pytest.approx(s.seam.polyline_length, rel=2e-4)
        assert abs(s.mismatch) < 0.02  # mm
    for a, b in zip(cup.panels, free.panels):
        assert a.flattening.distortion.strain_rms > b.flattening.distortion.strain_rms  # the price of true seams


def test_build123d_object_to_pattern_in_three_lines():
    part = bd.Box(200, 100, 50) - bd.Cylinder(20, 50)
    model = patterns.load(part, max_edge=8)
    pattern = patterns.flatten(model)
    # Seven faces: six box sides (two pierced) and the hole's wall, closed by its seam.
    assert len(pattern.panels) == 7
    walls = [p for p in pattern.panels if len(p.loops) == 1 and p.panel.area == pytest.approx(2 * pi * 20 * 50, rel=1e-3)]
    assert len(walls) == 1
    assert pattern.one_to_one
    # Planar faces come out exact, holes and all.
    planar = [p for p in pattern.panels if p is not walls[0]]
    for flat in planar:
        assert flat.flattening.distortion.edge_strain_max < 1e-9
        assert flat.area == pytest.approx(flat.panel.area, rel=1e-12)
    pierced = [p for p in planar if len(p.loops) == 2]
    assert len(pierced) == 2
    for flat in pierced:
        hole = flat.outline(1)
        radius = np.linalg.norm(hole - hole.mean(axis=0), axis=1)
        np.testing.assert_allclose(radius, 20.0, rtol=1e-9)
    # max_edge is the lattice spacing: measured median 0.94, 99th percentile 1.31,
    # longest 1.47 times it (boundary rows, where the lattice meets the edges).
    lengths = np.concatenate([np.linalg.norm(p.vertices[np.roll(p.faces, -1, axis=1)] - p.vertices[p.faces], axis=2)
                              .ravel() for p in model.panels]) / 8.0
    assert 0.85 < np.median(lengths) <= 1.0 + 1e-9
    assert np.percentile(lengths, 99) < 1.4 and lengths.max() < 1.6


def test_groups_of_faces_are_one_panel_and_a_closed_group_is_cut_open():
    box = bd.Box(100, 60, 40)
    model = patterns.load(box, panels={"wrap": [0, 1, 2, 3]})
    assert [p.name for p in model.panels] == ["wrap", "face4", "face5"]
    assert model.panels[0].cad_faces == (0, 1, 2, 3)
    cuts = [s for s in model.seams if s.cad_edge is None]
    assert len(cuts) == 1 and cuts[0].closes_panel and cuts[0].length == pytest.approx(40.0)
    # Eight CAD seams between the wrap and the two ends.
    assert sum(s.cad_edge is not None for s in model.seams) == 8
    pattern = patterns.flatten(model)
    wrap = pattern.panels[0]
    assert wrap.flattening.distortion.edge_strain_max < 1e-9  # a prism unrolls exactly
    assert wrap.area == pytest.approx(2 * (100 + 60) * 40, rel=1e-12)
    flat_cut = [s for s in pattern.seams if s.seam.cad_edge is None][0]
    assert flat_cut.flat_lengths == pytest.approx((40.0, 40.0), rel=1e-12)


@pytest.mark.parametrize(
    ("faces", "words"),
    [
        ({"a": [0], "b": [0]}, "in two groups"),
        ({"a": [99]}, "faces 0..5"),
        ({"a": []}, "is empty"),
        ([0, 1], "must map panel names"),
        ({"a": ["x"]}, "list of CAD face indices"),
    ],
)
def test_bad_groups(faces, words):
    with pytest.raises(InputError, match=words):
        patterns.load(bd.Box(10, 10, 10), panels=faces)


@pytest.mark.parametrize("option", [{"max_edge": 0}, {"max_edge": -1.0}, {"chord_tolerance": 0}, {"angular_tolerance": -0.1},
                                    {"max_edge": float("nan")}])
def test_bad_meshing_options(option):
    with pytest.raises(InputError, match=next(iter(option))):
        patterns.load(bd.Box(10, 10, 10), **option)


def test_closed_mesh_is_refused_but_the_kernel_can_slit_it(tmp_path):
    """Loading refuses a closed smooth surface (one cut cannot lay it flat: docs/loading.md); the
    kernel that opens tubes still slits it into a disk, and the engine lays that disk out one-to-one."""
    sphere = trimesh.creation.icosphere(subdivisions=3, radius=50.0)
    path = tmp_path / "ball.stl"
    sphere.export(path)
    with pytest.raises(patterns.MeshTopologyError, match="closed surface"):
        patterns.load(path)
    cut = patterns.cut_to_disk(sphere.vertices, sphere.faces)
    (path_,), ((left, right),) = cut.paths, cut.sides
    # Both sides carry the same points; inside the slit the copies differ.
    np.testing.assert_array_equal(cut.vertices[left], sphere.vertices[path_])
    np.testing.assert_array_equal(cut.vertices[right], sphere.vertices[path_])
    assert left[0] == right[0] and left[-1] == right[-1] and np.all(left[1:-1] != right[1:-1])
    result = patterns.flatten_mesh(cut.vertices, cut.faces)
    assert result.overlap.one_to_one and independent_one_to_one(cut.faces, result.uv)


def test_a_tube_is_cut_but_a_plate_with_a_hole_is_not(tmp_path):
    # An open cylinder (two rims, each turning 0) must be cut; it then unrolls exactly.
    tube = trimesh.creation.cylinder(radius=40.0, height=100.0, sections=48)
    keep = np.abs(tube.face_normals[:, 2]) < 0.5  # drop the caps
    v, f = tube.vertices, tube.faces[keep]
    used = np.unique(f)
    remap = np.full(len(v), -1)
    remap[used] = np.arange(len(used))
    path = tmp_path / "tube.obj"
    trimesh.Trimesh(v[used], remap[f], process=False).export(path)
    model = patterns.load(path)
    assert len(model.seams) == 1 and model.seams[0].length == pytest.approx(100.0)
    flat = patterns.flatten(model).panels[0]
    assert flat.flattening.distortion.edge_strain_max < 1e-9
    # A flat washer (its hole turns by -2 pi) keeps its hole.
    p, f = surfaces.disk_mesh(2000)
    f = f[np.linalg.norm(p[f].mean(axis=1), axis=1) > 0.4]
    used = np.unique(f)
    remap = np.full(len(p), -1)
    remap[used] = np.arange(len(used))
    washer = np.column_stack([p[used] * 100.0, np.zeros(len(used))])
    path = tmp_path / "washer.ply"
    trimesh.Trimesh(washer, remap[f], process=False).export(path)
    model = patterns.load(path)
    assert len(model.seams) == 0 and len(model.panels[0].loops) == 2
    assert patterns.flatten(model).panels[0].flattening.distortion.edge_strain_max < 1e-9


def test_mesh_pieces_become_panels(tmp_path):
    a = trimesh.creation.box(extents=(10, 10, 10))
    b = a.copy()
    b.apply_translation((30, 0, 0))
    path = tmp_path / "two.off"
    trimesh.util.concatenate([a, b]).export(path)
    model = patterns.load(path)
    # two pieces, each a closed box: split along its twelve edges into its six faces
    assert [p.name for p in model.panels] == [f"piece{i}.{k}" for i in range(2) for k in range(6)]
    assert len(model.seams) == 24 and all(s.length == pytest.approx(10.0) for s in model.seams)
    assert all(s.panels[0] // 6 == s.panels[1] // 6 for s in model.seams)  # a seam stays within its box
    pattern = patterns.flatten(model)
    assert pattern.one_to_one and patterns.check(pattern).ok


def test_3mf_is_read(tmp_path):
    path = tmp_path / "dish.3mf"
    v, f = surfaces.paraboloid_dish(n_faces=500)
    trimesh.Trimesh(v, f, process=False).export(path)
    model = patterns.load(path)
    assert len(model.panels) == 1 and len(model.panels[0].faces) == len(f)


def _write(path, data: bytes):
    path.write_bytes(data)
    return path


@pytest.mark.parametrize(
    ("make", "error", "words"),
    [
        (lambda d: d / "missing.step", InputError, "no such file"),
        (lambda d: _write(d / "part.xyz", b"1 2 3"), InputError, "unknown file type"),
        (lambda d: _write(d / "empty.step", b""), CadError, "empty"),
        (lambda d: _write(d / "noise.step", bytes(np.random.default_rng(1).integers(0, 256, 4000, dtype=np.uint8))),
         CadError, "not a readable STEP"),
        (lambda d: _write(d / "cut.step", (SAMPLES / "hopper.step").read_bytes()[:900]), CadError, "STEP"),
        (lambda d: _write(d / "noise.igs", b"garbage" * 100), CadError, "IGES"),
        (lambda d: _write(d / "noise.brep", b"garbage" * 100), CadError, "BREP"),
        (lambda d: _write(d / "nan.obj", b"v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n"), InputError, "NaN"),
        (lambda d: _write(d / "range.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"), InputError, ""),
        (lambda d: _write(d / "empty.stl", b""), InputError, ""),
    ],
)
def test_bad_files_get_one_named_error(tmp_path, make, error, words):
    path = make(tmp_path)
    with pytest.raises(error) as info:
        patterns.load(path)
    message = str(info.value)
    assert path.name in message and words in message
    assert "\n" not in message


def test_step_without_faces_is_refused(tmp_path):
    path = tmp_path / "wire.step"
    bd.export_step(bd.Edge.make_line((0, 0, 0), (100, 0, 0)), path)
    with pytest.raises(CadError, match="wire.step: the shape has no faces"):
        patterns.load(path)


def test_a_mesh_with_handles_is_refused(tmp_path):
    path = tmp_path / "ring.stl"
    trimesh.creation.torus(major_radius=50, minor_radius=10).export(path)
    with pytest.raises(MeshTopologyError, match="ring.stl: closed surface with handles"):
        patterns.load(path)


def test_options_that_do_not_apply_are_refused(tmp_path):
    with pytest.raises(InputError, match="CAD files only"):
        patterns.load(SAMPLES / "dish.obj", panels={"a": [0]})
    with pytest.raises(InputError, match="mesh files only"):
        patterns.load(SAMPLES / "hopper.step", weld_vertices=True)
    with pytest.raises(InputError, match="cannot load a int"):
        patterns.load(7)
    with pytest.raises(InputError, match="takes a patterns.Model"):
        patterns.flatten("samples/hopper.step")


def test_model_and_pattern_are_read_only():
    model = patterns.load(SAMPLES / "cup.step")
    with pytest.raises(ValueError):
        model.panels[0].vertices[0, 0] = 1.0
    with pytest.raises(ValueError):
        model.seams[0].points[0, 0] = 1.0
    with pytest.raises(AttributeError):
        model.panels[0].name = "x"
    pattern = patterns.flatten(model)
    with pytest.raises(ValueError):
        pattern.panels[0].uv[0, 0] = 1.0


def test_iges_and_brep_files_load_like_the_step(tmp_path):
    from OCP.IGESControl import IGESControl_Writer

    shape = bd.import_step(SAMPLES / "cup.step")
    writer = IGESControl_Writer("MM", 1)  # 1: B-rep mode, faces share their edges
    writer.AddShape(shape.wrapped)
    writer.ComputeModel()
    assert writer.Write(str(tmp_path / "cup.igs"))
    bd.export_brep(shape, tmp_path / "cup.brep")
    for name in ("cup.igs", "cup.brep"):
        model = patterns.load(tmp_path / name)
        assert len(model.panels) == 4 and len(model.seams) == 4
        np.testing.assert_allclose([s.length for s in model.seams], pi / 2 * 90, rtol=1e-6)
        assert patterns.flatten(model).one_to_one


def test_loose_faces_are_sewn_into_seams():
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Copy

    shape = bd.import_step(SAMPLES / "cup.step")
    loose = bd.Compound([bd.Face(BRepBuilderAPI_Copy(f.wrapped).Shape()) for f in shape.faces()])
    assert len(loose.edges()) == 12  # every face keeps its own three edges
    assert len(patterns.load(loose, sew=False).seams) == 0
    model = patterns.load(loose)
    assert len(model.seams) == 4
    np.testing.assert_allclose([s.length for s in model.seams], pi / 2 * 90, rtol=1e-6)
    for seam in model.seams:
        for side in (0, 1):
            np.testing.assert_array_equal(model.panels[seam.panels[side]].vertices[seam.vertices[side]], seam.points)


def test_constructors_never_freeze_the_callers_arrays():
    """A Panel or Seam owns read-only copies; the arrays it was given stay writeable and
    later writes to them do not reach the model."""
    from patterns import surfaces

    v, f = surfaces.spherical_cap(radius=100.0, half_angle=30.0, n_faces=200)
    loops = patterns.mesh.boundary_loops(v, f)
    panel = patterns.Panel("p", v, f, loops)
    assert v.flags.writeable and f.flags.writeable
    assert not panel.vertices.flags.writeable and not panel.faces.flags.writeable
    v[0] += 1000.0
    assert not np.allclose(panel.vertices[0], v[0])
    points = v[loops[0][:3]].copy()
    seam = patterns.Seam(0, (0, 0), points, (loops[0][:3], loops[0][:3]), 1.0)
    assert points.flags.writeable and not seam.points.flags.writeable
