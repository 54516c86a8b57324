"""The installed ``patterns`` command, run as a subprocess on the bundled samples."""

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import shapely
from ezdxf import recover

import patterns
from patterns.load import read_mesh

from .conftest import SAMPLES

EXE = Path(sys.executable).with_name("patterns")


def run(*args, cwd=None):
    if not EXE.exists():
        pytest.skip(f"the entry point {EXE} is not installed (pip install the package)")
    return subprocess.run([str(EXE), *map(str, args)], capture_output=True, text=True, cwd=cwd, timeout=300)


def test_flatten_writes_a_dxf_matching_the_library(tmp_path):
    out = tmp_path / "dish.dxf"
    proc = run("flatten", SAMPLES / "dish.obj", "-o", out)
    assert proc.returncode == 0, proc.stderr
    assert "overlap: one-to-one" in proc.stdout
    rms = float(re.search(r"RMS ([0-9.]+) %", proc.stdout).group(1))
    mesh = read_mesh(SAMPLES / "dish.obj")
    r = patterns.flatten_mesh(mesh.vertices, mesh.faces)
    assert rms == pytest.approx(100 * r.distortion.edge_strain_rms, abs=5e-4)
    doc, auditor = recover.readfile(out)
    assert not auditor.has_errors
    (cut,) = doc.modelspace().query("LWPOLYLINE")
    area = shapely.Polygon([p[:2] for p in cut.get_points("xy")]).area
    assert area == pytest.approx(shapely.Polygon(r.uv[r.loops[0]]).area, rel=1e-9)


def test_flatten_developable_sample_to_obj_is_exact(tmp_path):
    out = tmp_path / "cone.obj"
    proc = run("flatten", SAMPLES / "cone.obj", "-o", out, "--method", "isometric")
    assert proc.returncode == 0, proc.stderr
    assert "edge strain: RMS 0.000 %, max 0.000 %" in proc.stdout
    flat = np.loadtxt([ln[2:] for ln in out.read_text().splitlines() if ln.startswith("v ")])
    mesh = read_mesh(SAMPLES / "cone.obj")
    e = mesh.faces[:, [0, 1]]
    l3 = np.linalg.norm(mesh.vertices[e[:, 0]] - mesh.vertices[e[:, 1]], axis=1)
    l2 = np.linalg.norm(flat[e[:, 0]] - flat[e[:, 1]], axis=1)
    assert np.abs(l2 / l3 - 1).max() < 1e-9


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (("flatten", "missing.obj", "-o", "x.dxf"), "missing.obj: no such file"),
        (("flatten", SAMPLES / "dish.obj", "-o", "x.pdf"), "unknown output type '.pdf'"),
        (("flatten", SAMPLES / "dish.obj", "-o", "nofolder/x.dxf"), "folder nofolder does not exist"),
        (("flatten", SAMPLES / "dish.obj", "-o", "x.dxf", "--seed-face", "-3"), "seed_face"),
    ],
)
def test_user_errors_print_one_line_and_exit_2(tmp_path, args, words):
    proc = run(*args, cwd=tmp_path)
    assert proc.returncode == 2
    assert proc.stdout == ""
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("patterns: error: ") and words in lines[0]
    assert list(tmp_path.iterdir()) == []  # no partial output


def test_broken_mesh_file(tmp_path):
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n")
    proc = run("flatten", bad, "-o", tmp_path / "x.dxf")
    assert proc.returncode == 2 and "NaN" in proc.stderr and "Traceback" not in proc.stderr
    assert not (tmp_path / "x.dxf").exists()


def test_debug_shows_the_traceback(tmp_path):
    proc = run("--debug", "flatten", "missing.obj", "-o", "x.dxf", cwd=tmp_path)
    assert proc.returncode != 0 and "Traceback" in proc.stderr


def test_usage_error_exits_2():
    proc = run("flatten")
    assert proc.returncode == 2 and "usage:" in proc.stderr


def test_relaxed_is_the_default_and_reports_its_start(tmp_path):
    proc = run("flatten", SAMPLES / "dish.obj", "-o", tmp_path / "a.dxf", "--max-iterations", "3")
    assert proc.returncode == 0, proc.stderr
    assert "(relaxed, from the greedy layout, 3 iterations)" in proc.stdout
    bad = run("flatten", SAMPLES / "dish.obj", "-o", tmp_path / "b.dxf", "--max-iterations", "0")
    assert bad.returncode == 2 and "max_iterations" in bad.stderr
    assert not (tmp_path / "b.dxf").exists()
