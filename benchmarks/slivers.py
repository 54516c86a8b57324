"""Crushed triangles: how far the flat layouts squeeze single triangles.

Edge-strain RMS, the benchmark's main measure, does not see a triangle pressed
flat: the edge stress of a collapsing edge is bounded (``(l/L - 1)**2 <= 1`` as
``l -> 0``), and a triangle can flatten into a line with its three edges still
of sensible lengths.  This script measures the smallest principal stretch
``sigma_min`` of every triangle (1 for a rigid copy, 0 for a triangle pressed
flat) for ``patterns.flatten_mesh`` (``relaxed``) and libigl ARAP (the
benchmark's recipe), and prints one markdown table:

* ``min sigma_min``: the most squeezed triangle;
* ``< 0.5``, ``< 0.2``: how many triangles are squeezed below half, below a
  fifth of their size in one direction, and the share of the 3D area they cover;
* where they are (``z`` range of their centres, mm, on the generated surfaces).

    python benchmarks/slivers.py            # 10k and 100k surfaces, the corpus
    python benchmarks/slivers.py --no-corpus

The corpus is read from ``../shared/corpus/`` (skipped, with the reason
printed, when absent).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

import patterns
from patterns.measure import principal_stretches
from patterns.mesh import face_areas

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench_flatten as bench  # noqa: E402  (the meshes and libigl recipes of the benchmark)


def sliver_row(name: str, method: str, vertices, faces, uv) -> str:
    """One markdown row of squeeze statistics for a layout ``uv`` ``(n, 2)``."""
    s = principal_stretches(vertices, faces, np.asarray(uv, dtype=np.float64))
    smin = s.min(axis=1)
    area = face_areas(vertices, faces)
    centre_z = vertices[faces].mean(axis=1)[:, 2]
    cells = [name, f"{len(faces)}", method, f"{smin.min():.4f}"]
    for limit in (0.5, 0.2):
        bad = smin < limit
        cells.append(f"{int(bad.sum())} ({100 * area[bad].sum() / area.sum():.2f} %)")
    bad = smin < 0.2
    cells.append(f"{centre_z[bad].min():.1f} .. {centre_z[bad].max():.1f}" if bad.any() else "")
    return "| " + " | ".join(cells) + " |"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--no-corpus", action="store_true", help="skip ../shared/corpus/")
    args = parser.parse_args(argv)
    meshes = list(bench.generated_meshes([("10k", 10_000)], [("10k", 10_000), ("100k", 100_000)]))
    if args.no_corpus:
        print("corpus: skipped (--no-corpus)")
    elif not bench.CORPUS.is_dir():
        print(f"corpus: skipped ({bench.CORPUS} does not exist)")
    else:
        meshes += list(bench.corpus_meshes(bench.CORPUS))
    print("| mesh | faces | method | min sigma_min | sigma_min < 0.5 (area) | sigma_min < 0.2 (area) "
          "| z of those < 0.2 |")
    print("|---|---|---|---|---|---|---|")
    for name, vertices, faces in meshes:
        result = patterns.flatten_mesh(vertices, faces, name=name)
        print(sliver_row(name, "relaxed", result.vertices, result.faces, result.uv), flush=True)
        arap = bench.igl_arap(vertices, faces)[0]
        print(sliver_row(name, "arap", vertices, faces, bench._mirror_if_reversed(faces, np.asarray(arap),
                                                                                  bench.Row(name, len(faces), "arap"))),
              flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
