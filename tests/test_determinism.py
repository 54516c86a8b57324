"""The same file gives the same pattern on every machine (issue 51).

OpenBLAS picks its kernels by the CPU, and ``OPENBLAS_CORETYPE`` makes it pick another's: with fused
multiply-adds (``Haswell``) or without (``Sandybridge``), with AVX or with SSE only (``Nehalem``).  Each
case is flattened in child processes under the CPU's own kernels and two such settings, and all must agree
bit for bit: every panel's layout, its darts, the pieces a limit parted it into.  An AVX-512 CPU's own
(``SkylakeX``) rounds apart from both: a start fitted to its pins by a BLAS product and an SVD moved the
dish's far-pinned layout three ways (2026-11-29).  Before the engine's factorisations were
qdldl's (no BLAS beneath), the sample cup flattened to different bits under Haswell and Sandybridge on an
AMD EPYC, and the darts the search cut followed those bits ([3, 4, 3, 3] against [3, 3, 4, 3]).
"""

from __future__ import annotations

import json
import os
import platform
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent

CHILD = r'''
import hashlib, json, sys
import numpy as np
import patterns
from patterns import samples
from patterns.reading import read_mesh


def pinned(target):  # the dish's vertices 0 and 17 pinned 33.34 mm apart (their 3D distance) or 250 mm
    mesh = read_mesh(sys.argv[1] + "/samples/dish.obj")
    result = patterns.flatten_mesh(mesh.vertices, mesh.faces, pins=([0, 17], [[0.0, 0.0], [target, 0.0]]))
    return [("dish", 0)], [result.uv]


def flat(pattern):
    return [(p.name, len(p.darts)) for p in pattern.panels], [p.uv for p in pattern.panels]


CASES = {
    "cup": lambda: flat(patterns.flatten(patterns.load(sys.argv[1] + "/samples/cup.step"))),
    "cup darts": lambda: flat(patterns.flatten(patterns.load(sys.argv[1] + "/samples/cup.step"), max_strain=0.03)),
    "saddle inserts": lambda: flat(patterns.flatten(patterns.load(samples.saddle()), max_strain=0.03)),
    "spline bowl parted": lambda: flat(patterns.flatten(patterns.load(samples.spline_bowl()), max_strain=0.03)),
    "oblate dome gores": lambda: flat(patterns.flatten(patterns.load(samples.oblate_dome()), max_strain=0.03,
                                                       gores=True)),
    "hopper exact": lambda: flat(patterns.flatten(patterns.load(sys.argv[1] + "/samples/hopper.step"))),
    "dish pinned near": lambda: pinned(33.34),
    "dish pinned far": lambda: pinned(250.0),
}
out = {}
for name in sys.argv[2:]:
    pieces, layouts = CASES[name]()
    digest = hashlib.sha256()
    for uv in layouts:
        digest.update(np.ascontiguousarray(uv).tobytes())
    out[name] = {"pieces": pieces, "layout": digest.hexdigest()}
print(json.dumps(out))
'''


def _coretypes() -> tuple:
    """The OpenBLAS kernel sets to run under: this CPU's own (``None``: no setting) and two it can run that
    round differently, or a reason to skip."""
    if platform.machine() not in ("x86_64", "AMD64"):
        pytest.skip(f"OPENBLAS_CORETYPE names x86-64 kernels; this machine is {platform.machine()}")
    try:
        flags = set(Path("/proc/cpuinfo").read_text().split("flags", 1)[1].split("\n", 1)[0].split())
    except (OSError, IndexError):
        pytest.skip("no /proc/cpuinfo to say which kernels this CPU runs")
    if {"avx2", "fma"} <= flags:
        return None, "Haswell", "Sandybridge"  # (an AVX-512 CPU's own: SkylakeX), fused multiply-adds, none
    if "avx" in flags:
        return None, "Sandybridge", "Nehalem"  # AVX against SSE
    pytest.skip("a CPU without AVX: one kernel set only")


def _children(code: str, args: list, folders: Path | None = None) -> dict:
    """``{coretype: (stdout, its folder or None)}``: ``python -c code *args`` run under this CPU's own kernels
    (``"own"``) and two other kernel sets, side by side, each in a folder of its own under ``folders`` where
    given; every child checked to have ended well and taken the kernels it was given."""
    runs = {}
    for coretype in _coretypes():
        name = coretype or "own"
        env = dict(os.environ, OPENBLAS_VERBOSE="2")
        env.pop("OPENBLAS_CORETYPE", None)
        if coretype is not None:
            env["OPENBLAS_CORETYPE"] = coretype
        folder = None if folders is None else folders / name
        if folder is not None:
            folder.mkdir()
        runs[name] = folder, subprocess.Popen([sys.executable, "-c", code, *args], env=env, cwd=folder,
                                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    out = {}
    for name, (folder, child) in runs.items():
        stdout, stderr = child.communicate(timeout=1200)
        assert child.returncode == 0, stderr[-2000:]
        assert f"Core: {name}" in stderr or name == "own"  # OpenBLAS says the kernels it took
        out[name] = stdout, folder
    return out


def _run_under_each(cases: list) -> dict:
    """``{coretype: {case: {"pieces", "layout"}}}``, the children run side by side (``"own"``: this CPU's own
    kernels)."""
    return {name: json.loads(stdout.strip().splitlines()[-1])
            for name, (stdout, _) in _children(CHILD, [str(REPO), *cases]).items()}


def _same(out: dict) -> None:
    (a, first), *others = out.items()
    for b, second in others:
        for case in first:
            assert first[case]["pieces"] == second[case]["pieces"], (case, a, first[case]["pieces"], b,
                                                                     second[case]["pieces"])
            assert first[case]["layout"] == second[case]["layout"], (case, "layouts differ between", a, "and", b)


def test_the_cup_and_a_saddle_flatten_to_the_same_bits_under_two_cpus_kernels():
    """The cup, the saddle with its inserts, the hopper's exact cones and the dish pinned where it can lie and
    where it cannot (500 iterations, not converged: the far pins' stretch was 3.126 / 3.125 / 3.1246 under an
    AVX-512 CPU's own kernels, Haswell's and Sandybridge's while the start was fitted to its pins by BLAS)."""
    _same(_run_under_each(["cup", "saddle inserts", "hopper exact", "dish pinned near", "dish pinned far"]))


@pytest.mark.slow
def test_darts_parting_and_gores_are_the_same_under_two_cpus_kernels():
    """The searches that decide: the cup's darts, the spline bowl parted into pieces with darts, the oblate
    dome in gores; each decision (a dart more or less, a gore count, a piece) the same, and every layout."""
    _same(_run_under_each(["cup darts", "spline bowl parted", "oblate dome gores"]))


def _files_under_each(commands: list[list[str]], tmp_path: Path) -> dict:
    """``{coretype: {file name: bytes}}``: each command line of ``patterns`` run in a folder of its own per
    kernel set (this CPU's own and two others), the runs side by side."""
    code = f"from patterns.cli import main\nfor args in {commands!r}:\n    assert main(args) == 0, args"
    return {name: {p.name: p.read_bytes() for p in sorted(folder.iterdir())}
            for name, (_, folder) in _children(code, [], tmp_path).items()}


def test_the_files_written_are_the_same_bytes_under_two_cpus_kernels(tmp_path):
    """What a cutter receives: the cup's pattern with its darts cut at 3 %, a 10 mm seam allowance and notches,
    as DXF (lines, and arcs fitted with V notches), SVG and the JSON report, and the bracket's blank with its
    bend sheet: byte for byte the same under the CPU's own kernels, Haswell's and Sandybridge's (any number
    printed to its last digit).  A notch's direction (a BLAS dot product of a 2-vector), the arcs' fit and the
    pieces' placement (a BLAS matrix product) moved last digits of the DXF between an AVX-512 CPU's own kernels
    and Haswell's (2026-11-29)."""
    cup, bracket = str(REPO / "samples" / "cup.step"), str(REPO / "samples" / "bracket.step")
    out = _files_under_each([
        ["flatten", cup, "-o", "cup.dxf", "--dart-strain", "0.03", "--seam-allowance", "10", "--report", "cup.json"],
        ["flatten", cup, "-o", "cup.svg", "--dart-strain", "0.03", "--seam-allowance", "10"],
        ["flatten", cup, "-o", "arcs.dxf", "--dart-strain", "0.03", "--seam-allowance", "10", "--arcs",
         "--notch-style", "v"],
        ["unfold", bracket, "-o", "bracket.dxf", "--bend-sheet", "bends.csv"],
    ], tmp_path)
    (a, first), *others = out.items()
    assert sorted(first) == ["arcs.dxf", "bends.csv", "bracket.dxf", "cup.dxf", "cup.json", "cup.svg"]
    darts = [len(panel["darts"]) for panel in json.loads(first["cup.json"])["panels"]]
    assert sum(darts) >= 12 and b"BEND" in first["bracket.dxf"]  # the darts a search decided; bend lines drawn
    for b, second in others:
        assert sorted(second) == sorted(first)
        for name in first:
            assert first[name] == second[name], (name, "differs between", a, "and", b)


@pytest.mark.slow
def test_every_real_sheet_metal_part_unfolds_to_the_same_bytes_under_two_cpus_kernels(tmp_path):
    """Every part of the torture set (the Laser4DIY enclosure from Fusion 360, the OpenAMR parts, FreeCAD's
    own) and SolidWorks' five in ``../shared/sheetmetal`` where present: the blank's DXF and its bend sheet
    byte for byte the same, and each refusal the same message, under the CPU's own kernels, Haswell's and
    Sandybridge's.  The faces' placement on the blank was fitted by a BLAS product (a Kabsch cross-covariance):
    the Cover's outline and the Center bracket's slots moved in their last digits between an AVX-512 CPU's
    own kernels and Sandybridge's (2026-11-29)."""
    torture = REPO / "tests" / "data" / "torture"
    parts = sorted(torture.glob("*.step")) + sorted((torture / "freecad").glob("*.step"))
    shared = REPO.parent / "shared" / "sheetmetal"
    parts += sorted(shared.glob("*.STEP")) if shared.is_dir() else []
    code = (
        "import contextlib, io, json\n"
        "from patterns.cli import main\n"
        "said = {}\n"
        f"for path in {[str(p) for p in parts]!r}:\n"
        "    stem = path.rsplit('/', 1)[1].rsplit('.', 1)[0]\n"
        "    err = io.StringIO()\n"
        "    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):\n"
        "        code = main(['unfold', path, '-o', stem + '.dxf', '--bend-sheet', stem + '.csv'])\n"
        "    said[stem] = [code, err.getvalue() if code else '']\n"
        "open('said.json', 'w').write(json.dumps(said, sort_keys=True))\n"
    )
    out = {name: {p.name: p.read_bytes() for p in sorted(folder.iterdir())}
           for name, (_, folder) in _children(code, [], tmp_path).items()}
    (a, first), *others = out.items()
    said = json.loads(first["said.json"])
    unfolded = [stem for stem, (code, _) in said.items() if code == 0]
    # Fusion's 17 sheet-metal parts and FreeCAD's 4 unfold (docs/sheet-metal.md), SolidWorks' 5 where present
    assert len(said) == len(parts) and len(unfolded) >= 21 + (5 if shared.is_dir() else 0)
    assert all(f"{stem}.dxf" in first for stem in unfolded)
    for b, second in others:
        assert sorted(second) == sorted(first)
        for name in first:
            assert first[name] == second[name], (name, "differs between", a, "and", b)
