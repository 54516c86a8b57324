"""How little strain can a panel have with its seams at their 3D length?  The floor, from four starts.

Issue 16 asks that holding seams at their length cost at most 1.3 x the strain of
the free-boundary layout.  This script measures what the constraint itself
costs: for one freeform panel of each model it relaxes, to a tight tolerance
(1e-9, up to 5000 iterations), the area-weighted ARAP energy with the seams
held -- edge by edge (``seams="true"``) and in total (``"total"``) -- from four
starts: the free optimum, the greedy layout, LSCM and Tutte.  If every start
ends at the same strain, that is the least strain any layout with those seam
lengths has (not a proof, strong evidence), and a criterion below it cannot be
met by any method.

Run from the repository root::

    python benchmarks/seam_floor.py            # the cup, the bowl segment, the gores (about a minute)
"""

from __future__ import annotations

import argparse
import importlib
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parent.parent
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

import patterns
from patterns.flattening.embed import lscm, tutte_embedding
from patterns.flattening.moves import best_scale
from patterns.flattening.seams import SeamLengths, held_lengths
from patterns.measure import strain_rms
from patterns.mesh import unique_edges, validate_mesh
from patterns.samples import bowl_segment, sphere_gores

relax = importlib.import_module("patterns.flattening.relax")


def models():
    """``(name, model, panel index)``: one freeform panel of each model."""
    out = [("cup", patterns.load(REPO / "samples" / "cup.step"))]
    out += [("bowl segment", patterns.load(bowl_segment())), ("sphere gores", patterns.load(sphere_gores()))]
    return [(name, m, next(i for i, p in enumerate(m.panels) if p.surface is None)) for name, m in out]


def starts(v, f, conn):
    """The four starting layouts, each one-to-one."""
    free = patterns.flatten_mesh(v, f, energy_tolerance=1e-9, max_iterations=5000)
    out = {"free optimum": (free.uv, 0.0), "greedy": (patterns.flatten_mesh(v, f, method="isometric").uv, 0.0)}
    for name, make in (("lscm", lscm), ("tutte", tutte_embedding)):
        s = make(v, f, conn)
        out[name] = (s * best_scale(v, conn.edges, s), 0.1)
    return free, out


def main(argv=None) -> int:
    argparse.ArgumentParser(description=__doc__.splitlines()[0]).parse_args(argv)
    print("| model | seams | start | strain RMS % | / free | held-length error | one-to-one | iterations |")
    print("|---|---|---|---|---|---|---|---|")
    for name, model, index in models():
        panel = model.panels[index]
        v, f, conn = validate_mesh(panel.vertices, panel.faces)
        free, layouts = starts(v, f, conn)
        base = strain_rms(v, f, free.uv)
        greedy_ok = patterns.overlap_verdict(layouts["greedy"][0], f, conn.loops).one_to_one
        print(f"| {name} | free | free optimum | {100 * base:.4f} | 1 | - | yes | {free.iterations} |")
        for mode in (SeamLengths.TOTAL, SeamLengths.TRUE):
            held = held_lengths(model, index, v, {}, mode, mesh_edges=unique_edges(f))
            for start, (uv, barrier) in layouts.items():
                if start == "greedy" and not greedy_ok:
                    continue
                r = relax.relax(v, f, conn, np.array(uv), lengths=held, tolerance=1e-9, max_iterations=5000,
                                barrier=barrier)
                rms = strain_rms(v, f, r.uv)
                ok = patterns.overlap_verdict(r.uv, f, conn.loops).one_to_one
                print(f"| {name} | {mode.value} | {start} | {100 * rms:.4f} | {rms / base:.4f} | "
                      f"{r.length_error:.1e} | {'yes' if ok else 'no'} | {r.iterations} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
