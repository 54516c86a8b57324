"""Does the greedy grower get worse as the same surface is meshed finer?

Prints one markdown table: for each step (the paper's similarity step, an
edge-aligned rigid step, the transported rigid step that ``isometric`` uses) and
each growth order (the paper's shortest-front heap, front-by-front passes),
the edge-strain RMS and max and the folded-triangle count on

* the paraboloid dish of the issue (600 mm across, 54 mm sag),
* a 60-degree spherical cap (radius 100 mm, polar half-angle 30 degrees),

at 1k, 10k, 100k (and, with ``--million``, 1M) faces.  The heap order is a
Python loop and is skipped above 100k faces.  Time is printed as a ratio to a
peer timed side by side on the same mesh in the same run: libigl's LSCM
(``bench_flatten.igl_lscm``, a linear solve, the usual one-shot flattening).

    python benchmarks/resolution_study.py [--million]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench_flatten as bench  # libigl's LSCM, as the benchmark runs it

import patterns
from patterns import surfaces
from patterns.flattening import grow
from patterns.measure import local_coordinates
from patterns.mesh import validate_mesh

STEPS = {
    "similarity (paper)": grow.similarity_step,
    "rigid, edge-aligned": grow.rigid_step,
    "rigid, transported": grow.transported_step,
}
GROWTHS = {"heap": grow.grow_heap, "fronts": grow.grow_fronts}
SHAPES = {
    "dish 600x54": lambda n: surfaces.paraboloid_dish(diameter=600.0, sag=54.0, n_faces=n),
    "cap 60deg": lambda n: surfaces.spherical_cap(radius=100.0, half_angle=30.0, n_faces=n),
}


def study(sizes: list[int]) -> list[str]:
    """Run every combination; return markdown table rows."""
    rows = [
        "| surface | faces | step | growth | time / libigl LSCM | edge strain RMS | max | folds |",
        "|---|---:|---|---|---:|---:|---:|---:|",
    ]
    print("\n".join(rows), flush=True)
    for shape, make in SHAPES.items():
        for n in sizes:
            v, f, conn = validate_mesh(*make(n))
            z = local_coordinates(v, f)
            weights = 0.5 * np.abs(np.imag(np.conj(z[:, 1]) * z[:, 2]))
            seed = grow.seed_face(v, f, conn)
            rotations = grow.transported_rotations(z, f, conn, seed)
            peer, _ = bench.best_of(lambda: bench.igl_lscm(v, f), 1)
            for step_name, step in STEPS.items():
                for growth_name, growth in GROWTHS.items():
                    if growth_name == "heap" and len(f) > 150_000:
                        continue
                    start = time.perf_counter()
                    with np.errstate(over="ignore", invalid="ignore"):
                        w = growth(z, f, conn, weights, seed, step, rotations=rotations)
                    seconds = time.perf_counter() - start
                    d = patterns.distortion(v, f, np.column_stack([w.real, w.imag]))
                    rows.append(
                        f"| {shape} | {len(f)} | {step_name} | {growth_name} | {seconds / peer:.2f} | "
                        f"{d.edge_strain_rms:.3g} | {d.edge_strain_max:.3g} | {d.n_folded} |"
                    )
                    print(rows[-1], flush=True)
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--million", action="store_true", help="add the 1M-face meshes")
    args = parser.parse_args()
    sizes = [1_000, 10_000, 100_000] + ([1_000_000] if args.million else [])
    study(sizes)


if __name__ == "__main__":
    main()
