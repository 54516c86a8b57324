"""`patterns batch` with one worker process against two, side by side on the same 23 parts (issue 23).

The 23 parts: the eight samples (six STEP files, two meshes) and fifteen generated meshes (dishes,
caps, saddles and cylinders of 40k to 245k triangles, as OBJ, STL and PLY): some 30 s of work on one
core, so that starting the worker processes (about 3 s, once) does not hide the speed-up.  Each command runs
``--runs`` times, alternating, as a whole process (``patterns batch PARTS -o OUT --jobs N``); the
table gives the least and the median wall time and the speed-up of the medians, and checks that
both wrote byte-identical files.  Run it on an idle machine: the speed-up is the point.

    python benchmarks/batch.py [--runs 3] [--keep DIR]
"""

from __future__ import annotations

import argparse
import hashlib
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import trimesh

from patterns import surfaces

REPO = Path(__file__).resolve().parent.parent
EXE = Path(sys.executable).with_name("patterns")


def make_parts(folder: Path) -> list:
    folder.mkdir(parents=True, exist_ok=True)
    for sample in sorted((REPO / "samples").iterdir()):
        if sample.suffix in (".step", ".obj"):
            shutil.copy(sample, folder / sample.name)
    shapes = []
    for k, n in enumerate((40_000, 80_000, 120_000, 160_000)):
        shapes.append((f"dish{k}", surfaces.paraboloid_dish(n_faces=n)))
        shapes.append((f"cap{k}", surfaces.spherical_cap(half_angle=60.0, n_faces=n)))
    for k, n in enumerate((60_000, 100_000, 140_000)):
        shapes.append((f"saddle{k}", surfaces.saddle(n_faces=n)))
    for k, (angle, n) in enumerate(((180.0, 200), (270.0, 250), (300.0, 300), (330.0, 350))):
        shapes.append((f"cyl{k}", surfaces.cylinder_patch(radius=100.0, height=200.0, angle=angle, n_around=n,
                                                           n_along=n // 2)))
    suffixes = (".obj", ".stl", ".ply")
    for k, (name, (v, f)) in enumerate(shapes):
        trimesh.Trimesh(v, f, process=False).export(folder / f"{name}{suffixes[k % 3]}")
    return sorted(p.name for p in folder.iterdir())


def digest(folder: Path) -> str:
    h = hashlib.sha256()
    for p in sorted(folder.iterdir()):
        h.update(p.name.encode() + p.read_bytes())
    return h.hexdigest()[:12]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--keep", type=Path, default=None, help="make the parts here and keep them")
    args = parser.parse_args(argv)
    work = args.keep or Path(tempfile.mkdtemp(prefix="patterns-batch-bench-"))
    parts = work / "parts"
    names = make_parts(parts)
    print(f"{len(names)} parts in {parts}")
    times = {1: [], 2: []}
    digests = {}
    for _ in range(args.runs):
        for jobs in (1, 2):
            out = work / f"out{jobs}"
            shutil.rmtree(out, ignore_errors=True)
            start = time.perf_counter()
            proc = subprocess.run([str(EXE), "batch", str(parts), "-o", str(out), "--jobs", str(jobs), "--quiet"],
                                  capture_output=True, text=True)
            times[jobs].append(time.perf_counter() - start)
            assert proc.returncode in (0, 1), proc.stdout[-2000:] + proc.stderr[-2000:]
            digests.setdefault(jobs, digest(out))
    print("\n| command | runs | least s | median s |")
    print("|---|---|---|---|")
    for jobs in (1, 2):
        print(f"| `patterns batch --jobs {jobs}` | {args.runs} | {min(times[jobs]):.2f} | "
              f"{statistics.median(times[jobs]):.2f} |")
    speedup = statistics.median(times[1]) / statistics.median(times[2])
    same = "byte-identical" if digests[1] == digests[2] else f"DIFFERENT ({digests[1]} / {digests[2]})"
    print(f"\n--jobs 2 is {speedup:.2f}x as fast as --jobs 1 (medians); outputs {same}")
    if args.keep is None:
        shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
