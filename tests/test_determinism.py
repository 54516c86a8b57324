"""The same file gives the same pattern on every machine (issue 51).

OpenBLAS picks its kernels by the CPU, and ``OPENBLAS_CORETYPE`` makes it pick another's: with fused
multiply-adds (``Haswell``) or without (``Sandybridge``), with AVX or with SSE only (``Nehalem``).  Each
case is flattened in two child processes under two such settings, and the two must agree bit for bit: every
panel's layout, its darts, the pieces a limit parted it into.  Before the engine's factorisations were
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
CASES = {
    "cup": lambda: patterns.flatten(patterns.load(sys.argv[1] + "/samples/cup.step")),
    "cup darts": lambda: patterns.flatten(patterns.load(sys.argv[1] + "/samples/cup.step"), max_strain=0.03),
    "saddle inserts": lambda: patterns.flatten(patterns.load(samples.saddle()), max_strain=0.03),
    "spline bowl parted": lambda: patterns.flatten(patterns.load(samples.spline_bowl()), max_strain=0.03),
    "oblate dome gores": lambda: patterns.flatten(patterns.load(samples.oblate_dome()), max_strain=0.03,
                                                  gores=True),
}
out = {}
for name in sys.argv[2:]:
    pattern = CASES[name]()
    digest = hashlib.sha256()
    for panel in pattern.panels:
        digest.update(np.ascontiguousarray(panel.uv).tobytes())
    out[name] = {"pieces": [[p.name, len(p.darts)] for p in pattern.panels], "layout": digest.hexdigest()}
print(json.dumps(out))
'''


def _coretypes() -> tuple:
    """Two OpenBLAS kernel sets this CPU can run that round differently, or a reason to skip."""
    if platform.machine() not in ("x86_64", "AMD64"):
        pytest.skip(f"OPENBLAS_CORETYPE names x86-64 kernels; this machine is {platform.machine()}")
    try:
        flags = set(Path("/proc/cpuinfo").read_text().split("flags", 1)[1].split("\n", 1)[0].split())
    except (OSError, IndexError):
        pytest.skip("no /proc/cpuinfo to say which kernels this CPU runs")
    if {"avx2", "fma"} <= flags:
        return "Haswell", "Sandybridge"  # fused multiply-adds against none
    if "avx" in flags:
        return "Sandybridge", "Nehalem"  # AVX against SSE
    pytest.skip("a CPU without AVX: one kernel set only")


def _run_under_each(cases: list) -> dict:
    """``{coretype: {case: {"pieces", "layout"}}}``, the two children run side by side."""
    runs = {}
    for coretype in _coretypes():
        env = dict(os.environ, OPENBLAS_CORETYPE=coretype, OPENBLAS_VERBOSE="2")
        runs[coretype] = subprocess.Popen([sys.executable, "-c", CHILD, str(REPO), *cases], env=env,
                                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    out = {}
    for coretype, child in runs.items():
        stdout, stderr = child.communicate(timeout=1200)
        assert child.returncode == 0, stderr[-2000:]
        assert f"Core: {coretype}" in stderr  # OpenBLAS says the kernels it took: the setting took hold
        out[coretype] = json.loads(stdout.strip().splitlines()[-1])
    return out


def _same(out: dict) -> None:
    (a, first), (b, second) = out.items()
    for case in first:
        assert first[case]["pieces"] == second[case]["pieces"], (case, a, first[case]["pieces"], b,
                                                                 second[case]["pieces"])
        assert first[case]["layout"] == second[case]["layout"], (case, "layouts differ between", a, "and", b)


def test_the_cup_and_a_saddle_flatten_to_the_same_bits_under_two_cpus_kernels():
    _same(_run_under_each(["cup", "saddle inserts"]))


@pytest.mark.slow
def test_darts_parting_and_gores_are_the_same_under_two_cpus_kernels():
    """The searches that decide: the cup's darts, the spline bowl parted into pieces with darts, the oblate
    dome in gores; each decision (a dart more or less, a gore count, a piece) the same, and every layout."""
    _same(_run_under_each(["cup darts", "spline bowl parted", "oblate dome gores"]))
