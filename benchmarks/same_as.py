"""Is the engine still the one a benchmark measured?  Flatten the corpus with this checkout and
with an earlier commit, side by side: are the layouts bitwise the same, and how do the times compare?

    python benchmarks/same_as.py 656efbf            # the commit docs/benchmarks.md names
    python benchmarks/same_as.py 656efbf --repeats 3

For every corpus mesh (``../shared/corpus/``) both versions run ``patterns.flatten_mesh`` with its
defaults, each in its own process (the earlier one from a temporary ``git worktree``), alternately,
best of ``--repeats``; the table gives the SHA-1 of each ``uv`` array, whether they are equal, and
the time of this checkout over the earlier one's (the peer, in the same run).  When every layout
is bitwise equal, every strain, fold count and verdict of that commit's benchmark holds unchanged.
(Both run in this process's environment.)

It refuses, with exit code 2, to compare a tree with itself: a commit whose files are the checkout's
(``git diff --quiet COMMIT``, the working tree's edits included), or a run in which both processes
imported the same ``patterns`` (each child reports the file it imported; the earlier one must come from the
worktree).  Both once happened unseen: four changes' notes said "10 of 10 corpus layouts bitwise equal"
from runs that compared the checkout with itself.
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
                  "seconds": best, "faces": len(mesh.faces), "engine": patterns.__file__}))
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
    parser.add_argument("--corpus", type=Path, default=CORPUS, help=f"the meshes (default {CORPUS})")
    args = parser.parse_args(argv)
    head = subprocess.run(["git", "-C", str(REPO), "rev-parse", "--short", "HEAD"], capture_output=True,
                          text=True, check=True).stdout.strip()
    if subprocess.run(["git", "-C", str(REPO), "diff", "--quiet", args.commit, "--", "patterns"]).returncode == 0:
        print(f"same_as: {args.commit}'s patterns/ is this checkout's (edits included): that compares the engine "
              f"with itself; name an earlier commit", file=sys.stderr)
        return 2
    # after the refusal: a clone with no ../shared refuses to compare the engine with itself as well
    if not args.corpus.is_dir():
        print(f"{args.corpus} does not exist: nothing to compare")
        return 0
    meshes = sorted(p for p in args.corpus.iterdir() if p.suffix.lower() in (".obj", ".off", ".ply", ".stl"))
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
                if Path(a["engine"]).resolve() == Path(b["engine"]).resolve() or old.resolve() not in \
                        Path(a["engine"]).resolve().parents:
                    print(f"same_as: both runs imported {b['engine']} (the earlier one imported {a['engine']}, "
                          f"not the worktree's): the comparison would be with itself", file=sys.stderr)
                    return 2
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
