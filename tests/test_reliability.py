"""Trust at the command line (issue 21): a refused run writes nothing, no run destroys a file it was
not asked to write, "ok" means the pattern is usable -- every class of the issue, as a user (and a
hostile one) would meet it.  docs/reliability.md is the table of what each bad input gets.

Each case checks: the exit code; one line on stderr (for exit 2); every file in the folder
byte-identical afterwards, nothing created and no temporary left (for exit 2)."""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import shutil
import signal
import subprocess
import sys
import time
import xml.dom.minidom
import zipfile
from pathlib import Path

import numpy as np
import pytest
import trimesh

import patterns
from patterns import cli, surfaces

from .conftest import SAMPLES
from .helpers import small_disk

EXE = Path(sys.executable).with_name("patterns")


# --------------------------------------------------------------------------- #
# Helpers: the folder before and after, the command line in this process or in its own
# --------------------------------------------------------------------------- #


def snapshot(root: Path) -> dict:
    """Every entry under ``root``: its kind and, for a regular file, its bytes' hash."""
    out = {}
    for dirpath, dirnames, filenames in os.walk(os.fsencode(root)):
        for name in dirnames + filenames:
            p = os.path.join(dirpath, name)
            rel = os.path.relpath(p, os.fsencode(root))
            if os.path.islink(p):
                out[rel] = ("link", os.readlink(p))
            elif os.path.isdir(p):
                out[rel] = ("dir",)
            elif os.path.isfile(p):
                out[rel] = ("file", hashlib.sha256(open(p, "rb").read()).hexdigest())
            else:
                out[rel] = ("special",)
    return out


def run(argv, cwd: Path, capfd) -> tuple[int, str, str]:
    """``patterns ARGV`` in this process, in ``cwd``: (exit code, stdout, stderr)."""
    old = os.getcwd()
    os.chdir(cwd)
    try:
        code = cli.main([os.fsdecode(a) if isinstance(a, bytes) else str(a) for a in argv])
    finally:
        os.chdir(old)
    out, err = capfd.readouterr()
    return code, out, err


def refused(argv, cwd: Path, capfd, words: str) -> str:
    """The run exits 2 with one line on stderr holding ``words``, and changes nothing in ``cwd``."""
    before = snapshot(cwd)
    code, out, err = run(argv, cwd, capfd)
    assert code == 2, (out, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("patterns: error: "), err
    assert words in lines[0], lines[0]
    assert snapshot(cwd) == before
    return lines[0]


@pytest.fixture
def here(tmp_path):
    """A folder holding the cup (CAD) and the dish (mesh)."""
    shutil.copy(SAMPLES / "cup.step", tmp_path / "cup.step")
    shutil.copy(SAMPLES / "dish.obj", tmp_path / "dish.obj")
    return tmp_path


def no_dac_override() -> list:
    """A command prefix under which file permissions bind this process too (root drops the capabilities
    that let it read and write anything; another user needs nothing)."""
    if os.geteuid() != 0:
        return []
    if shutil.which("setpriv") is None:
        pytest.skip("running as root without setpriv: permissions cannot be made to bind")
    caps = "-dac_override,-dac_read_search"
    return ["setpriv", f"--inh-caps={caps}", f"--bounding-set={caps}"]


def cmd(args, cwd, *, prefix=(), timeout=300, **kwargs):
    return subprocess.run([*prefix, str(EXE), *map(str, args)], cwd=cwd, capture_output=True, text=True,
                          timeout=timeout, **kwargs)


# --------------------------------------------------------------------------- #
# 1. Data lost: no output may replace an input or another output
# --------------------------------------------------------------------------- #


def test_the_output_cannot_be_the_input(here, capfd):
    shutil.copy(here / "dish.obj", here / "part.obj")
    refused(["flatten", "part.obj", "-o", "part.obj"], here, capfd, "part.obj: is an input of this run")


def test_the_report_cannot_be_the_input_or_the_pattern(here, capfd):
    refused(["flatten", "cup.step", "-o", "x.dxf", "--report", "cup.step"], here, capfd, "--report writes .json")
    refused(["flatten", "cup.step", "-o", "cup.dxf", "--report", "cup.dxf"], here, capfd, "--report writes .json")
    os.symlink("cup.step", here / "r.json")  # a link to the input, under a report's name
    refused(["flatten", "cup.step", "-o", "x.dxf", "--report", "r.json"], here, capfd, "is an input of this run")
    os.link(here / "dish.obj", here / "hard.json")  # the same file under another name
    refused(["check", "dish.obj", "--report", "hard.json"], here, capfd, "is an input of this run")


def test_two_outputs_cannot_share_a_file(here, capfd):
    refused(["flatten", "dish.obj", "-o", "d.dxf", "--heat-map", "pic.png", "--preview", "pic.png"], here, capfd,
            "given twice, as --heat-map and --preview")
    refused(["flatten", "dish.obj", "-o", "d.dxf", "--heat-map", "pic.png", "--preview", "./pic.png"], here, capfd,
            "given twice")


def test_a_device_or_a_pipe_is_refused_and_a_link_is_written_through(here, capfd):
    os.symlink("/dev/null", here / "null.json")
    refused(["flatten", "dish.obj", "-o", "d.dxf", "--report", "null.json"], here, capfd, "is a device")
    os.mkfifo(here / "pipe.json")
    refused(["flatten", "dish.obj", "-o", "d.dxf", "--report", "pipe.json"], here, capfd, "is a pipe")
    os.unlink(here / "pipe.json")
    os.symlink("real.json", here / "link.json")
    code, _, _ = run(["flatten", "dish.obj", "-o", "d.dxf", "--report", "link.json"], here, capfd)
    assert code == 0
    assert os.readlink(here / "link.json") == "real.json"  # still a link, to the report now
    assert json.loads((here / "real.json").read_text())["pattern"] == "dish.obj"


@pytest.mark.slow
def test_batch_keeps_colliding_stems_apart_and_writes_nothing_outside(tmp_path, capfd):
    parts = tmp_path / "parts"
    parts.mkdir()
    shutil.copy(SAMPLES / "cup.step", parts / "a.step")
    shutil.copy(SAMPLES / "dish.obj", parts / "a.obj")
    shutil.copy(SAMPLES / "cone.obj", parts / "..obj")  # its stem is "."
    shutil.copy(SAMPLES / "cone.obj", parts / "b.obj")
    before = snapshot(tmp_path / "parts")
    code, out, err = run(["batch", "parts", "-o", "out", "--jobs", "2"], tmp_path, capfd)
    assert code == 0, out + err
    written = sorted(p.name for p in (tmp_path / "out").iterdir())
    assert written == sorted(["a.step.dxf", "a.step.json", "a.obj.dxf", "a.obj.json", "..obj.dxf", "..obj.json",
                              "b.dxf", "b.json"])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out", "parts"]  # nothing beside the folders
    assert snapshot(tmp_path / "parts") == before
    reports = {n: json.loads((tmp_path / "out" / n).read_text())["pattern"] for n in written if n.endswith(".json")}
    assert reports == {"a.step.json": "a.step", "a.obj.json": "a.obj", "..obj.json": "..obj", "b.json": "b.obj"}


# --------------------------------------------------------------------------- #
# 2. Exit 2 after writing: every check comes before any work
# --------------------------------------------------------------------------- #


def test_outputs_into_a_missing_folder_are_refused_before_anything_is_written(here, capfd):
    for flag in ("--preview", "--report", "--heat-map"):
        name = "missing/p.json" if flag == "--report" else "missing/p.png"
        refused(["flatten", "dish.obj", "-o", "d.dxf", flag, name], here, capfd, "folder missing does not exist")


def test_a_usage_error_between_outputs_writes_nothing(here, capfd):
    refused(["flatten", "dish.obj", "-o", "flat.obj", "--preview", "p.png"], here, capfd,
            "--preview renders the DXF file")
    refused(["flatten", "cup.step", "-o", "flat.obj", "--report", "r.json"], here, capfd,
            "4 panels; a flat .obj holds one")


def test_bad_options_are_refused_before_a_large_mesh_is_read(tmp_path, capfd):
    """The options are checked before the input is even opened: a FIFO that no one writes would block any
    reader of it forever, so the refusal proves the order (no clock involved)."""
    os.mkfifo(tmp_path / "big.obj")
    proc = cmd(["flatten", "big.obj", "-o", "d.dxf", "--seam-allowance", "-5"], tmp_path, timeout=60)
    assert proc.returncode == 2 and proc.stderr.splitlines() == [
        "patterns: error: big.obj: --seam-allowance (mm) must be a number between 0 and 1000, got -5.0"], proc.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["big.obj"]


# --------------------------------------------------------------------------- #
# 3. Tracebacks: one line instead
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize("big", [1e200, 1e300])
def test_absurd_coordinates(tmp_path, capfd, big):
    (tmp_path / "huge.obj").write_text(f"v 0 0 0\nv {big} 0 0\nv 0 {big} 0\nf 1 2 3\n")
    refused(["flatten", "huge.obj", "-o", "d.dxf"], tmp_path, capfd, "beyond 1e+07 mm (10 km) of the origin")


def test_an_output_that_is_a_folder(here, capfd):
    (here / "x.dxf").mkdir()
    refused(["flatten", "dish.obj", "-o", "x.dxf"], here, capfd, "x.dxf: is a folder")


def test_a_full_disk_leaves_nothing_behind(tmp_path):
    disk = tmp_path / "disk"
    small_disk(disk, "120k")
    try:
        shutil.copy(SAMPLES / "cup.step", disk / "cup.step")
        before = snapshot(disk)
        proc = cmd(["flatten", "cup.step", "-o", "cup.dxf", "--report", "cup.json", "--heat-map", "h.png"], disk)
        assert proc.returncode == 2, proc.stdout + proc.stderr
        (line,) = proc.stderr.strip().splitlines()
        assert "No space left on device" in line and ".~patterns" not in line
        assert snapshot(disk) == before  # neither the DXF nor the JSON written beside it, no temporary
    finally:
        subprocess.run(["umount", str(disk)], check=False)


def test_demo_into_a_read_only_folder(tmp_path):
    (tmp_path / "ro").mkdir()
    os.chmod(tmp_path / "ro", 0o555)
    proc = cmd(["demo", "-o", "ro/demo"], tmp_path, prefix=no_dac_override())
    assert proc.returncode == 2 and len(proc.stderr.strip().splitlines()) == 1, proc.stderr
    assert "ro/demo: cannot create the demo folder (Permission denied)" in proc.stderr
    assert list((tmp_path / "ro").iterdir()) == []


def test_a_preview_too_large_for_pixels_still_prints_at_one_to_one(tmp_path, capfd):
    """A 10 m square at 96 dpi would be 1.4 billion pixels: the PNG is made at a lower resolution,
    stored in the file, so that printed at it the square is 10 m (pixels x 25.4 / dpi)."""
    from PIL import Image

    s = 10_000.0
    trimesh.Trimesh([[0, 0, 0], [s, 0, 0], [s, s, 0], [0, s, 0]], [[0, 1, 2], [0, 2, 3]],
                    process=False).export(tmp_path / "square.obj")
    code, out, _ = run(["flatten", "square.obj", "-o", "sq.dxf", "--preview", "sq.png"], tmp_path, capfd)
    assert code == 0 and "lowered to stay under 40 megapixels" in out
    with Image.open(tmp_path / "sq.png") as image:
        w, h = image.size
        dpi = image.info["dpi"][0]
    assert w * h <= patterns.export.preview.MAX_PIXELS
    assert w * 25.4 / dpi == pytest.approx(s + 2 * 10, rel=2e-3)  # the square and the preview's 10 mm margins


def test_notch_spacing_that_would_draw_millions_is_refused(here, capfd):
    refused(["flatten", "cup.step", "-o", "d.dxf", "--notch-spacing", "1e-9"], here, capfd,
            "notch_spacing 1e-09 mm would draw about")


def test_mathtext_in_a_name_is_just_text(here, capfd):
    shutil.copy(here / "dish.obj", here / "a$x^{2$.obj")  # unbalanced: matplotlib's mathtext would raise
    code, out, err = run(["flatten", "a$x^{2$.obj", "-o", "d.dxf", "--heat-map", "h.png"], here, capfd)
    assert code == 0, err
    assert (here / "h.png").stat().st_size > 1000


# --------------------------------------------------------------------------- #
# 4. Hangs and runaway memory
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize(("flag", "value", "words"), [("--notch-spacing", "1e-4", "notches"),
                                                      ("--bend-spacing", "1e-3", "bend lines")])
def test_spacings_that_would_run_for_minutes_are_refused_at_once(here, capfd, flag, value, words):
    """Refused once the part is read and before it is flattened: the spacing is checked against the part's
    size, so the refusal comes with the part's panels counted and no pattern made."""
    refused(["flatten", "cup.step", "-o", "d.dxf", flag, value], here, capfd, words)


def test_an_obj_naming_a_pipe_as_its_materials_does_not_block(here):
    os.mkfifo(here / "fifo.mtl")
    (here / "withmtl.obj").write_text("mtllib fifo.mtl\nusemtl skin\n" + (here / "dish.obj").read_text())
    proc = cmd(["flatten", "withmtl.obj", "-o", "d.dxf"], here, timeout=60)  # blocked forever before
    assert proc.returncode == 0, proc.stderr


@pytest.mark.slow
def test_a_zip_bomb_3mf_is_refused_before_it_is_inflated(tmp_path, capfd):
    with zipfile.ZipFile(tmp_path / "bomb.3mf", "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("3D/3dmodel.model", b" " * (patterns.reading.MAX_FILE_BYTES + 2**20))
    assert (tmp_path / "bomb.3mf").stat().st_size < 2**21  # about 1 MB packed
    refused(["flatten", "bomb.3mf", "-o", "d.dxf"], tmp_path, capfd, "inflate to 1.0 GiB, over the limit")


@pytest.fixture(scope="module")
def slow_folder(tmp_path_factory):
    """The samples, a broken file and a part that takes seconds (a million-face dish: some 14 s on an idle
    machine, eight times the slowest sample's, hopper.step, 1 s)."""
    parts = tmp_path_factory.mktemp("batch") / "parts"
    parts.mkdir()
    for name in ("cup.step", "dish.obj", "cone.obj", "hopper.step"):
        shutil.copy(SAMPLES / name, parts / name)
    (parts / "broken.step").write_bytes(b"garbage")
    v, f = surfaces.paraboloid_dish(n_faces=1_000_000)
    trimesh.Trimesh(v, f, process=False).export(parts / "slow.obj")
    shutil.copy(SAMPLES / "dish.obj", parts / "slow.stl.obj")  # and a name close to it
    shutil.copy(SAMPLES / "cone.obj", parts / "cup.obj")  # a colliding pair: cup.step and cup.obj
    return parts


def _rows(stdout: str) -> dict:
    rows = {}
    for line in stdout.splitlines()[1:]:
        if line.startswith("batch:"):
            break
        name, *_, rest = line.split(None, 6)
        rows[name] = rest
    return rows


@pytest.mark.slow
def test_batch_stops_a_file_at_its_timeout_and_finishes_the_others(slow_folder, tmp_path):
    # 7 s: the slow part takes some 14 s, the others 1 s at most (a machine busy with twice its cores' work
    # takes 4 s over hopper.step: still in time)
    proc = cmd(["batch", slow_folder, "-o", tmp_path / "out", "--jobs", "2", "--timeout", "7"], tmp_path,
               timeout=300)
    assert proc.returncode == 2, proc.stdout + proc.stderr
    rows = _rows(proc.stdout)
    assert rows["slow.obj"].startswith("timeout: still running after 7 s: stopped")
    assert rows["broken.step"].startswith("failed: broken.step: not a readable STEP file")
    written = {p.name for p in (tmp_path / "out").iterdir()}
    for name in ("cup.step", "cup.obj", "dish", "cone", "hopper", "slow.stl"):  # the pair both kept
        assert {f"{name}.dxf", f"{name}.json"} <= written
    assert not any(n.startswith("slow.dxf") or n.startswith(".~") for n in written)
    assert "batch: 8 files: 6 ok, 1 failed, 1 timeout (2 processes); 6 written to" in proc.stdout


def _children(pid: int) -> list:
    out = subprocess.run(["pgrep", "-P", str(pid)], capture_output=True, text=True).stdout.split()
    return [int(p) for p in out]


def _workers(pid: int) -> list:
    """The batch's worker processes (its children running spawn_main, not the resource tracker)."""
    return [child for child in _children(pid) if _alive_worker(child)]


def _alive_worker(pid: int) -> bool:
    try:
        return b"spawn_main" in Path(f"/proc/{pid}/cmdline").read_bytes()
    except OSError:
        return False


def _interruptible():
    """In the child before it runs: Ctrl-C's default action.  A shell runs a background job (``.ci/run &``) with
    SIGINT ignored, every process it starts inherits that, and Python keeps an inherited SIG_IGN: the tests that
    press Ctrl-C give the command the terminal's default, as a user's shell does."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _start_batch(folder, out, *extra):
    return subprocess.Popen([str(EXE), "batch", str(folder), "-o", str(out), "--jobs", "2", *extra],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True,
                            preexec_fn=_interruptible)


def _wait_for_workers(proc, n=2, timeout=60):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        found = _workers(proc.pid)
        if len(found) >= n:
            return found
        time.sleep(0.2)
    raise AssertionError("the batch's workers did not start")


@pytest.mark.slow
@pytest.mark.parametrize(("sig", "code", "word"), [(signal.SIGTERM, 143, "terminated"),
                                                    (signal.SIGINT, 130, "interrupted")])
def test_a_stopped_batch_stops_its_workers_and_still_sums_up(slow_folder, tmp_path, sig, code, word):
    proc = _start_batch(slow_folder, tmp_path / "out")
    workers = _wait_for_workers(proc)
    time.sleep(3)  # the quick parts done, the slow one running
    if sig == signal.SIGINT:
        os.killpg(proc.pid, sig)  # Ctrl-C reaches the whole group
    else:
        proc.send_signal(sig)
    out, err = proc.communicate(timeout=60)
    assert proc.returncode == code, out + err
    assert f"batch: {word}: 8 files:" in err and "not run" in out
    assert "Traceback" not in err
    time.sleep(0.5)
    assert not [w for w in workers if _alive_worker(w)]
    names = [p.name for p in (tmp_path / "out").iterdir()] if (tmp_path / "out").exists() else []
    assert not [n for n in names if n.startswith(".~")]  # nothing half-written


@pytest.fixture(scope="module")
def long_folder(tmp_path_factory):
    """Three quick parts and one that takes some ten seconds (a million-face dish)."""
    parts = tmp_path_factory.mktemp("long") / "parts"
    parts.mkdir()
    for name in ("cup.step", "dish.obj", "cone.obj"):
        shutil.copy(SAMPLES / name, parts / name)
    v, f = surfaces.paraboloid_dish(n_faces=1_000_000)
    trimesh.Trimesh(v, f, process=False).export(parts / "slow.obj")
    return parts


def _rss_mb(pid: int) -> float:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    return 0.0


def _busy_worker(pid: int, timeout: float = 120.0) -> int:
    """The worker holding the million-face part (over 800 MB resident: a worker starting up, or on a small
    part, holds a few hundred), waited for."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        for w in _workers(pid):
            with contextlib.suppress(OSError):
                if _rss_mb(w) > 800:
                    return w
        time.sleep(0.1)
    raise AssertionError("no worker took the large part")


@pytest.mark.slow
@pytest.mark.parametrize(("kills", "status"), [(1, "ok"), (2, "lost")])
def test_a_killed_worker_loses_nothing(long_folder, tmp_path, kills, status):
    """Once the quick parts are written, the worker still computing (the slow part's) is killed, as the
    OOM killer would: the part runs again on a new worker and is written; killed again, it is one row,
    lost, its worker's death named, and every other part is written."""
    out = tmp_path / "out"
    proc = _start_batch(long_folder, out)
    quick = [out / f"{n}.dxf" for n in ("cup", "dish", "cone")]
    end = time.monotonic() + 120
    while not all(p.exists() for p in quick) and time.monotonic() < end:
        time.sleep(0.2)
    for _ in range(kills):
        victim = _busy_worker(proc.pid)
        os.kill(victim, signal.SIGKILL)
        while victim in _workers(proc.pid):
            time.sleep(0.05)  # gone (or a zombie: no command line)
    stdout, stderr = proc.communicate(timeout=300)
    rows = _rows(stdout)
    assert rows["slow.obj"].startswith(status), stdout + stderr
    if status == "lost":
        assert "its worker died twice (SIGKILL: out of memory or killed)" in rows["slow.obj"]
    assert all(p.exists() for p in quick)
    assert (out / "slow.dxf").exists() == (status == "ok")
    assert proc.returncode == (0 if status == "ok" else 2)


@pytest.mark.slow
def test_a_part_over_the_memory_budget_fails_alone(long_folder, tmp_path, capfd):
    code, out, err = run(["batch", long_folder, "-o", "out", "--jobs", "2", "--memory", "1024"], tmp_path, capfd)
    rows = _rows(out)
    assert rows["slow.obj"] == "failed: out of memory (over the worker's memory budget)", out
    assert all(rows[n] == "ok" for n in ("cup.step", "dish.obj", "cone.obj")), out
    assert code == 2


def test_a_budget_too_small_to_start_a_worker_is_refused(tmp_path, capfd):
    refused(["batch", tmp_path, "-o", "out", "--memory", "100"], tmp_path, capfd,
            "memory must be a number between 1024 and 1e+09, got 100.0")


# --------------------------------------------------------------------------- #
# 5. "ok" that is not
# --------------------------------------------------------------------------- #


def test_a_closed_sphere_is_refused_not_flattened_through_one_cut(tmp_path, capfd):
    trimesh.creation.icosphere(subdivisions=3, radius=100.0).export(tmp_path / "sphere.stl")
    refused(["flatten", "sphere.stl", "-o", "d.dxf"], tmp_path, capfd, "a closed surface with no crease")
    import build123d as bd

    bd.export_step(bd.Sphere(100), tmp_path / "sphere.step")
    refused(["flatten", "sphere.step", "-o", "d.dxf"], tmp_path, capfd, "face 0 closes on itself")


def test_a_thin_cone_is_refused_with_the_reason_not_made_a_sliver(tmp_path, capfd):
    import build123d as bd

    bd.export_step(bd.Cone(0.1, 0, 1000), tmp_path / "needle.step")  # 10 million triangles at the chord tolerance
    refused(["flatten", "needle.step", "-o", "d.dxf"], tmp_path, capfd, "triangles, over the limit of 4e+06")


@pytest.mark.parametrize("method", ["relaxed", "isometric", "conformal"])
def test_a_grossly_distorted_pattern_is_not_ok_on_any_method(tmp_path, capfd, method):
    """A deep dome in one piece (a hemisphere's worth of curvature) cannot lie flat: whatever the
    method, the run says so and exits 1 (the files are still written, to look at)."""
    v, f = surfaces.paraboloid_dish(diameter=400, sag=300, n_faces=3000)
    trimesh.Trimesh(v, f, process=False).export(tmp_path / "dome.obj")
    code, out, _ = run(["flatten", "dome.obj", "-o", "d.dxf", "--report", "d.json", "--method", method],
                       tmp_path, capfd)
    report = json.loads((tmp_path / "d.json").read_text())
    panel = report["panels"][0]
    change = panel["area_flat"] / panel["area_3d"] - 1
    codes = {f["code"] for f in report["findings"]}
    assert code == 1 and report["ok"] is False, out
    assert codes & {"area-not-kept", "grossly-distorted"}
    assert ("area-not-kept" in codes) == (abs(change) > 0.05)  # the finding agrees with the numbers


def test_grain_of_huge_numbers_is_a_direction(here):
    big = patterns.flatten(patterns.load(here / "dish.obj"), grain=(1e308, 1e308, 0))
    unit = patterns.flatten(patterns.load(here / "dish.obj"), grain=(1, 1, 0))
    np.testing.assert_allclose(big.panels[0].uv, unit.panels[0].uv, atol=1e-9)


def test_an_absurd_seam_allowance_is_refused(here, capfd):
    refused(["flatten", "dish.obj", "-o", "d.dxf", "--seam-allowance", "1e300"], here, capfd,
            "between 0 and 1000, got 1e+300")


# --------------------------------------------------------------------------- #
# 6. Names are data
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize("suffix", [".obj", ".step"])
def test_a_file_name_that_is_not_utf8(here, capfd, suffix):
    name = b"caf\xe9" + suffix.encode()
    src = here / ("dish.obj" if suffix == ".obj" else "cup.step")
    shutil.copy(src, os.path.join(os.fsencode(here), name))
    code, out, err = run(["flatten", name, "-o", "d.dxf", "--report", "d.json"], here, capfd)
    assert code == 0, err
    assert "caf\\xe9" in out  # shown as an escape, never an encoding error
    assert json.loads((here / "d.json").read_text())["pattern"] == "caf\\xe9" + suffix


def test_control_characters_in_a_name_reach_no_terminal_and_no_file_raw(here, capfd):
    name = "e\x1b[31mred\x07.obj"
    shutil.copy(here / "dish.obj", here / name)
    code, out, err = run(["flatten", name, "-o", "d.dxf", "--heat-map", "h.svg", "--report", "r.json"], here, capfd)
    assert code == 0, err
    assert "\x1b" not in out + err and "\x07" not in out + err
    assert "e\\x1b[31mred\\x07.obj" in out
    xml.dom.minidom.parse(str(here / "h.svg"))  # well-formed XML
    assert "\x1b" not in (here / "d.dxf").read_text(errors="replace")
    assert json.loads((here / "r.json").read_text())["pattern"] == "e\\x1b[31mred\\x07.obj"


def test_the_longest_legal_output_name(here, capfd):
    name = "n" * 251 + ".dxf"  # 255 bytes: the file system's limit, the temporary's own name is short
    code, _, err = run(["flatten", "dish.obj", "-o", name], here, capfd)
    assert code == 0, err
    assert (here / name).stat().st_size > 0
    refused(["flatten", "dish.obj", "-o", "n" * 252 + ".dxf"], here, capfd, "the file system allows 255")


# --------------------------------------------------------------------------- #
# 7. Messages a person can act on
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize(("flag", "value", "said"), [
    ("--profile", "foo", "profile must be one of machine, astm, svg, json, bends, got 'foo'"),  # the registered profiles
    ("--method", "fast", "(choose from 'relaxed', 'isometric', 'conformal')")])
def test_a_bad_choice_is_one_line_with_the_choices(here, capfd, flag, value, said):
    refused(["flatten", "dish.obj", "-o", "d.dxf", flag, value], here, capfd, said)


@pytest.mark.parametrize("where", [0, 1, -1])
def test_debug_anywhere_on_the_line(here, capfd, where):
    argv = ["flatten", "missing.obj", "-o", "d.dxf"]
    argv.insert(where if where >= 0 else len(argv), "--debug")
    with pytest.raises(patterns.InputError, match="missing.obj: no such file"):
        cli.main(argv)


def test_opencascade_says_nothing_on_stdout(tmp_path, capfd):
    (tmp_path / "bad.step").write_text("ISO-10303-21;\nthis is not STEP\n")
    code, out, err = run(["info", "bad.step"], tmp_path, capfd)
    assert code == 2 and out == ""
    (line,) = err.strip().splitlines()
    assert line.startswith("patterns: error: bad.step: not a readable STEP file") and "\x1b" not in line


def test_an_unreadable_file_says_permission_denied_not_corrupt(here):
    os.chmod(here / "cup.step", 0)
    proc = cmd(["info", "cup.step"], here, prefix=no_dac_override())
    assert proc.returncode == 2
    assert proc.stderr.strip() == "patterns: error: cup.step: cannot read the CAD file (permission denied)"


def test_a_folder_is_not_a_missing_file(here, capfd):
    (here / "parts.step").mkdir()
    refused(["flatten", "parts.step", "-o", "d.dxf"], here, capfd, "parts.step: is a folder")


def test_max_edge_out_of_range_says_so(here, capfd):
    refused(["flatten", "cup.step", "-o", "d.dxf", "--max-edge", "1e300"], here, capfd,
            "--max-edge must be a positive number <= 1e+07, got 1e+300")


# --------------------------------------------------------------------------- #
# 8. Parity and silence
# --------------------------------------------------------------------------- #


@pytest.mark.slow
def test_batch_takes_units_report_preview_and_heat_map(tmp_path, capfd):
    parts = tmp_path / "parts"
    parts.mkdir()
    shutil.copy(SAMPLES / "dish.obj", parts / "dish.obj")
    code, out, err = run(["batch", "parts", "-o", "out", "--input-units", "in", "--units", "in", "--preview",
                          "--heat-map"], tmp_path, capfd)
    assert code == 0, out + err
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["dish.dxf", "dish.json", "dish_heatmap.png",
                                                                    "dish_preview.png"]
    import ezdxf

    assert ezdxf.readfile(tmp_path / "out" / "dish.dxf").header["$INSUNITS"] == 1  # inches, as asked
    report = json.loads((tmp_path / "out" / "dish.json").read_text())
    assert report["loading"]["units"] == "in"
    code, out, err = run(["batch", "parts", "-o", "out2", "--no-report"], tmp_path, capfd)
    assert sorted(p.name for p in (tmp_path / "out2").iterdir()) == ["dish.dxf"]


def test_a_flat_obj_is_written_in_the_unit_asked_and_says_so(here, capfd):
    code, out, _ = run(["flatten", "dish.obj", "-o", "mm.obj"], here, capfd)
    code_in, out_in, _ = run(["flatten", "dish.obj", "-o", "in.obj", "--input-units", "in", "--units", "in"], here,
                             capfd)
    assert code == code_in == 0 and "(flat mesh, z = 0, in in)" in out_in
    mm = trimesh.load(here / "mm.obj", process=False).vertices
    inch = trimesh.load(here / "in.obj", process=False).vertices
    # the file's numbers read as inches (x 25.4 into mm), flattened, written back in inches: the same numbers
    # as the run in mm (an OBJ left in mm would hold them 25.4 times larger)
    np.testing.assert_allclose(inch, mm, rtol=1e-6, atol=1e-6)


def test_welding_is_said_in_info_and_in_the_report(tmp_path, capfd):
    v, f = surfaces.paraboloid_dish(n_faces=216)
    trimesh.Trimesh(v, f, process=False).export(tmp_path / "dish.stl")
    expected = 3 * len(f) - len(v)
    code, out, _ = run(["info", "dish.stl"], tmp_path, capfd)
    assert code == 0 and f"loading: {expected} vertices welded" in out
    run(["check", "dish.stl", "--report", "r.json"], tmp_path, capfd)
    assert json.loads((tmp_path / "r.json").read_text())["loading"]["welded"] == expected


# --------------------------------------------------------------------------- #
# Property: whatever the options and the mesh, exit 0, 1 or 2, never a traceback; nothing written
# on 2; the input never changed
# --------------------------------------------------------------------------- #

from hypothesis import HealthCheck, event, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

_NUMBER = st.one_of(st.floats(min_value=0.01, max_value=50), st.floats(min_value=0.01, max_value=50),
                    st.floats(allow_nan=True, allow_infinity=True, width=64),
                    st.floats(min_value=-1e3, max_value=1e3), st.integers(-5, 1000),
                    st.sampled_from(["", "abc", "1e309", "-0", "0x10", "1,2", "3,4,5", "nan", "1e-9", "1e300"]))
_FLAGS = {
    "--max-edge": _NUMBER, "--chord-tolerance": _NUMBER, "--angular-tolerance": _NUMBER,
    "--seam-allowance": _NUMBER, "--max-strain": _NUMBER, "--max-seam-mismatch": _NUMBER,
    "--notch-spacing": _NUMBER, "--bend-spacing": _NUMBER, "--text-height": _NUMBER, "--gap": _NUMBER,
    "--arc-tolerance": _NUMBER, "--dart-strain": _NUMBER, "--max-darts": st.integers(-2, 4),
    "--max-gores": st.integers(-1, 4),
    "--max-iterations": st.integers(-2, 30), "--min-stretch": _NUMBER, "--crease-angle": _NUMBER,
    "--area-tolerance": _NUMBER, "--max-distortion": _NUMBER, "--roll-width": _NUMBER,
    "--thickness": _NUMBER, "--k-factor": _NUMBER,
    "--method": st.sampled_from(["relaxed", "isometric", "conformal", "fast"]),
    "--profile": st.sampled_from(["machine", "astm", "pdf"]),
    "--units": st.sampled_from(["mm", "cm", "m", "in", "ft"]),
    "--energy": st.sampled_from(["auto", "arap", "hybrid", "symmetric-dirichlet", "x"]),
    "--dxf-version": st.sampled_from(["R12", "R2000", "R2018", "R14"]),
    "--notch-style": st.sampled_from(["slit", "v", "w"]),
    "--seams": st.sampled_from(["true", "total", "free", "no"]),
    "--weld-vertices": st.sampled_from(["yes", "no", "maybe"]),
    "--grain": st.tuples(_NUMBER, _NUMBER, _NUMBER).map(lambda t: ",".join(map(str, t))),
    "--arcs": st.none(), "--no-exact": st.none(), "--strain-layer": st.none(), "--gores": st.none(),
}


@st.composite
def _meshes(draw):
    """A small mesh as OBJ text: a bumpy grid, or something broken (NaN, huge, tiny, degenerate,
    non-manifold, closed, out-of-range indices, empty)."""
    kind = draw(st.sampled_from(["grid", "grid", "grid", "nan", "huge", "tiny", "degenerate", "nonmanifold",
                                 "closed", "badindex", "empty", "tangle"]))
    n = draw(st.integers(2, 6))
    st_, f = surfaces.grid_mesh(n, n)
    v = np.column_stack([st_ * 100.0, np.zeros(len(st_))])
    v[:, 2] = draw(st.floats(0, 80)) * (st_[:, 0] - 0.5) ** 2 + draw(st.floats(-40, 40)) * (st_[:, 1] - 0.5) ** 2
    if kind == "nan":
        v[0, 0] = np.nan
    elif kind == "huge":
        v = v * draw(st.sampled_from([1e6, 1e9, 1e200]))
    elif kind == "tiny":
        v = v * draw(st.sampled_from([1e-6, 1e-12, 1e-300]))
    elif kind == "degenerate":
        v[f[0, 1]] = v[f[0, 0]]
    elif kind == "nonmanifold":
        v = np.vstack([v, [50, 50, 50]])
        a, b = f[0, 0], f[0, 1]
        f = np.vstack([f, [a, b, len(v) - 1]])
    elif kind == "closed":
        v = np.array([[0, 0, 0], [100, 0, 0], [0, 100, 0], [0, 0, 100]], dtype=float)
        f = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    elif kind == "badindex":
        f = f.copy()
        f[-1, -1] = len(v) + draw(st.integers(0, 5))
    elif kind == "empty":
        f = f[:0]
    elif kind == "tangle":
        v = v[draw(st.permutations(list(range(len(v)))))]
    lines = [f"v {x!r} {y!r} {z!r}" for x, y, z in v.tolist()] + [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in f]
    return "\n".join(lines) + "\n"


@st.composite
def _argvs(draw):
    chosen = draw(st.lists(st.sampled_from(sorted(_FLAGS)), max_size=3, unique=True))
    argv = []
    for flag in chosen:
        value = draw(_FLAGS[flag])
        argv += [flag] if value is None else [flag, str(value)]
    out = draw(st.sampled_from(["out.dxf", "out.dxf", "out.obj", "out.txt"]))
    extra = draw(st.sampled_from([[], [], ["--report", "r.json"], ["--heat-map", "h.png"], ["--report", "in.obj"],
                                  ["--preview", "p.svg"]]))
    return ["flatten", "in.obj", "-o", out, *extra, *argv]


@pytest.mark.slow
@settings(max_examples=400, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(mesh=_meshes(), argv=_argvs())
def test_no_option_and_no_small_mesh_breaks_a_promise(tmp_path_factory, mesh, argv):
    folder = tmp_path_factory.mktemp("prop")
    (folder / "in.obj").write_text(mesh)
    before = snapshot(folder)
    old = os.getcwd()
    os.chdir(folder)
    try:
        code = cli.main(argv)  # a traceback would raise here and fail the test
    finally:
        os.chdir(old)
    assert code in (0, 1, 2), (code, argv)
    event(f"exit {code}")
    after = snapshot(folder)
    assert after[b"in.obj"] == before[b"in.obj"]  # the input untouched
    assert not [k for k in after if k.startswith(b".~")]  # no temporary left
    if code == 2:
        assert after == before, argv  # refused: nothing written
    else:
        assert (folder / argv[3]).is_file(), argv


@pytest.mark.slow
def test_batch_progress_off_a_terminal_is_a_line_per_file_and_quiet_is_silent(tmp_path, capfd):
    parts = tmp_path / "parts"
    parts.mkdir()
    for name in ("dish.obj", "cone.obj"):
        shutil.copy(SAMPLES / name, parts / name)
    code, out, err = run(["batch", "parts", "-o", "out", "--jobs", "1"], tmp_path, capfd)
    assert code == 0
    lines = [line.split(" (")[0] for line in err.splitlines() if line.startswith("[")]
    assert [line[:6] for line in lines] == ["[1/2] ", "[2/2] "]  # in the order they end
    assert sorted(line[6:] for line in lines) == ["cone.obj: ok", "dish.obj: ok"]
    code, out, err = run(["batch", "parts", "-o", "out2", "--jobs", "1", "--quiet"], tmp_path, capfd)
    assert code == 0 and err == "" and "batch: 2 files: 2 ok" in out


@pytest.mark.slow
def test_sigterm_while_the_outputs_are_written_leaves_nothing(tmp_path):
    """SIGTERM as soon as the first temporary output appears (the work done, the writing begun):
    exit 143, one line, no output, no temporary."""
    v, f = surfaces.paraboloid_dish(n_faces=100_000)
    trimesh.Trimesh(v, f, process=False).export(tmp_path / "dish.obj")
    before = snapshot(tmp_path)
    proc = subprocess.Popen([str(EXE), "flatten", "dish.obj", "-o", "d.dxf", "--report", "d.json", "--heat-map",
                             "h.png", "--preview", "p.png", "--strain-layer"], cwd=tmp_path,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    end = time.monotonic() + 120
    while time.monotonic() < end and not any(p.name.startswith(".~patterns-") for p in tmp_path.iterdir()):
        time.sleep(0.01)
    assert any(p.name.startswith(".~patterns-") for p in tmp_path.iterdir()), "no output was being written"
    proc.send_signal(signal.SIGTERM)
    out, err = proc.communicate(timeout=60)
    assert proc.returncode == 143 and err.strip() == "patterns: terminated; nothing written", err
    assert snapshot(tmp_path) == before


@pytest.mark.parametrize("dpi", [1e9, float("nan"), float("inf"), 0])
def test_picture_resolutions_are_bounded(here, dpi):
    """The API's dpi for a heat map (10-1200) and a preview (1-2400): refused, nothing written."""
    pattern = patterns.flatten(patterns.load(here / "dish.obj"))
    before = snapshot(here)
    with pytest.raises(patterns.InputError, match="dpi must be a number between"):
        patterns.heat_map(pattern, here / "h.png", dpi=dpi)
    patterns.write(pattern, here / "d.dxf")
    with pytest.raises(patterns.InputError, match="dpi must be a number between"):
        patterns.preview_dxf(here / "d.dxf", here / "p.png", dpi=dpi)
    assert set(snapshot(here)) == set(before) | {b"d.dxf"}


# --------------------------------------------------------------------------- #
# Issue 33: the bend table is an input, and a bounded, sane one
# --------------------------------------------------------------------------- #

TABLE = "thickness,radius,angle,deduction\n2,3,90,3.5\n"


@pytest.fixture
def bent(tmp_path):
    """A folder holding the bracket (2 mm, R3, one 90 degree bend) and a good bend table."""
    shutil.copy(SAMPLES / "bracket.step", tmp_path / "part.step")
    (tmp_path / "table.csv").write_text(TABLE)
    return tmp_path


@pytest.mark.parametrize(("argv", "words"), [
    (["-o", "table.dxf", "--bend-table", "table.dxf"], "table.dxf: is an input of this run"),
    (["-o", "o.dxf", "--report", "table.json", "--bend-table", "table.json"], "table.json: is an input of this run"),
    (["-o", "o.dxf", "--preview", "table.png", "--bend-table", "table.png"], "table.png: is an input of this run"),
])
def test_no_output_replaces_the_bend_table(bent, capfd, argv, words):
    for name in ("table.dxf", "table.json", "table.png"):
        (bent / name).write_text(TABLE)
    refused(["unfold", "part.step", *argv], bent, capfd, words)


def test_a_deduction_that_puts_the_neutral_layer_outside_the_sheet_is_refused(bent, capfd):
    """-1e6 mm would make a kilometre blank; 2 (r + t) tan 45 - (pi / 2)(r + K t) is 2.146-5.288 mm for K 0-1."""
    (bent / "table.csv").write_text("thickness,radius,angle,deduction\n2,3,90,-1e6\n")
    line = refused(["unfold", "part.step", "-o", "o.dxf", "--bend-table", "table.csv"], bent, capfd,
                   "table.csv, line 2: deduction -1e+06 mm")
    assert "K-factor 0 to 1 gives 2.146 to 5.288 mm" in line
    for ded, ok in [(2 * 5 - np.pi / 2 * (3 + 1.5 * 2) - 0.06, False), (2 * 5 - np.pi / 2 * (3 + 1.5 * 2) + 0.04, True),
                    (2 * 5 - np.pi / 2 * (3 - 0.5 * 2) + 0.06, False), (2 * 5 - np.pi / 2 * (3 - 0.5 * 2) - 0.04, True)]:
        (bent / "table.csv").write_text(f"thickness,radius,angle,deduction\n2,3,90,{ded!r}\n")
        if ok:
            blank = patterns.unfold(bent / "part.step", bend_table=bent / "table.csv")
            assert blank.bends[0].allowance == pytest.approx(2 * 5 - ded, abs=1e-9)
        else:
            with pytest.raises(patterns.InputError, match="neutral layer outside the sheet"):
                patterns.read_bend_table(bent / "table.csv")


@pytest.mark.parametrize(("text", "words"), [
    ("thickness,radius,angle,deduction\n2,3,90," + "1" * 200_000 + "\n", "table.csv, line 2: not a CSV bend table"),
    ("thickness,radius,angle,deduction\n2,3,180,3\n", "line 2: the bend angle must be between 0 and 180 degrees"),
    ("thickness,radius,angle,deduction\n2,3,90,nan\n", "line 2: every value must be a finite number"),
    ("thickness,radius,angle,deduction\n", "the bend table has no rows"),
    ("thickness,radius,angle,deduction\n" + "2,3,90,3.5\n" * 100_000, "table.csv: 1100033 bytes; a bend table is at most 1 MB"),
])
def test_an_absurd_bend_table_is_one_line(bent, capfd, text, words):
    (bent / "table.csv").write_text(text)
    refused(["unfold", "part.step", "-o", "o.dxf", "--bend-table", "table.csv"], bent, capfd, words)


@pytest.mark.parametrize(("make", "words"), [
    (lambda p: os.mkfifo(p), "t.csv: is not a regular file (a device, pipe or socket)"),
    (lambda p: p.mkdir(), "t.csv: is a folder, not a bend table"),
    (lambda p: os.symlink("/dev/zero", p), "t.csv: is not a regular file"),
])
def test_a_bend_table_that_is_not_a_file_is_named_as_such(bent, capfd, make, words):
    make(bent / "t.csv")
    refused(["unfold", "part.step", "-o", "o.dxf", "--bend-table", "t.csv"], bent, capfd, words)


def test_unfold_of_a_mesh_says_a_mesh_has_no_bends(bent, capfd):
    shutil.copy(SAMPLES / "dish.obj", bent / "dish.obj")
    line = refused(["unfold", "dish.obj", "-o", "o.dxf"], bent, capfd,
                   "dish.obj: is a mesh; unfolding takes a CAD file (.step, .stp, .brep, .brp, .iges, .igs)")
    assert ".obj" not in line.split("takes", 1)[1]
    with pytest.raises(patterns.InputError, match="dish.obj: is a mesh; unfolding takes a CAD file"):
        patterns.unfold(bent / "dish.obj")


def helix_strip(n: int = 300, turns: float = 3.0) -> tuple:
    """A strip one triangle wide wound ``turns`` times on a helix (radii 50 and 70 mm, pitch 30 mm): every
    vertex on its boundary, no interior vertex.  ``(vertices (2n, 3), faces (2n - 2, 3))``."""
    t = np.linspace(0, turns * 2 * np.pi, n)
    rows = [np.column_stack([r * np.cos(t), r * np.sin(t), 30 * t / (2 * np.pi)]) for r in (50.0, 70.0)]
    i = np.arange(n - 1)
    faces = np.concatenate([np.column_stack([i, i + 1, n + i]), np.column_stack([i + 1, n + i + 1, n + i])])
    return np.concatenate(rows), faces


def _singular_values(v3, f, uv):
    """Per triangle, the 3D->2D map's smallest and largest singular values, from the positions alone."""
    e3 = np.stack([v3[f[:, 1]] - v3[f[:, 0]], v3[f[:, 2]] - v3[f[:, 0]]], axis=1)
    x = e3[:, 0] / np.linalg.norm(e3[:, 0], axis=1)[:, None]
    y = e3[:, 1] - (e3[:, 1] * x).sum(1)[:, None] * x
    y /= np.linalg.norm(y, axis=1)[:, None]
    local = np.stack([np.stack([(e3[:, k] * x).sum(1), (e3[:, k] * y).sum(1)], 1) for k in (0, 1)], 2)  # (m, 2, 2)
    flat = np.stack([uv[f[:, 1]] - uv[f[:, 0]], uv[f[:, 2]] - uv[f[:, 0]]], axis=2)
    s = np.linalg.svd(flat @ np.linalg.inv(local), compute_uv=False)
    return s[:, -1], s[:, 0]


@pytest.mark.parametrize("argv", [[], ["--min-stretch", "0.3"]])
def test_a_strip_with_every_vertex_on_its_boundary_flattens(tmp_path, capfd, argv):
    """Issue 33 (a regression): no interior vertex left the Tutte start an empty system.  The pattern is one
    closed outline read back from the DXF, one-to-one, within 5 % of the mesh's area (the usable-pattern check)."""
    import ezdxf
    import shapely

    v, f = helix_strip()
    trimesh.Trimesh(v, f, process=False).export(tmp_path / "helix.obj")
    code, out, err = run(["flatten", "helix.obj", "-o", "helix.dxf", *argv], tmp_path, capfd)
    assert code == 0 and "helix.obj: ok" in out, err
    cut = [e for e in ezdxf.readfile(tmp_path / "helix.dxf").modelspace().query("LWPOLYLINE") if e.closed]
    assert len(cut) == 1
    polygon = shapely.Polygon([p[:2] for p in cut[0].get_points()])
    area3d = trimesh.Trimesh(v, f, process=False).area
    assert polygon.is_valid and abs(polygon.area / area3d - 1) < 0.05
    if argv:
        pattern = patterns.flatten(patterns.load(tmp_path / "helix.obj"), min_stretch=0.3)
        panel = pattern.panels[0]
        low, _ = _singular_values(panel.vertices, panel.faces, panel.uv)
        assert low.min() >= 0.3 - 1e-6


# --------------------------------------------------------------------------- #
# Issue 33: the nest -- signals stop it, its geometry is checked first, sparrow's panics are one line
# --------------------------------------------------------------------------- #


def _child_commands(pid: int) -> list:
    """The command lines of the processes whose parent is ``pid`` (from /proc)."""
    out = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            with contextlib.suppress(OSError):
                if int((entry / "stat").read_text().rsplit(")", 1)[1].split()[1]) == pid:
                    out.append((int(entry.name), (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode()))
    return out


@pytest.mark.slow
@pytest.mark.parametrize(("sig", "code", "word"), [(signal.SIGINT, 130, "interrupted"),
                                                   (signal.SIGTERM, 143, "terminated")])
def test_a_signal_stops_the_nest_and_writes_nothing(here, sig, code, word):
    """Issue 33: sparrow searching (its process running, 120 s to go), Ctrl-C or SIGTERM: exit 130 or 143 at
    once, one line, nothing written or changed (out.dxf was there before), sparrow's process gone."""
    (here / "out.dxf").write_text("the user's file\n")
    before = snapshot(here)
    proc = subprocess.Popen([str(EXE), "flatten", "cup.step", "-o", "out.dxf", "--report", "out.json",
                             "--roll-width", "1500", "--copies", "5", "--nest-time", "120", "--no-nest-cache"],
                            cwd=here, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=_interruptible)
    end = time.monotonic() + 120
    while time.monotonic() < end and not any("sparrow_child" in c for _, c in _child_commands(proc.pid)):
        time.sleep(0.05)
    sparrow = [p for p, c in _child_commands(proc.pid) if "sparrow_child" in c]
    assert sparrow, "sparrow was not searching"
    time.sleep(1.0)
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=30)
    assert proc.returncode == code and err.strip() == f"patterns: {word}; nothing written", err
    assert snapshot(here) == before
    assert not Path(f"/proc/{sparrow[0]}").exists() or "Z" in Path(f"/proc/{sparrow[0]}/stat").read_text().split()[2]


@pytest.mark.parametrize(("argv", "words"), [
    (["--roll-width", "1500", "--nest-gap", "1e6"], ("--nest-gap 1e+06 mm (and --margin 0 mm each side) is as wide as "
                                                     "the 1500 mm roll")),
    (["--sheet", "100x80", "--nest-gap", "50", "--margin", "15"], "is as wide as the 100 x 80 mm sheet"),
    (["--roll-width", "1500", "--copies", "10000"], "copies must be an integer between 1 and 2000, got 10000"),
    (["--roll-width", "1500", "--copies", "1000"], ("cup.step: 4000 pieces to nest, over the limit of 2000 in one "
                                                    "nest")),
    (["--roll-width", "1500", "--copies", "600", "--mirror"], "4800 pieces to nest"),
])
def test_a_nest_that_cannot_be_is_refused_before_flattening(here, capfd, argv, words):
    """A gap as wide as the stock (sparrow panicked, 195 lines), or more pieces than a nest takes (10,000 copies
    ran past 600 s): one line, before the part is flattened."""
    before = snapshot(here)
    code, out, err = run(["flatten", "cup.step", "-o", "o.dxf", *argv], here, capfd)
    assert code == 2 and err.strip().splitlines() == [f"patterns: error: {err.split('error: ', 1)[1].strip()}"]
    assert words in err and "flattened" not in out and snapshot(here) == before


def test_a_panic_in_sparrow_is_one_line_and_its_backtrace_stays_away(capfd, monkeypatch):
    """A panic (an item wider than its strip: layout() never sends one), with RUST_BACKTRACE=1 in the
    user's environment: a LayoutError in one line, nothing on this process's stderr."""
    from patterns.nesting import _sparrow

    monkeypatch.setenv("RUST_BACKTRACE", "1")
    task = {"items": [[[0.0, 0.0], [50.0, 0.0], [50.0, 200.0], [0.0, 200.0]]], "strip": 100.0,
            "orientations": [0.0], "gap": 0.0, "time": 1, "seed": 0}
    with pytest.raises(patterns.LayoutError) as caught:
        _sparrow(task, "wide")
    assert "\n" not in str(caught.value) and str(caught.value).startswith("wide: sparrow could not nest the pieces (")
    out, err = capfd.readouterr()
    assert out == "" and err == ""


def test_a_link_another_user_planted_in_a_shared_folder_is_not_written_through(tmp_path, capfd):
    """Issue 33: ``shared/out.dxf``, in a sticky world-writable folder, a link by another user to a file only
    root may write: refused as the kernel's protected_symlinks would (the links are resolved here, not by it);
    the file is untouched.  One's own link there is written through, as any link is."""
    if os.geteuid() != 0:
        pytest.skip("making a link owned by another user takes root")
    shared = tmp_path / "shared"
    shared.mkdir()
    shared.chmod(0o1777)
    secret = tmp_path / "secret.conf"
    secret.write_text("root's\n")
    secret.chmod(0o600)
    os.symlink(secret, shared / "out.dxf")
    os.lchown(shared / "out.dxf", 65534, 65534)
    shutil.copy(SAMPLES / "dish.obj", tmp_path / "dish.obj")
    before = snapshot(tmp_path)
    code, _, err = run(["flatten", "dish.obj", "-o", "shared/out.dxf"], tmp_path, capfd)
    assert code == 2 and "shared/out.dxf: is a link another user (uid 65534) made in a shared folder" in err, err
    assert snapshot(tmp_path) == before and secret.read_text() == "root's\n"
    os.symlink(tmp_path / "mine.dxf", shared / "mine.dxf")  # root's own link: written through
    code, _, _ = run(["flatten", "dish.obj", "-o", "shared/mine.dxf"], tmp_path, capfd)
    assert code == 0 and (tmp_path / "mine.dxf").read_text().startswith("  0\nSECTION")


@pytest.mark.slow
def test_an_unreadable_home_is_not_a_traceback(here):
    """Issue 33: ``sudo -u user`` without ``-H`` keeps a HOME the user cannot read; ezdxf's import read its
    settings there and failed with a traceback.  Now the run works, says nothing more, and leaves nothing."""
    home = here / "home"
    home.mkdir()
    home.chmod(0)
    try:
        proc = cmd(["flatten", "dish.obj", "-o", "d.dxf", "--preview", "d.png", "--roll-width", "1000"], here,
                   prefix=no_dac_override(), env={**os.environ, "HOME": str(home), "XDG_CONFIG_HOME": "",
                                                  "XDG_CACHE_HOME": "", "MPLCONFIGDIR": ""})
    finally:
        home.chmod(0o755)
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr
    assert (here / "d.dxf").exists() and (here / "d.png").exists()
