"""Reading mesh files: real files written by trimesh, and broken ones."""

import numpy as np
import pytest
import trimesh
from scipy.spatial import cKDTree

from patterns import surfaces
from patterns.errors import InputError
from patterns.reading import read_mesh

from .conftest import SAMPLES


def test_obj_keeps_the_file_connectivity(tmp_path):
    v, f = surfaces.paraboloid_dish(n_faces=500)
    path = tmp_path / "dish.obj"
    trimesh.Trimesh(v, f, process=False).export(path)
    mesh = read_mesh(path)
    assert mesh.faces.shape == f.shape and mesh.n_welded == 0 and mesh.n_unused == 0
    np.testing.assert_array_equal(mesh.faces, f)
    np.testing.assert_allclose(mesh.vertices, v, atol=1e-7)


def test_stl_is_welded_explicitly(tmp_path):
    v, f = surfaces.paraboloid_dish(n_faces=500)
    path = tmp_path / "dish.stl"
    trimesh.Trimesh(v, f, process=False).export(path)
    mesh = read_mesh(path)
    assert len(mesh.vertices) == len(v)
    assert mesh.n_welded == 3 * len(f) - len(v)
    # Same surface and connectivity: map each welded vertex to its original
    # (STL stores float32) and compare the faces, up to cyclic order.
    dist, idx = cKDTree(v).query(mesh.vertices)
    assert dist.max() < 1e-3 and len(np.unique(idx)) == len(v)

    def canonical(faces):
        k = np.argmin(faces, axis=1)[:, None]
        return {tuple(row) for row in np.take_along_axis(faces, (k + np.arange(3)) % 3, axis=1)}

    assert canonical(idx[mesh.faces]) == canonical(f)


def test_unused_vertices_are_dropped(tmp_path):
    path = tmp_path / "extra.off"
    path.write_text("OFF\n4 1 0\n0 0 0\n9 9 9\n1 0 0\n0 1 0\n3 0 2 3\n")
    mesh = read_mesh(path)
    assert mesh.n_unused == 1
    np.testing.assert_array_equal(mesh.faces, [[0, 1, 2]])
    np.testing.assert_array_equal(mesh.vertices, [[0, 0, 0], [1, 0, 0], [0, 1, 0]])


@pytest.mark.parametrize(
    ("name", "content", "words"),
    [
        ("empty.obj", b"", "holds no triangles"),
        ("words.obj", b"this is not a mesh\n", "holds no triangles"),
        ("empty.stl", b"", "holds no triangles"),
        ("random.ply", bytes(range(256)) * 8, "cannot read this .ply file"),
        ("part.step", b"ISO-10303-21;", "unknown mesh file type '.step'"),
        ("bad-index.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n", None),
    ],
)
def test_broken_files_give_one_error_naming_the_file(tmp_path, name, content, words):
    path = tmp_path / name
    path.write_bytes(content)
    with pytest.raises(InputError) as info:
        read_mesh(path)
    assert str(path) in str(info.value)
    if words:
        assert words in str(info.value)


def test_missing_file(tmp_path):
    with pytest.raises(InputError, match="no such file"):
        read_mesh(tmp_path / "nope.obj")


@pytest.mark.parametrize("name", ["dish.obj", "cone.obj"])
def test_bundled_samples_read(name):
    mesh = read_mesh(SAMPLES / name)
    assert len(mesh.faces) > 500


def test_the_model_carries_what_loading_did(tmp_path, capsys):
    """An STL's welding is on the Model and printed by the CLI (never behind the user's back)."""
    import patterns
    from patterns import cli

    v, f = surfaces.paraboloid_dish(n_faces=216)
    path = tmp_path / "dish.stl"
    trimesh.Trimesh(v, f, process=False).export(path)
    corners = 3 * len(f)  # an STL stores every triangle's corners apart
    model = patterns.load(path)
    assert model.bookkeeping.welded == corners - len(v)
    assert model.bookkeeping.unused == 0 and model.bookkeeping.cuts == 0
    assert cli.main(["info", str(path)]) == 0
    assert f"{corners - len(v)} vertices welded" in capsys.readouterr().out


def test_a_closed_smooth_mesh_is_refused_not_cut_once(tmp_path):
    """A sphere has no line to cut it along, and no single cut lays it flat (Gauss-Bonnet: its
    4 pi of curvature must go somewhere): refused, with the advice to give it seams."""
    import patterns

    sphere = trimesh.creation.icosphere(subdivisions=2, radius=50.0)
    path = tmp_path / "ball.obj"
    sphere.export(path)
    with pytest.raises(patterns.MeshTopologyError, match="ball.obj: a closed surface with no crease.*give it seams"):
        patterns.load(path)


def test_a_closed_box_mesh_is_split_along_its_creases(tmp_path):
    """A closed box (STL, as CAD exports a solid) comes in as its six faces, joined by its twelve
    edges: each seam as long as the box edge it runs along."""
    import patterns

    path = tmp_path / "box.stl"
    trimesh.creation.box((100.0, 60.0, 40.0)).export(path)
    model = patterns.load(path)
    assert len(model.panels) == 6 and len(model.seams) == 12
    assert sorted(round(s.length, 5) for s in model.seams) == [40.0] * 4 + [60.0] * 4 + [100.0] * 4
    assert sorted(round(p.area, 3) for p in model.panels) == [2400.0] * 2 + [4000.0] * 2 + [6000.0] * 2
    assert model.bookkeeping.split == 1 and model.bookkeeping.cuts == 0
    assert "1 closed piece split into panels along creases" in str(model.bookkeeping)


def test_a_closed_can_is_split_at_its_rims_and_its_side_cut_open(tmp_path):
    import patterns

    path = tmp_path / "can.stl"
    trimesh.creation.cylinder(radius=30.0, height=80.0, sections=48).export(path)
    model = patterns.load(path)
    assert len(model.panels) == 3
    rims = [s for s in model.seams if not s.closes_panel]
    polygon = 48 * 2 * 30.0 * np.sin(np.pi / 48)  # the 48-gon's perimeter
    assert [s.length for s in rims] == pytest.approx([polygon, polygon], rel=1e-6)  # STL: float32
    (cut,) = [s for s in model.seams if s.closes_panel]  # the side, a tube, cut along its height
    assert cut.length == pytest.approx(80.0, rel=1e-6)
    assert model.bookkeeping.cuts == 1
    pattern = patterns.flatten(model)
    assert patterns.check(pattern).ok


@pytest.mark.parametrize(("unit", "mm"), [("mm", 1.0), ("cm", 10.0), ("m", 1000.0), ("in", 25.4)])
def test_mesh_units_are_converted_to_mm(tmp_path, unit, mm):
    import patterns

    v, f = surfaces.paraboloid_dish(n_faces=200)
    path = tmp_path / "dish.obj"
    trimesh.Trimesh(v, f, process=False).export(path)
    model = patterns.load(path, units=unit)
    np.testing.assert_allclose(model.panels[0].vertices, trimesh.load(path, process=False).vertices * mm,
                               rtol=1e-12)
