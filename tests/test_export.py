"""DXF and OBJ output, read back by ezdxf and trimesh; atomic writes."""

import os
from pathlib import Path

import ezdxf
import numpy as np
import pytest
import shapely
import trimesh
from ezdxf import recover

import patterns
from patterns import surfaces
from patterns.errors import ExportError, InputError
from patterns.export import atomic_output, write_flat_obj, write_outline_dxf


@pytest.fixture(scope="module")
def dish_with_hole():
    p, f = surfaces.disk_mesh(3000)
    keep = np.linalg.norm(p[f].mean(axis=1) - [0.3, 0.1], axis=1) > 0.2
    f = f[keep]
    used = np.unique(f)
    remap = np.full(len(p), -1)
    remap[used] = np.arange(len(used))
    p, f = p[used] * 300.0, remap[f]
    v = np.column_stack([p, 54.0 * (p**2).sum(axis=1) / 300.0**2])
    return patterns.flatten_mesh(v, f)


def test_dxf_contours_read_back_closed_with_true_area_and_perimeter(tmp_path, dish_with_hole):
    r = dish_with_hole
    path = tmp_path / "dish.dxf"
    loops = [r.uv[loop] for loop in r.loops]
    write_outline_dxf(path, loops)
    doc, auditor = recover.readfile(path)
    assert not auditor.has_errors
    assert doc.header["$INSUNITS"] == 4  # millimetres
    polylines = doc.modelspace().query("LWPOLYLINE")
    assert len(polylines) == len(r.loops) == 2
    for entity, loop in zip(polylines, loops):
        assert entity.closed and entity.dxf.layer == "CUT"
        pts = np.array([p[:2] for p in entity.get_points("xy")])
        ring = shapely.Polygon(pts)
        expected = shapely.Polygon(loop)
        assert ring.area == pytest.approx(expected.area, rel=1e-6)
        assert ring.length == pytest.approx(expected.length, rel=1e-6)
    assert len(doc.modelspace()) == len(loops)  # nothing else, nothing twice


def test_flat_obj_round_trips(tmp_path, dish_with_hole):
    r = dish_with_hole
    path = tmp_path / "flat.obj"
    write_flat_obj(path, r.uv, r.faces)
    back = trimesh.load(path, process=False)
    np.testing.assert_array_equal(back.faces, r.faces)
    np.testing.assert_allclose(back.vertices[:, :2], r.uv, rtol=0, atol=1e-12)
    assert np.all(back.vertices[:, 2] == 0)


def test_failed_write_leaves_nothing_and_keeps_the_old_file(tmp_path):
    path = tmp_path / "out.dxf"
    path.write_text("old")
    with pytest.raises(RuntimeError), atomic_output(path) as tmp:
        tmp.write_text("half")
        raise RuntimeError("boom")
    assert path.read_text() == "old"
    assert os.listdir(tmp_path) == ["out.dxf"]


def test_written_files_get_the_usual_permissions(tmp_path):
    old = os.umask(0o022)
    try:
        write_outline_dxf(tmp_path / "new.dxf", [np.eye(3)[:, :2]])
    finally:
        os.umask(old)
    assert (tmp_path / "new.dxf").stat().st_mode & 0o777 == 0o644
    (tmp_path / "kept.dxf").write_text("old")
    (tmp_path / "kept.dxf").chmod(0o664)
    write_outline_dxf(tmp_path / "kept.dxf", [np.eye(3)[:, :2]])
    assert (tmp_path / "kept.dxf").stat().st_mode & 0o777 == 0o664


def test_bad_loop_writes_nothing(tmp_path):
    path = tmp_path / "bad.dxf"
    with pytest.raises(InputError, match="loop 1"):
        write_outline_dxf(path, [np.eye(3)[:, :2] * 10, np.array([[0.0, 0.0], [np.nan, 1.0], [1.0, 1.0]])])
    assert not path.exists()


def test_missing_folder_is_an_export_error(tmp_path):
    with pytest.raises(ExportError, match="does not exist") as info:
        write_outline_dxf(tmp_path / "no" / "x.dxf", [np.eye(3)[:, :2]])
    assert isinstance(info.value, OSError)


def test_read_only_folder_is_an_export_error(tmp_path):
    if os.geteuid() == 0:
        # Root writes through permission bits; /proc/self is a folder nobody can write into.
        with pytest.raises(ExportError, match="cannot write the DXF file"):
            write_outline_dxf(Path("/proc/self/x.dxf"), [np.eye(3)[:, :2]])
        return
    folder = tmp_path / "ro"
    folder.mkdir()
    folder.chmod(0o500)
    try:
        with pytest.raises(ExportError, match="cannot write the DXF file"):
            write_outline_dxf(folder / "x.dxf", [np.eye(3)[:, :2]])
        assert list(folder.iterdir()) == []
    finally:
        folder.chmod(0o700)


def test_units_are_declared(tmp_path):
    write_outline_dxf(tmp_path / "in.dxf", [np.eye(3)[:, :2]], units="in")
    assert ezdxf.readfile(tmp_path / "in.dxf").header["$INSUNITS"] == 1
    with pytest.raises(InputError, match="unknown unit"):
        write_outline_dxf(tmp_path / "x.dxf", [np.eye(3)[:, :2]], units="furlong")
