"""``benchmarks/same_as.py`` compares the engine with an earlier commit's, never with itself (issue 51)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import trimesh

from patterns.surfaces import spherical_cap

REPO = Path(__file__).resolve().parent.parent
SCRIPT = REPO / "benchmarks" / "same_as.py"
BEFORE_QDLDL = "e3f365c"
"""The last commit whose engine factorised with SuperLU: its layouts differ from qdldl's in the last bits."""


def test_a_commit_whose_engine_is_this_checkouts_is_refused():
    run = subprocess.run([sys.executable, str(SCRIPT), "HEAD"], capture_output=True, text=True, cwd=REPO)
    assert run.returncode == 2 and "compares the engine with itself" in run.stderr and run.stdout == ""


def test_an_earlier_engine_runs_from_its_own_worktree_and_its_layout_differs(tmp_path):
    """The earlier commit's child imports the worktree's patterns, not this checkout's: its SuperLU layout
    of a small cap is not bitwise this checkout's qdldl one (the comparison of a tree with itself said "equal")."""
    vertices, faces = spherical_cap(radius=50.0, half_angle=60.0, n_faces=2000)
    (tmp_path / "corpus").mkdir()
    trimesh.Trimesh(vertices, faces, process=False).export(tmp_path / "corpus" / "cap.obj")
    run = subprocess.run([sys.executable, str(SCRIPT), BEFORE_QDLDL, "--corpus", str(tmp_path / "corpus")],
                         capture_output=True, text=True, cwd=REPO, timeout=600)
    assert run.returncode == 0, run.stderr
    (row,) = [line for line in run.stdout.splitlines() if line.startswith("| cap.obj")]
    cells = [c.strip() for c in row.strip("|").split("|")]
    assert cells[2] != cells[3] and cells[4] == "NO"
    assert "0 of 1 layouts bitwise equal" in run.stdout
