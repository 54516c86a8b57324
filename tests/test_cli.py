"""The installed ``patterns`` command, run as a subprocess on the bundled samples:
every subcommand, its files and its exit code."""

import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import shapely
from ezdxf import recover

import patterns
from patterns.reading import read_mesh

from .conftest import SAMPLES

EXE = Path(sys.executable).with_name("patterns")


def run(*args, cwd=None, timeout=600):
    if not EXE.exists():
        pytest.skip(f"the entry point {EXE} is not installed (pip install the package)")
    return subprocess.run([str(EXE), *map(str, args)], capture_output=True, text=True, cwd=cwd, timeout=timeout)


def test_flatten_a_step_file_writes_the_pattern_report_and_pictures(tmp_path):
    out = tmp_path / "cup.dxf"
    proc = run("flatten", SAMPLES / "cup.step", "-o", out, "--seam-allowance", "10", "--report",
               tmp_path / "cup.json", "--preview", tmp_path / "cup.png", "--heat-map", tmp_path / "heat.svg")
    assert proc.returncode == 0, proc.stderr
    assert "4 panels, 4 seams" in proc.stdout
    doc, auditor = recover.readfile(out)
    assert not auditor.has_errors
    assert len(doc.modelspace().query('LWPOLYLINE[layer=="CUT"]')) == 4
    assert len(doc.modelspace().query('LWPOLYLINE[layer=="SEW"]')) == 4
    report = json.loads((tmp_path / "cup.json").read_text())
    # The numbers printed are the report's.
    for panel in report["panels"]:
        assert re.search(rf"{panel['name']}\s+\d+\s+[\d.]+\s+[\d.]+\s+{100 * panel['strain_rms']:.2f}", proc.stdout)
    assert (tmp_path / "cup.png").read_bytes()[:4] == b"\x89PNG"
    assert "<svg" in (tmp_path / "heat.svg").read_text()


@pytest.mark.slow
def test_flatten_a_mesh_matches_the_library(tmp_path):
    out = tmp_path / "dish.dxf"
    proc = run("flatten", SAMPLES / "dish.obj", "-o", out)
    assert proc.returncode == 0, proc.stderr
    mesh = read_mesh(SAMPLES / "dish.obj")
    r = patterns.flatten_mesh(mesh.vertices, mesh.faces, energy_tolerance=1e-6)  # patterns.flatten's default
    doc, auditor = recover.readfile(out)
    assert not auditor.has_errors
    (cut,) = doc.modelspace().query('LWPOLYLINE[layer=="CUT"]')
    area = shapely.Polygon([p[:2] for p in cut.get_points("xy")]).area
    assert area == pytest.approx(shapely.Polygon(r.uv[r.loops[0]]).area, rel=1e-9)


def test_flatten_developable_sample_to_obj_is_exact(tmp_path):
    out = tmp_path / "cone.obj"
    proc = run("flatten", SAMPLES / "cone.obj", "-o", out, "--method", "isometric")
    assert proc.returncode == 0, proc.stderr
    flat = np.loadtxt([ln[2:] for ln in out.read_text().splitlines() if ln.startswith("v ")])
    mesh = read_mesh(SAMPLES / "cone.obj")
    e = mesh.faces[:, [0, 1]]
    l3 = np.linalg.norm(mesh.vertices[e[:, 0]] - mesh.vertices[e[:, 1]], axis=1)
    l2 = np.linalg.norm(flat[e[:, 0]] - flat[e[:, 1]], axis=1)
    assert np.abs(l2 / l3 - 1).max() < 1e-9


@pytest.mark.slow
def test_flatten_astm_profile(tmp_path):
    out = tmp_path / "cup.dxf"
    proc = run("flatten", SAMPLES / "cup.step", "-o", out, "--profile", "astm")
    assert proc.returncode == 0, proc.stderr
    doc, _ = recover.readfile(out)
    assert len(doc.modelspace().query("INSERT")) == 4


@pytest.mark.slow
def test_a_failed_strain_check_exits_1_and_still_writes(tmp_path):
    out = tmp_path / "cup.dxf"
    proc = run("flatten", SAMPLES / "cup.step", "-o", out, "--max-strain", "0.03")
    assert proc.returncode == 1, proc.stderr
    assert "NOT ok" in proc.stdout and "strain above 3.00%" in proc.stdout
    assert out.exists()
    ok = run("flatten", SAMPLES / "hopper.step", "-o", tmp_path / "hopper.dxf", "--max-strain", "0.01")
    assert ok.returncode == 0, ok.stdout + ok.stderr


@pytest.mark.slow
def test_check_reports_without_writing_a_pattern(tmp_path):
    proc = run("check", SAMPLES / "cup.step", "--max-strain", "0.03", "--report", tmp_path / "r.json")
    assert proc.returncode == 1
    assert [p.name for p in tmp_path.iterdir()] == ["r.json"]
    doc = json.loads((tmp_path / "r.json").read_text())
    assert doc["ok"] is False and len(doc["findings"]) == 4
    proc = run("check", SAMPLES / "hopper.step")
    assert proc.returncode == 0 and "hopper.step: ok" in proc.stdout


def test_info_lists_panels_and_seams(tmp_path):
    proc = run("info", SAMPLES / "duct_transition.step")
    assert proc.returncode == 0, proc.stderr
    assert "4 panels, 4 seams" in proc.stdout
    lengths = [float(x) for x in re.findall(r"face\d/face\d\s+\d+\s+([\d.]+)", proc.stdout)]
    assert lengths == pytest.approx([328.096] * 4, abs=1e-3)
    assert list(tmp_path.iterdir()) == []


def test_demo_runs_the_whole_pipeline(tmp_path):
    proc = run("demo", cwd=tmp_path, timeout=600)
    assert proc.returncode == 0, proc.stderr
    out = tmp_path / "patterns-demo"
    names = sorted(p.name for p in out.iterdir())
    assert names == ["cup.dxf", "cup.json", "cup.step", "cup_astm.dxf", "cup_heatmap.png", "cup_preview.png"]
    for name in names:
        assert str(out / name) in proc.stdout or f"patterns-demo/{name}" in proc.stdout
    doc, auditor = recover.readfile(out / "cup.dxf")
    assert not auditor.has_errors and len(doc.modelspace().query('LWPOLYLINE[layer=="CUT"]')) == 4
    assert json.loads((out / "cup.json").read_text())["schema"] == "patterns.report/5"


def _batch_folder(folder: Path, n_good: int = 20) -> list[str]:
    """``n_good`` readable parts (the STEP samples and mesh files) and two broken files."""
    import trimesh

    from patterns import surfaces

    folder.mkdir()
    names = []
    for i in range(n_good):
        kind = i % 5
        if kind < 4:
            src = ["cup.step", "hopper.step", "hull_panel.step", "duct_transition.step"][kind]
            name = f"part{i:02d}_{src}"
            shutil.copy(SAMPLES / src, folder / name)
        else:
            v, f = surfaces.spherical_cap(radius=100.0 + i, half_angle=40.0, n_faces=1500)
            name = f"part{i:02d}_cap.stl"
            trimesh.Trimesh(v, f, process=False).export(folder / name)
        names.append(name)
    (folder / "broken.step").write_bytes(b"ISO-10303-21;\nHEADER;\nthis is not a step file\n")
    (folder / "broken.obj").write_text("v 0 0 0\nv 1 0 0\nf 1 2 7\n")
    (folder / "notes.txt").write_text("not a part: ignored")
    return names


@pytest.mark.slow
def test_batch_keeps_going_past_broken_files(tmp_path):
    names = _batch_folder(tmp_path / "in")
    proc = run("batch", tmp_path / "in", "-o", tmp_path / "out", "--jobs", "2", timeout=900)
    assert proc.returncode == 2, proc.stdout + proc.stderr
    assert "batch: 22 files: 20 ok, 2 failed (2 processes); 20 written to" in proc.stdout
    for name in names:
        assert (tmp_path / "out" / Path(name).with_suffix(".dxf").name).exists()
        assert (tmp_path / "out" / Path(name).with_suffix(".json").name).exists()
    lines = {ln.split()[0]: ln for ln in proc.stdout.splitlines() if ln.strip()}
    assert "failed: " in lines["broken.step"] and "broken.step: not a readable STEP" in lines["broken.step"]
    assert "failed: " in lines["broken.obj"] and "broken.obj: " in lines["broken.obj"]
    assert "notes.txt" not in proc.stdout
    assert not (tmp_path / "out" / "broken.dxf").exists()


@pytest.mark.slow
def test_batch_on_a_local_dask_cluster(tmp_path):
    distributed = pytest.importorskip("distributed", reason="Dask is the optional extra patterns[dask]")
    names = _batch_folder(tmp_path / "in", n_good=4)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, host="127.0.0.1", processes=True,
                                  dashboard_address=None) as cluster:
        proc = run("batch", tmp_path / "in", "-o", tmp_path / "out", "--scheduler", cluster.scheduler_address,
                   timeout=900)
    assert proc.returncode == 2, proc.stdout + proc.stderr
    assert "batch: 6 files: 4 ok, 2 failed (Dask scheduler tcp://127.0.0.1:" in proc.stdout
    for name in names:
        assert (tmp_path / "out" / Path(name).with_suffix(".dxf").name).exists()


@pytest.mark.slow
def test_batch_exit_codes(tmp_path):
    folder = tmp_path / "in"
    folder.mkdir()
    shutil.copy(SAMPLES / "hopper.step", folder)
    assert run("batch", folder, "-o", tmp_path / "a").returncode == 0
    shutil.copy(SAMPLES / "cup.step", folder)
    failing = run("batch", folder, "-o", tmp_path / "b", "--max-strain", "0.03")
    assert failing.returncode == 1 and "check failed" in failing.stdout
    bad = run("batch", tmp_path / "nowhere", "-o", tmp_path / "c")
    assert bad.returncode == 2 and "no such folder" in bad.stderr
    unreachable = run("batch", folder, "-o", tmp_path / "d", "--scheduler", "tcp://127.0.0.1:9")
    assert unreachable.returncode == 2 and "cannot reach the Dask scheduler" in unreachable.stderr


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (("flatten", "missing.obj", "-o", "x.dxf"), "missing.obj: no such file"),
        (("flatten", "missing.step", "-o", "x.dxf"), "missing.step: no such file"),
        (("flatten", SAMPLES / "dish.obj", "-o", "x.pdf"), "x.pdf: -o writes .dxf, .svg or .obj, not '.pdf'"),
        (("flatten", SAMPLES / "dish.obj", "-o", "nofolder/x.dxf"), "folder nofolder does not exist"),
        (("flatten", SAMPLES / "cup.step", "-o", "x.obj"), "4 panels; a flat .obj holds one"),
        (("flatten", SAMPLES / "cup.step", "-o", "x.dxf", "--max-edge", "-1"), "--max-edge must be"),
        (("flatten", SAMPLES / "cup.step", "-o", "x.dxf", "--seam-allowance", "-2"), "--seam-allowance (mm) must be"),
        (("flatten", SAMPLES / "cup.step", "-o", "x.dxf", "--max-strain", "0"), "--max-strain must be a ratio"),
        (("flatten", SAMPLES / "cup.step", "-o", "x.dxf", "--preview", "x.jpg"), "--preview writes .png or .svg"),
        (("check", "part.xyz"), "part.xyz: unknown file type '.xyz'"),
        (("info", "missing.iges"), "no such file"),
        (("batch", ".", "-o", "out", "--jobs", "0"), "jobs must be an integer between 1 and 1024, got 0"),
    ],
)
def test_user_errors_print_one_line_and_exit_2(tmp_path, args, words):
    proc = run(*args, cwd=tmp_path)
    assert proc.returncode == 2, proc.stdout + proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("patterns: error: ") and words in lines[0], proc.stderr
    assert list(tmp_path.iterdir()) == []  # no partial output


def test_broken_files(tmp_path):
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n")
    proc = run("flatten", bad, "-o", tmp_path / "x.dxf")
    assert proc.returncode == 2 and "NaN" in proc.stderr and "Traceback" not in proc.stderr
    assert not (tmp_path / "x.dxf").exists()
    noise = tmp_path / "noise.step"
    noise.write_bytes(bytes(range(256)) * 8)
    proc = run("flatten", noise, "-o", tmp_path / "y.dxf")
    assert proc.returncode == 2 and "noise.step: not a readable STEP file" in proc.stderr
    assert not (tmp_path / "y.dxf").exists()


def test_debug_shows_the_traceback(tmp_path):
    proc = run("--debug", "flatten", "missing.obj", "-o", "x.dxf", cwd=tmp_path)
    assert proc.returncode != 0 and "Traceback" in proc.stderr


def test_usage_error_exits_2_in_one_line():
    proc = run("flatten")
    assert proc.returncode == 2
    assert proc.stderr == ("patterns: error: the following arguments are required: -o/--output, input "
                           "(patterns flatten --help lists the options)\n")


def test_relaxed_is_the_default(tmp_path):
    proc = run("flatten", SAMPLES / "dish.obj", "-o", tmp_path / "a.dxf", "--max-iterations", "3")
    assert proc.returncode == 0, proc.stderr
    assert "flattened (relaxed)" in proc.stdout
    bad = run("flatten", SAMPLES / "dish.obj", "-o", tmp_path / "b.dxf", "--max-iterations", "0")
    assert bad.returncode == 2 and "--max-iterations must be" in bad.stderr
    assert not (tmp_path / "b.dxf").exists()


def test_progress_bar_only_on_a_terminal(capsys):
    import io

    from patterns.terminal import Progress

    stream = io.StringIO()
    bar = Progress("work", stream=stream)  # a StringIO is not a terminal
    bar(5, 10)
    assert stream.getvalue() == ""
    bar = Progress("work", stream=stream, enabled=True)
    bar(5, 10)
    bar(10, 10)
    assert "work [###############---------------]  50%" in stream.getvalue()
    assert stream.getvalue().endswith("100%\n")


def test_sheet_metal_options(tmp_path):
    out = tmp_path / "shell.dxf"
    proc = run("flatten", SAMPLES / "rolled_cylinder.step", "-o", out, "--thickness", "2", "--k-factor", "0.44",
               "--reference", "inside", "--arcs", "--bend-spacing", "100")
    assert proc.returncode == 0, proc.stderr
    doc, auditor = recover.readfile(out)
    assert not auditor.has_errors
    (cut,) = doc.modelspace().query('LWPOLYLINE[layer=="CUT"]')
    xs = [p[0] for p in cut.get_points("xy")]
    assert max(xs) - min(xs) == pytest.approx(2 * np.pi * (250 + 0.88), abs=0.01)
    assert len(doc.modelspace().query('LINE[layer=="BEND"]')) == 15


@pytest.mark.slow
def test_garment_options(tmp_path):
    out = tmp_path / "cup.dxf"
    proc = run("flatten", SAMPLES / "cup.step", "-o", out, "--grain", "0,0,1", "--notch-spacing", "20",
               "--seam-allowance", "10", "--roll-width", "600", "--nest-time", "2")
    assert proc.returncode == 0, proc.stderr
    assert "nested on a 600 mm roll" in proc.stdout
    doc, auditor = recover.readfile(out)
    assert not auditor.has_errors
    assert len(doc.modelspace().query('LINE[layer=="NOTCH"]')) == 4 * 2 * 8
    cuts = [shapely.Polygon([p[:2] for p in e.get_points("xy")]) for e in doc.modelspace().query('LWPOLYLINE[layer=="CUT"]')]
    margin = patterns.pieces.MARGIN  # the drawing starts this far from the axes
    assert max(c.bounds[2] for c in cuts) <= 600 + margin + 1e-6 and min(c.bounds[0] for c in cuts) >= margin - 1e-6
    bad = run("flatten", SAMPLES / "cup.step", "-o", tmp_path / "x.dxf", "--grain", "1,2")
    assert bad.returncode == 2 and "X,Y,Z" in bad.stderr


def test_a_closed_pipe_does_not_stop_the_files_or_show_a_traceback(tmp_path):
    """``patterns flatten ... | head -1``: the reader goes away after a line."""
    if not EXE.exists():
        pytest.skip(f"the entry point {EXE} is not installed (pip install the package)")
    out = tmp_path / "dish.dxf"
    proc = subprocess.Popen([str(EXE), "flatten", str(SAMPLES / "dish.obj"), "-o", str(out), "--report",
                             str(tmp_path / "dish.json")], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    proc.stdout.close()  # nobody reads: every line printed hits a closed pipe
    stderr = proc.stderr.read().decode()
    assert proc.wait(timeout=300) == 0, stderr
    assert "Traceback" not in stderr and "BrokenPipe" not in stderr
    doc, auditor = recover.readfile(out)
    assert not auditor.has_errors and len(doc.modelspace().query('LWPOLYLINE[layer=="CUT"]')) == 1
    assert json.loads((tmp_path / "dish.json").read_text())["panels"][0]["one_to_one"]


@pytest.mark.slow
def test_energy_and_min_stretch_options(tmp_path):
    """--energy arap presses part of a head flat (its least-strain layout would fold);
    --min-stretch 0.3 keeps every triangle open; the default (auto) goes on with the hybrid."""
    from .conftest import CORPUS

    path = CORPUS / "bff_bunnyhead.obj"
    if not path.is_file():
        pytest.skip(f"corpus mesh {path} is absent")
    strain = {}  # the smallest principal stretch
    for label, extra in (("arap", ("--energy", "arap")), ("guarded", ("--energy", "arap", "--min-stretch", "0.3")),
                         ("auto", ())):
        report = tmp_path / f"{label}.json"
        proc = run("flatten", path, "-o", tmp_path / f"{label}.dxf", "--report", report, *extra)
        # a head in one piece is not a usable pattern of it (strain above 50 % over much of it): exit 1, said
        assert proc.returncode == 1 and "not a usable pattern of this surface" in proc.stdout, proc.stderr
        panel = json.loads(report.read_text())["panels"][0]
        strain[label] = panel["stretch_min"]
        assert panel["energy"] == ("hybrid" if label == "auto" else "arap")
    assert strain["arap"] < 1e-3  # a triangle pressed (nearly) flat
    assert strain["guarded"] > 0.25 and strain["auto"] > 0.1  # none below about 0.3 (0.1) of its size
    proc = run("flatten", path, "-o", tmp_path / "bad.dxf", "--min-stretch", "1.5")
    assert proc.returncode == 2 and "--min-stretch must be" in proc.stderr and "Traceback" not in proc.stderr
    assert not (tmp_path / "bad.dxf").exists()




@pytest.mark.slow
def test_seams_and_ease_from_the_command_line(tmp_path):
    lengths = {}
    for label, extra in (("true", ()), ("free", ("--seams", "free")), ("eased", ("--ease", "0:face0:5"))):
        report = tmp_path / f"{label}.json"
        proc = run("flatten", SAMPLES / "cup.step", "-o", tmp_path / f"{label}.dxf", "--report", report, *extra)
        assert proc.returncode == 0, proc.stderr
        lengths[label] = json.loads(report.read_text())["seams"][0]
    true, free, eased = lengths["true"], lengths["free"], lengths["eased"]
    assert true["length_flat"] == pytest.approx([true["length_3d_polyline"]] * 2, rel=2e-4)
    assert free["length_held"] is None and min(free["length_flat"]) > 1.03 * free["length_3d"]
    side = eased["panels"].index("face0")
    assert eased["length_flat"][side] == pytest.approx(eased["length_3d_polyline"] + 5.0, rel=2e-4)
    for bad, words in ((("--ease", "junk"), "SEAM:PANEL"), (("--seams", "loose"), "invalid choice"),
                       (("--ease", "9:face0:5"), "seam 9")):
        out = tmp_path / "bad.dxf"
        proc = run("flatten", SAMPLES / "cup.step", "-o", out, *bad)
        assert proc.returncode == 2 and words in proc.stderr and "Traceback" not in proc.stderr
        assert not out.exists()


def test_each_duration_says_what_it_covers_and_a_kept_marker_says_so(tmp_path, capsys, monkeypatch):
    """Issue 34: "flattened in 10.85 s" counted the nest, and a cached marker said "(sparrow, 0.0 s)"."""
    from patterns import cli

    monkeypatch.setenv("PATTERNS_CACHE", str(tmp_path / "cache"))
    argv = ["flatten", str(SAMPLES / "cup.step"), "-o", str(tmp_path / "cup.dxf"), "--roll-width", "600",
            "--nest-time", "2"]
    import time

    start = time.perf_counter()
    assert cli.main(argv) == 0
    wall = time.perf_counter() - start
    first = capsys.readouterr().out
    flat = float(re.search(r"flattened \(relaxed\) in ([\d.]+) s \(the flattening alone\)", first).group(1))
    searched = float(re.search(r"nested on a 600 mm roll: .* \(sparrow searched ([\d.]+) s\)", first).group(1))
    assert flat + searched <= wall + 0.01  # two parts of the run, neither counted in the other
    assert cli.main(argv) == 0
    again = capsys.readouterr().out
    assert re.search(r"nested on a 600 mm roll: .* \(a marker kept from an earlier run with the same pieces and "
                     r"options, [\d.]+ s; --no-nest-cache searches anew\)", again), again
    assert cli.main([*argv, "--no-nest-cache"]) == 0
    assert "(sparrow searched" in capsys.readouterr().out


def test_counts_are_singular_for_one():
    from patterns.text import counted

    assert [counted(n, "panel") for n in (0, 1, 2)] == ["0 panels", "1 panel", "2 panels"]
    assert counted(1, "vertex") == "1 vertex" and counted(2, "vertex") == "2 vertices"
    assert counted(1, "process") == "1 process" and counted(4, "process") == "4 processes"
    model = patterns.load(SAMPLES / "cone.obj")
    assert ", 1 panel, 0 seams, " in repr(model)
    assert "(1 panel, 0 seams, " in str(patterns.check(patterns.flatten(model)))


def test_one_panel_and_one_bend_read_in_the_singular(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "patterns", "info", str(SAMPLES / "cone.obj")], capture_output=True,
                          text=True, timeout=120, check=False)
    assert proc.returncode == 0 and "cone.obj: 1 panel, 0 seams (" in proc.stdout, proc.stdout + proc.stderr
    proc = subprocess.run([sys.executable, "-m", "patterns", "unfold", str(SAMPLES / "bracket.step"), "-o",
                           str(tmp_path / "l.dxf")], capture_output=True, text=True, timeout=120, check=False)
    assert proc.returncode == 0 and ": sheet 2 mm, 1 bend, 1 hole; blank " in proc.stdout, proc.stdout + proc.stderr


def test_a_pattern_is_never_written_under_a_suffix_of_another_format(tmp_path):
    """Issue 34: Pattern.to_dxf("x.pdf") wrote a DXF named x.pdf; patterns.write takes its format from the suffix
    and refuses one it cannot write, writing nothing."""
    pattern = patterns.flatten(patterns.load(SAMPLES / "cone.obj"))
    for name in ("x.pdf", "x.DXF.pdf", "x", "x.png"):
        with pytest.raises(patterns.InputError, match=r"cannot write '(\.pdf|\.png|\(no suffix\))' files; "
                                                      r"write \.csv, \.dxf, \.json, \.svg"):
            patterns.write(pattern, tmp_path / name)
    assert not list(tmp_path.iterdir())


_FREED = r'''
import sys
import numpy as np
from patterns.launch import one_run_allocator

took = one_run_allocator() if sys.argv[1] == "one run" else None


def rss():  # kB: this process's resident set now
    with open("/proc/self/status") as status:
        return next(int(line.split()[1]) for line in status if line.startswith("VmRSS:"))


block = np.ones(20 * 2**20 // 8)  # 20 MB, written: resident
before = rss()
del block
print(took, before - rss())
'''


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc's allocator, read in /proc")
def test_a_one_run_process_keeps_the_memory_it_frees_and_a_default_one_gives_it_back():
    """``patterns.launch.one_run_allocator`` (what the ``patterns`` command sets for itself): a 20 MB array
    freed stays with the process, for the next one (no page to fault in again); without it glibc gives the
    block back to the system at once."""
    runs = {}
    for mode in ("default", "one run"):
        out = subprocess.run([sys.executable, "-c", _FREED, mode], capture_output=True, text=True, check=True)
        took, dropped = out.stdout.split()
        runs[mode] = took, int(dropped)
    assert runs["default"][1] > 15_000  # kB: the 20 MB went back
    assert runs["one run"] == ("True", runs["one run"][1]) and runs["one run"][1] < 2_000
