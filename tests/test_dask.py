"""Batch on a real Dask cluster (issue 23): work travels as bytes, so relative paths work and the workers
need no view of the client's disk; every file ends as a row; bad addresses and workers without
patterns are refused in one line before any work.

The cluster is real: a ``dask scheduler`` and ``dask worker`` processes on loopback.  The workers run
in a private mount namespace where the client's folder is an empty file system (``unshare --mount``),
and in another working folder: a worker that opened a path the client typed would find nothing."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import ezdxf
import numpy as np
import pytest
import shapely
import trimesh

import patterns
from patterns import cli, surfaces

from .conftest import SAMPLES

distributed = pytest.importorskip("distributed", reason="Dask is the optional extra patterns[dask]")
pytestmark = pytest.mark.slow  # a real Dask scheduler and workers: run by .ci/run (pytest -m slow), not the quick suite
PYTHON = sys.executable
NOPATTERNS = """
import sys
class _Block:
    def find_spec(self, name, path=None, target=None):
        if name == "patterns" or name.startswith("patterns."):
            raise ModuleNotFoundError(f"No module named {name!r}")
sys.meta_path.insert(0, _Block())
from dask.cli import run_cli

sys.argv = ["dask", *sys.argv[1:]]
run_cli()
"""


class Cluster:
    """A scheduler and workers as processes of their own; stopped (their whole groups) at the end."""

    def __init__(self, root: Path):
        self.root = root
        self.procs = []
        self.file = root / "scheduler.json"

    def _start(self, argv, **kwargs):
        log = open(self.root / f"log{len(self.procs)}.txt", "w")
        proc = subprocess.Popen(argv, stdout=log, stderr=subprocess.STDOUT, start_new_session=True, **kwargs)
        self.procs.append(proc)
        return proc

    def scheduler(self, *, without_patterns=False) -> str:
        head = [PYTHON, "-c", NOPATTERNS] if without_patterns else [PYTHON, "-m", "dask"]
        self._start([*head, "scheduler", "--host", "127.0.0.1", "--port", "0", "--dashboard-address",
                     "127.0.0.1:0", "--scheduler-file", str(self.file)])
        end = time.monotonic() + 60
        while time.monotonic() < end:
            if self.file.exists():
                try:
                    return json.loads(self.file.read_text())["address"]
                except (ValueError, KeyError):
                    pass
            time.sleep(0.2)
        raise AssertionError("the scheduler did not start")

    def worker(self, *, hide: Path | None = None, without_patterns=False, memory=None, n=1):
        head = [PYTHON, "-c", NOPATTERNS] if without_patterns else [PYTHON, "-m", "dask"]
        argv = [*head, "worker", "--scheduler-file", str(self.file), "--nthreads", "1", "--nworkers", str(n)]
        if without_patterns:
            argv.append("--no-nanny")  # the nanny's own worker process would not carry the block
        if memory:
            argv += ["--memory-limit", memory]
        if hide is not None:  # a private view of the disk: the client's folder is empty there
            argv = ["unshare", "--mount", "--propagation", "private", "sh", "-c",
                    f'mount -t tmpfs tmpfs "{hide}" && exec "$@"', "sh", *argv]
        workdir = self.root / "elsewhere"
        workdir.mkdir(exist_ok=True)
        return self._start(argv, cwd=workdir)

    def wait_for(self, n: int, timeout=60):
        with distributed.Client(json.loads(self.file.read_text())["address"], timeout="10s") as client:
            client.wait_for_workers(n, timeout=timeout)

    def stop(self):
        for proc in self.procs:
            try:
                os.killpg(proc.pid, signal.SIGTERM)
            except ProcessLookupError:
                pass
        for proc in self.procs:
            try:
                proc.wait(10)
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)


def _can_hide() -> bool:
    if shutil.which("unshare") is None:
        return False
    return subprocess.run(["unshare", "--mount", "--propagation", "private", "true"], capture_output=True).returncode == 0


@pytest.fixture
def client_folder(tmp_path):
    """The client's side: parts/ (the samples and a broken file), run from here with relative paths."""
    client = tmp_path / "client"
    (client / "parts").mkdir(parents=True)
    for name in ("cup.step", "hopper.step", "dish.obj", "cone.obj", "duct_transition.step"):
        shutil.copy(SAMPLES / name, client / "parts" / name)
    (client / "parts" / "broken.step").write_bytes(b"ISO-10303-21;\nnot a step file\n")
    return client


@pytest.fixture
def cluster(tmp_path):
    made = Cluster(tmp_path)
    yield made
    made.stop()


def _batch(argv, cwd, capfd):
    old = os.getcwd()
    os.chdir(cwd)
    try:
        code = cli.main([str(a) for a in argv])
    finally:
        os.chdir(old)
    out, err = capfd.readouterr()
    return code, out, err


def _cut_polygons(path):
    doc = ezdxf.readfile(path)
    return sorted((round(shapely.Polygon([p[:2] for p in e.get_points("xy")]).area, 6),
                   round(shapely.Polygon([p[:2] for p in e.get_points("xy")]).length, 6))
                  for e in doc.modelspace().query('LWPOLYLINE[layer=="CUT"]'))


@pytest.mark.slow
def test_a_worker_that_cannot_see_the_client_disk_does_the_work(client_folder, cluster, capfd):
    """Relative paths, workers in another folder with the client's folder hidden from them: every good
    part's DXF and JSON land in the client's output folder, the same geometry as a local run; the broken
    file is one row; exit 2; no traceback."""
    if not _can_hide():
        pytest.skip("unshare --mount is not permitted here (needs root or user namespaces)")
    address = cluster.scheduler()
    cluster.worker(hide=client_folder, n=2)
    cluster.wait_for(2)
    code, out, err = _batch(["batch", "parts", "-o", "out", "--scheduler", address], client_folder, capfd)
    assert code == 2, out + err
    assert "Traceback" not in out + err
    assert f"batch: 6 files: 5 ok, 1 failed (Dask scheduler {address}); 5 written to out" in out
    rows = {line.split()[0]: line for line in out.splitlines()[1:7]}
    assert "failed: broken.step: not a readable STEP file" in rows["broken.step"]
    local = client_folder / "local"
    code_local, _, _ = _batch(["batch", "parts", "-o", "local", "--jobs", "2"], client_folder, capfd)
    assert code_local == 2
    for stem in ("cup", "hopper", "dish", "cone", "duct_transition"):
        assert _cut_polygons(client_folder / "out" / f"{stem}.dxf") == _cut_polygons(local / f"{stem}.dxf")
        remote = json.loads((client_folder / "out" / f"{stem}.json").read_text())
        here = json.loads((local / f"{stem}.json").read_text())
        assert [p["area_flat"] for p in remote["panels"]] == [p["area_flat"] for p in here["panels"]]
    assert not (cluster.root / "elsewhere" / "out").exists()  # nothing written on the worker's side


@pytest.mark.slow
def test_a_part_that_kills_its_worker_is_one_row_lost(client_folder, cluster, capfd):
    """A worker whose memory limit a million-face part exceeds is killed by its nanny, every time: the
    part ends as one row, lost, after the scheduler's retries and ours; every other part is written."""
    v, f = surfaces.paraboloid_dish(n_faces=1_000_000)
    trimesh.Trimesh(v, f, process=False).export(client_folder / "parts" / "huge.obj")
    address = cluster.scheduler()
    cluster.worker(memory="900MB")
    cluster.wait_for(1)
    code, out, err = _batch(["batch", "parts", "-o", "out", "--scheduler", address], client_folder, capfd)
    rows = {line.split()[0]: line for line in out.splitlines()[1:8]}
    assert "lost: its worker died twice" in rows["huge.obj"] and "out of memory, or a crash" in rows["huge.obj"], \
        out + err
    for stem in ("cup", "hopper", "dish", "cone", "duct_transition"):
        assert (client_folder / "out" / f"{stem}.dxf").exists()
    assert code == 2 and "Traceback" not in out + err


@pytest.mark.parametrize(("address", "words"), [
    ("http://127.0.0.1:8787/status", "a web address: the Dask dashboard's?"),
    ("tcp://127.0.0.1", "expected tcp://HOST:PORT"),
    ("junk!!", "expected tcp://HOST:PORT"),
    ("tls://127.0.0.1:8786", "not tls://"),
    ("tcp://nosuchhost.invalid:8786", "unknown host"),
    ("tcp://127.0.0.1:9", "cannot reach the Dask scheduler (Connection refused)"),
])
def test_bad_and_unreachable_addresses_are_one_line(client_folder, capfd, address, words):
    start = time.perf_counter()
    code, out, err = _batch(["batch", "parts", "-o", "out", "--scheduler", address], client_folder, capfd)
    assert time.perf_counter() - start < 60  # a guard against a hang, not a measure of speed
    assert code == 2 and err.strip().count("\n") == 0 and words in err, err
    assert not (client_folder / "out").exists()


def test_the_dashboard_port_is_named_as_such(client_folder, cluster, capfd):
    cluster.scheduler()
    dashboard = json.loads(cluster.file.read_text())["services"]["dashboard"]
    code, _, err = _batch(["batch", "parts", "-o", "out", "--scheduler", f"127.0.0.1:{dashboard}"], client_folder,
                          capfd)
    assert code == 2 and "that port answers HTTP: it is the Dask dashboard, not the scheduler" in err


def test_workers_and_a_scheduler_without_patterns_are_named(client_folder, cluster, capfd):
    address = cluster.scheduler()
    cluster.worker(without_patterns=True)
    cluster.worker()
    cluster.wait_for(2)
    with distributed.Client(address) as client:
        bad = [w for w, v in client.run(eval, "__import__('sys').meta_path[0].__class__.__name__").items()
               if v == "_Block"]
    code, _, err = _batch(["batch", "parts", "-o", "out", "--scheduler", address], client_folder, capfd)
    assert code == 2 and f"workers without patterns: {bad[0]} (pip install patterns there)" in err, err
    assert not (client_folder / "out").exists()


def test_a_scheduler_without_patterns_is_named(client_folder, cluster, capfd):
    address = cluster.scheduler(without_patterns=True)
    cluster.worker()
    cluster.wait_for(1)
    code, _, err = _batch(["batch", "parts", "-o", "out", "--scheduler", address], client_folder, capfd)
    assert code == 2 and "the scheduler has no patterns (pip install patterns there too)" in err, err


def test_no_worker_is_said_not_waited_for_forever(client_folder, cluster, capfd):
    address = cluster.scheduler()
    code, _, err = _batch(["batch", "parts", "-o", "out", "--scheduler", address, "--wait", "2"], client_folder,
                          capfd)
    assert code == 2 and "no Dask worker joined the scheduler within 2 s" in err


def test_the_python_api_takes_a_scheduler(client_folder, cluster):
    address = cluster.scheduler()
    cluster.worker()
    cluster.wait_for(1)
    result = patterns.batch(client_folder / "parts", client_folder / "api", scheduler=address)
    assert [r.status for r in result.rows] == ["failed", "ok", "ok", "ok", "ok", "ok"]
    assert result.exit_code == 2 and result.where == f"Dask scheduler {address}"
    assert np.all([(client_folder / "api" / f"{Path(r.file).stem}.dxf").exists() for r in result.rows if r.written])


def _big_processes(root_pid: int, mb: float) -> list:
    """Processes in the group of ``root_pid`` holding more than ``mb`` resident."""
    out = []
    for proc in Path("/proc").iterdir():
        if not proc.name.isdigit():
            continue
        try:
            if os.getpgid(int(proc.name)) != root_pid:
                continue
            rss = next(int(line.split()[1]) for line in (proc / "status").read_text().splitlines()
                       if line.startswith("VmRSS:"))
        except (OSError, StopIteration, ValueError):
            continue
        if rss / 1024 > mb:
            out.append(int(proc.name))
    return out


@pytest.mark.slow
def test_a_worker_killed_mid_run_loses_nothing(client_folder, cluster, capfd):
    """The worker computing a million-face part is killed once (as the OOM killer would): Dask's nanny
    starts another, the part runs again, and every part is written."""
    import threading

    v, f = surfaces.paraboloid_dish(n_faces=1_000_000)
    trimesh.Trimesh(v, f, process=False).export(client_folder / "parts" / "huge.obj")
    address = cluster.scheduler()
    worker = cluster.worker()
    cluster.wait_for(1)
    killed = []

    def kill_when_big():
        end = time.monotonic() + 120
        while time.monotonic() < end and not killed:
            for pid in _big_processes(worker.pid, 800):
                os.kill(pid, signal.SIGKILL)
                killed.append(pid)
            time.sleep(0.1)

    thread = threading.Thread(target=kill_when_big)
    thread.start()
    code, out, err = _batch(["batch", "parts", "-o", "out", "--scheduler", address], client_folder, capfd)
    thread.join()
    assert killed, "the large part's worker was never seen"
    rows = {line.split()[0]: line for line in out.splitlines()[1:8]}
    assert rows["huge.obj"].split()[-1] == "ok", out + err
    for stem in ("cup", "hopper", "dish", "cone", "duct_transition", "huge"):
        assert (client_folder / "out" / f"{stem}.dxf").exists()
    assert code == 2  # the broken file


def test_a_file_past_its_timeout_is_given_up_on_dask(client_folder, cluster, capfd):
    # One worker of one thread: the slow part (the largest, so the first) runs while the others wait
    # behind it -- on the worker too (Dask sends a thread more than one task).  Their time starts when
    # they run, not while they wait: only the slow one is given up.
    v, f = surfaces.paraboloid_dish(n_faces=600_000)
    trimesh.Trimesh(v, f, process=False).export(client_folder / "parts" / "slow.obj")
    address = cluster.scheduler()
    cluster.worker(n=1)
    cluster.wait_for(1)
    code, out, err = _batch(["batch", "parts", "-o", "out", "--scheduler", address, "--timeout", "2.5"],
                            client_folder, capfd)
    rows = {line.split()[0]: line for line in out.splitlines()[1:8]}
    assert "timeout: still running after 2.5 s: given up (Dask cannot stop a running task" in rows["slow.obj"], out
    assert "failed: broken.step: not a readable STEP file" in rows["broken.step"], out
    for stem in ("cup", "hopper", "dish", "cone", "duct_transition"):
        assert rows[f"{stem}{'.obj' if stem in ('dish', 'cone') else '.step'}"].endswith(" ok"), out
        assert (client_folder / "out" / f"{stem}.dxf").exists()
    assert not (client_folder / "out" / "slow.dxf").exists()
    assert code == 2


# --------------------------------------------------------------------------- #
# Issue 33: every network peer has a deadline; every way a cluster dies ends in the table, exit 2
# --------------------------------------------------------------------------- #


def test_a_port_that_accepts_and_never_answers_is_one_line(client_folder):
    """A port that takes the connection and says nothing (never ended, killed at 300 s): refused in one line
    within seconds, nothing written."""
    import socket
    import threading

    server = socket.create_server(("127.0.0.1", 0))
    held = []
    stop = threading.Event()

    def accept():
        server.settimeout(0.2)
        while not stop.is_set():
            try:
                held.append(server.accept()[0])  # and never a word
            except OSError:
                pass

    thread = threading.Thread(target=accept)
    thread.start()
    try:  # in a process of its own, given 60 s: it never ended before
        proc = subprocess.run([str(Path(PYTHON).with_name("patterns")), "batch", "parts", "-o", "out", "--scheduler",
                               f"127.0.0.1:{server.getsockname()[1]}"], cwd=client_folder, capture_output=True,
                              text=True, timeout=60, check=False)
        code, err = proc.returncode, proc.stderr
    finally:
        stop.set()
        thread.join()
        for conn in held:
            conn.close()
        server.close()
    assert code == 2 and err.strip().count("\n") == 0, err
    assert "that port accepts connections but says nothing in 3 s: not a Dask scheduler" in err
    assert not (client_folder / "out").exists()


def _slow_parts(client_folder, n=3):
    """Parts that take seconds each (dishes of 300,000 faces), so that the cluster can die mid-run."""
    v, f = surfaces.paraboloid_dish(n_faces=300_000)
    for k in range(n):
        trimesh.Trimesh(v * (1 + 0.01 * k), f, process=False).export(client_folder / "parts" / f"slow{k}.obj")


def _when_running(cluster, act):
    """A thread that calls ``act()`` once the first file has run for a second on the cluster."""
    import threading

    def watch():
        with distributed.Client(json.loads(cluster.file.read_text())["address"], timeout="10s") as client:
            end = time.monotonic() + 120
            while time.monotonic() < end:
                if any(client.processing().values()) and sum(map(len, client.call_stack().values())):
                    time.sleep(1.0)
                    act()
                    return
                time.sleep(0.1)

    thread = threading.Thread(target=watch)
    thread.start()
    return thread


@pytest.mark.parametrize("what", ["workers", "scheduler"])
def test_a_cluster_that_dies_mid_run_ends_in_the_table(client_folder, cluster, capfd, what):
    """Every worker killed (SIGKILL, nanny and all), or the scheduler: a raw distributed traceback before
    (TimeoutError: No valid workers found; OSError: Timed out trying to connect).  Now: the table, every file
    a row (those not done lost, saying why), exit 2, within --wait seconds of the loss."""
    _slow_parts(client_folder)
    address = cluster.scheduler()
    worker = cluster.worker(n=1)
    cluster.wait_for(1)
    target = worker if what == "workers" else cluster.procs[0]
    thread = _when_running(cluster, lambda: os.killpg(target.pid, signal.SIGKILL))
    start = time.monotonic()
    code, out, err = _batch(["batch", "parts", "-o", "out", "--scheduler", address, "--wait", "3"], client_folder,
                            capfd)
    thread.join()
    assert time.monotonic() - start < 90
    assert code == 2 and "Traceback" not in out + err, out + err
    rows = {line.split()[0]: line for line in out.splitlines()[1:10] if line.split()}
    assert set(rows) >= {"slow0.obj", "slow1.obj", "slow2.obj", "cup.step", "broken.step"}, out
    lost = [r for r in rows.values() if " lost" in r]
    assert lost and all("went away" in r or "died" in r for r in lost), out
    assert "batch: 9 files:" in out
