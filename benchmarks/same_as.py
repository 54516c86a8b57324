"""Is the engine still the one a benchmark measured?  Flatten the corpus with this checkout and
with an earlier commit, side by side: are the layouts bitwise the same, and how do the times compare?

    python benchmarks/same_as.py 656efbf            # the commit docs/benchmarks.md names
    python benchmarks/same_as.py 656efbf --repeats 3

For every corpus mesh (``../shared/corpus/``) both versions run ``patterns.flatten_mesh`` with its
defaults, each in its own process (the earlier one from a temporary ``git worktree``), alternately,
best of ``--repeats``; the table gives the SHA-1 of each ``uv`` array, whether they are equal, and
the time of this checkout over the earlier one's (the peer, in the same run).  When every layout
is bitwise equal, every strain, fold count and verdict of that commit's benchmark holds unchanged.
(Both run in this process's environment: OpenBLAS picks its kernels by CPU type, and another
kernel rounds dot products differently, so the SHA-1 values themselves belong to this machine.)
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
CORPUS = REPO.parent / "shared" / "corpus"

_RUN = """
import hashlib, json, sys, time
import numpy as np
import patterns
mesh = patterns.read_mesh(sys.argv[1])
best = float("inf")
for _ in range(int(sys.argv[2])):
    t = time.perf_counter()
    r = patterns.flatten_mesh(mesh.vertices, mesh.faces)
    best = min(best, time.perf_counter() - t)
print(json.dumps({"sha": hashlib.sha1(np.ascontiguousarray(r.uv).tobytes()).hexdigest()[:12],
                  "seconds": best, "faces": len(mesh.faces)}))
"""


def _run(root: Path, mesh: Path, repeats: int) -> dict:
    # Run in ``root``: ``python -c`` puts the working directory first on sys.path, before PYTHONPATH, so run
    # from anywhere else (the repository root, say) both versions would import that directory's patterns.
    proc = subprocess.run([sys.executable, "-c", _RUN, str(mesh), str(repeats)], capture_output=True, text=True,
                          env=dict(os.environ, PYTHONPATH=str(root)), cwd=str(root), check=True)
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("commit", help="the earlier commit (the one a benchmark measured)")
    parser.add_argument("--repeats", type=int, default=1, help="best of this many runs of each (default 1)")
    args = parser.parse_args(argv)
    if not CORPUS.is_dir():
        print(f"{CORPUS} does not exist: nothing to compare")
        return 0
    meshes = sorted(p for p in CORPUS.iterdir() if p.suffix.lower() in (".obj", ".off", ".ply", ".stl"))
    head = subprocess.run(["git", "-C", str(REPO), "rev-parse", "--short", "HEAD"], capture_output=True,
                          text=True, check=True).stdout.strip()
    with tempfile.TemporaryDirectory(prefix="patterns-same-as-") as tmp:
        old = Path(tmp) / "old"
        subprocess.run(["git", "-C", str(REPO), "worktree", "add", "--detach", str(old), args.commit],
                       check=True, capture_output=True)
        try:
            print(f"| mesh | faces | uv at {args.commit} | uv at {head} (this checkout) | equal | "
                  f"time / time at {args.commit} |")
            print("|---|---:|---|---|---|---:|")
            equal = 0
            for mesh in meshes:
                a = _run(old, mesh, args.repeats)
                b = _run(REPO, mesh, args.repeats)
                same = a["sha"] == b["sha"]
                equal += same
                print(f"| {mesh.name} | {b['faces']} | {a['sha']} | {b['sha']} | {'yes' if same else 'NO'} | "
                      f"{b['seconds'] / a['seconds']:.2f} |", flush=True)
            print(f"\n{equal} of {len(meshes)} layouts bitwise equal")
        finally:
            subprocess.run(["git", "-C", str(REPO), "worktree", "remove", "--force", str(old)], capture_output=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
