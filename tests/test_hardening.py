"""Bad input of every kind gets one clear error naming the file, leaves no file behind,
and cannot hang; the same input gives byte-identical output; properties over random meshes."""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import trimesh
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import patterns
from patterns import surfaces
from patterns.errors import CadError, InputError, MeshTopologyError, PatternsError

from .conftest import SAMPLES

EXE = Path(sys.executable).with_name("patterns")
RNG = np.random.default_rng(2026)


def _noise(n):
    return bytes(RNG.integers(0, 256, n, dtype=np.uint8))


def _mesh_bytes(suffix):
    v, f = surfaces.paraboloid_dish(n_faces=200)
    path = Path(os.environ.get("TMPDIR", "/tmp")) / f"_hardening_source{suffix}"
    trimesh.Trimesh(v, f, process=False).export(path)
    data = path.read_bytes()
    path.unlink()
    return data


def _cad_bytes(suffix):
    """The cup sample written as IGES or BREP, to truncate."""
    import build123d as bd
    from OCP.IGESControl import IGESControl_Writer

    shape = bd.import_step(SAMPLES / "cup.step")
    path = Path(os.environ.get("TMPDIR", "/tmp")) / f"_hardening_source{suffix}"
    if suffix == ".igs":
        writer = IGESControl_Writer("MM", 1)
        writer.AddShape(shape.wrapped)
        writer.ComputeModel()
        writer.Write(str(path))
    else:
        bd.export_brep(shape, path)
    data = path.read_bytes()
    path.unlink()
    return data


FILES = {
    # name: (bytes, error class, words in the message)
    "empty.step": (b"", CadError, "empty"),
    "empty.iges": (b"", CadError, "empty"),
    "empty.brep": (b"", CadError, "empty"),
    "empty.stl": (b"", InputError, "holds no triangles"),
    "empty.obj": (b"", InputError, "no triangles"),
    "empty.ply": (b"", InputError, "cannot read this .ply file"),
    "noise.step": (_noise(5000), CadError, "not a readable STEP"),
    "noise.iges": (_noise(5000), CadError, "IGES"),
    "noise.brep": (_noise(5000), CadError, "BREP"),
    "noise.stl": (_noise(5000), InputError, "holds no triangles"),
    "noise.ply": (_noise(5000), InputError, "cannot read this .ply file"),
    "truncated.step": ((SAMPLES / "cup.step").read_bytes()[:2000], CadError, "not a readable STEP file"),
    "truncated.stl": (_mesh_bytes(".stl")[:1000], InputError, "holds no triangles"),
    "truncated.igs": (_cad_bytes(".igs")[:3000], CadError, "IGES"),
    "truncated.brep": (_cad_bytes(".brep")[:3000], CadError, "BREP"),
    "truncated.ply": (_mesh_bytes(".ply")[:600], InputError, "cannot read this .ply file"),
    "nan.obj": (b"v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n", InputError, "NaN"),
    "inf.obj": (b"v 0 0 0\nv 1 0 0\nv inf 1 0\nf 1 2 3\n", InputError, "NaN or infinite"),
    "range.off": (b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n", InputError, "face index outside the range"),
    "negative.off": (b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 -2\n", InputError, "face index outside the range"),
    "zero_area.obj": (b"v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\nf 1 4 2\n", InputError, "degenerate"),
    "duplicate_faces.obj": (b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 3\n", MeshTopologyError,
                            "used twice in the same direction"),
    "nonmanifold.obj": (b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n",
                        MeshTopologyError, "non-manifold"),
    "winding.obj": (b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 3 4\n", MeshTopologyError,
                    "not consistently wound"),
    "unknown.xyz": (b"1 2 3", InputError, "unknown file type"),
}


@pytest.mark.parametrize("name", sorted(FILES))
def test_bad_files_library_and_command_line(tmp_path, name):
    data, error, words = FILES[name]
    path = tmp_path / name
    path.write_bytes(data)
    with pytest.raises(error) as info:
        patterns.flatten(patterns.load(path))
    message = str(info.value)
    assert words, "every bad file names its problem"
    assert name in message and words in message and "\n" not in message
    if not EXE.exists():
        pytest.skip(f"the entry point {EXE} is not installed")
    out = tmp_path / "out"
    out.mkdir()
    proc = subprocess.run([str(EXE), "flatten", str(path), "-o", str(out / "x.dxf"), "--report", str(out / "r.json")],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2, proc.stdout + proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("patterns: error: ") and name in lines[0]
    assert "Traceback" not in proc.stderr
    assert list(out.iterdir()) == []  # no partial output


def test_closed_surfaces_several_pieces_and_flipped_normals_are_handled(tmp_path):
    # Not errors: a closed box is split along its edges, pieces become panels, a mesh wound
    # the other way round flattens mirrored -- still one-to-one.  A closed smooth piece (a ball)
    # is refused, naming the piece: one cut cannot lay it flat.
    ball = trimesh.creation.icosphere(subdivisions=2, radius=40.0)
    box = trimesh.creation.box(extents=(30, 20, 10))
    box.apply_translation((100, 0, 0))
    tube = trimesh.creation.cylinder(radius=10, height=40, sections=32)
    tube = trimesh.Trimesh(tube.vertices, tube.faces[np.abs(tube.face_normals[:, 2]) < 0.5])  # open ends
    tube.apply_translation((0, 100, 0))
    path = tmp_path / "two.ply"
    trimesh.util.concatenate([box, tube]).export(path)
    pattern = patterns.flatten(patterns.load(path))
    assert len(pattern.panels) == 7 and len(pattern.seams) == 13 and pattern.one_to_one  # 6 + the tube, cut once
    trimesh.util.concatenate([box, ball]).export(path)
    with pytest.raises(MeshTopologyError, match="two.ply: piece1: a closed surface with no crease"):
        patterns.load(path)
    v, f = surfaces.paraboloid_dish(n_faces=500)
    flipped = patterns.flatten_mesh(v, f[:, ::-1])
    assert flipped.one_to_one and flipped.n_folded == 0


@pytest.mark.parametrize("scale,offset", [(1e-9, 0.0), (1.0, 9e6), (1.6e4, 0.0)])
def test_extreme_coordinates(scale, offset):
    """A part of a micrometre, one 9 km from the origin, one 9.6 km across: the same strains."""
    v, f = surfaces.paraboloid_dish(diameter=600.0, sag=54.0, n_faces=1000)
    reference = patterns.flatten_mesh(v, f)
    result = patterns.flatten_mesh(v * scale + offset, f)
    assert result.one_to_one and np.all(np.isfinite(result.uv))
    assert result.distortion.edge_strain_rms == pytest.approx(reference.distortion.edge_strain_rms, rel=0.02, abs=1e-6)


@pytest.mark.parametrize("scale,offset", [(1.0, 1.1e7), (1e6, 0.0)])
def test_coordinates_beyond_ten_km_are_refused(scale, offset):
    v, f = surfaces.paraboloid_dish(diameter=600.0, sag=54.0, n_faces=1000)
    with pytest.raises(InputError, match="vertices lie beyond 1e\\+07 mm \\(10 km\\) of the origin"):
        patterns.flatten_mesh(v * scale + offset, f)


def test_meshing_limits_refuse_instead_of_hanging():
    import build123d as bd

    with pytest.raises(CadError, match="would make about .* triangles, over the limit"):
        patterns.load(bd.Box(1000, 1000, 1000), max_edge=0.01)


@pytest.mark.slow
def test_same_input_gives_byte_identical_files(tmp_path):
    if not EXE.exists():
        pytest.skip(f"the entry point {EXE} is not installed")
    outputs = []
    for run in range(2):
        folder = tmp_path / f"run{run}"
        folder.mkdir()
        proc = subprocess.run([str(EXE), "flatten", str(SAMPLES / "cup.step"), "-o", str(folder / "cup.dxf"),
                               "--report", str(folder / "cup.json"), "--seam-allowance", "8"],
                              capture_output=True, text=True, timeout=300)
        assert proc.returncode == 0, proc.stderr
        subprocess.run([str(EXE), "flatten", str(SAMPLES / "cup.step"), "-o", str(folder / "astm.dxf"),
                        "--profile", "astm"], capture_output=True, text=True, timeout=300, check=True)
        outputs.append([(folder / n).read_bytes() for n in ("cup.dxf", "cup.json", "astm.dxf")])
    assert outputs[0] == outputs[1]


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 10_000), bump=st.floats(0.0, 0.6), n=st.integers(150, 900))
def test_random_disk_meshes(tmp_path_factory, seed, bump, n):
    """Random disks lifted to random smooth height fields: the default method never
    folds, never gives NaN, is one-to-one, and the DXF reads back with the same outline."""
    import shapely
    from ezdxf import recover

    rng = np.random.default_rng(seed)
    p, f = surfaces.disk_mesh(n)
    p = p + rng.normal(scale=0.01, size=p.shape) * (np.linalg.norm(p, axis=1, keepdims=True) < 0.95)
    c = rng.normal(size=4)
    z = bump * (c[0] * p[:, 0] ** 2 + c[1] * p[:, 1] ** 2 + c[2] * p[:, 0] * p[:, 1] + c[3] * p[:, 0])
    v = np.column_stack([p * 100.0, z * 100.0])
    result = patterns.flatten_mesh(v, f)
    assert np.all(np.isfinite(result.uv))
    assert result.n_folded == 0 and result.one_to_one
    path = tmp_path_factory.mktemp("dxf") / "disk.dxf"
    from patterns.export import write_outline_dxf

    write_outline_dxf(path, [result.uv[loop] for loop in result.loops])
    doc, auditor = recover.readfile(path)
    assert not auditor.has_errors
    (cut,) = doc.modelspace().query("LWPOLYLINE")
    area = shapely.Polygon([q[:2] for q in cut.get_points("xy")]).area
    assert area == pytest.approx(shapely.Polygon(result.uv[result.loops[0]]).area, rel=1e-9)


def test_every_error_is_a_patterns_error_and_a_builtin():
    assert issubclass(InputError, ValueError) and issubclass(MeshTopologyError, InputError)
    assert issubclass(patterns.ExportError, OSError)
    for cls in (InputError, MeshTopologyError, CadError, patterns.FlattenError, patterns.ExportError,
                patterns.LayoutError):
        assert issubclass(cls, PatternsError)


@pytest.mark.slow
def test_a_million_face_mesh_through_the_command_line(tmp_path):
    """Bounded: a 1M-face STL goes through the command line within the subprocess's
    time limit and under 4 GB (measured: 19.6 s in all -- 4.6 s loading, 13.3 s flattening --
    and 1.54 GB peak on this 2-core machine; 29 s and 2.1 GB before the column gathers, the
    single-precision preconditioner and the sort-based unique)."""
    v, f = surfaces.paraboloid_dish(diameter=600.0, sag=54.0, n_faces=1_000_000)
    path = tmp_path / "big.stl"
    trimesh.Trimesh(v, f, process=False).export(path)
    # The command run in a fresh interpreter that reports its own peak resident size at exit.
    script = ("import resource, sys\nfrom patterns.cli import main\ncode = main(sys.argv[1:])\n"
              "print('PEAK', resource.getrusage(resource.RUSAGE_SELF).ru_maxrss, file=sys.stderr)\nsys.exit(code)")
    proc = subprocess.run([sys.executable, "-c", script, "flatten", str(path), "-o", str(tmp_path / "big.dxf"),
                           "--report", str(tmp_path / "big.json")], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    assert "1 panel, 0 seams" in proc.stdout and (tmp_path / "big.dxf").exists()
    import json

    report = json.loads((tmp_path / "big.json").read_text())
    assert report["panels"][0]["n_triangles"] == len(f) and report["panels"][0]["one_to_one"]
    peak = int(proc.stderr.split("PEAK ")[1].split()[0])  # KiB (Linux ru_maxrss)
    assert 0 < peak * 1024 < 4e9
