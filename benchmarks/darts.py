"""Darts at a strain limit: how many, how long against the gore bound, how strained, how fast (issue 18).

For each dome: the worst triangle strain without darts, then with
``flatten(max_strain=...)``: darts, worst triangle and RMS strain (area-weighted
principal strains), the darts' total 3D length against the gore bound of a
sphere of the same radius (docs/garments.md: a gore ``4 sqrt(limit)`` rad
wide, each running a quarter meridian), the largest difference between a
dart's two legs, and the time as a ratio to peers run side by side on the same
mesh: our own dartless flattening and libigl's ARAP (``bench_flatten.igl_arap``,
a single-panel flattening with no limit; there is no open dart tool to race).

* ``hemisphere``: one build123d spherical face, R 150 mm, as ``patterns.load``
  meshes it (4,924 triangles);
* ``hemisphere 10k``: ``surfaces.spherical_cap`` at R 150 mm, 10k triangles;
* ``cup``: ``samples/cup.step``, four quarter-sphere gores of R 100 mm;
* ``four gores``: the R 150 hemisphere cut into four quarter gores in build123d.

Then (``--shapes``, issue 36) the curved faces of ``patterns.samples.DOMES``
(a spline bowl, oblate and prolate domes, an ellipsoid, a torus patch, a
saddle, an asymmetric freeform cup), each with darts (inserts on the saddle)
and then in gores (at most ``max_gores``, 24, the default): the worst and RMS strain, the darts'
total 3D length or the gore count, whether the
limit was met, the largest difference between the two flat sides of a gore
seam, and the time against the dartless flattening.

    python benchmarks/darts.py [--limit 0.03] [--shapes]
"""

from __future__ import annotations

import argparse
import sys
import time
from functools import partial
from pathlib import Path

import build123d as bd
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench_flatten as bench  # libigl's ARAP, as the flattening benchmark runs it

import patterns
from patterns import samples, surfaces
from patterns.flattening.curvature import gore_bound as curvature_bound
from patterns.flattening.inserts import is_saddle
from patterns.measure import angle_defects, strain_rms, triangle_strains
from patterns.reading import mesh_model

REPO = Path(__file__).resolve().parent.parent


def domes():
    """``(name, model, sphere radius mm)``."""
    half = bd.Sphere(150.0, arc_size1=0)
    (face,) = [f for f in half.faces() if f.geom_type != bd.GeomType.PLANE]
    quarters = [half & bd.Pos(sx * 200, sy * 200, 0) * bd.Box(400, 400, 400) for sx in (1, -1) for sy in (1, -1)]
    gores = [f for q in quarters for f in q.faces() if f.geom_type != bd.GeomType.PLANE]
    v, f = surfaces.spherical_cap(radius=150.0, half_angle=90.0, n_faces=10_000)
    return [("hemisphere", patterns.load(face), 150.0),
            ("hemisphere 10k", mesh_model(v, f, name="hemisphere 10k"), 150.0),
            ("cup", patterns.load(REPO / "samples" / "cup.step"), 100.0),
            ("four gores", patterns.load(bd.Compound(gores)), 150.0)]


def gore_bound(radius: float, limit: float, share: float = 1.0) -> float:
    """Total gore-seam length a sphere's dome needs at ``limit`` (``share`` of a full hemisphere)."""
    return share * 2 * np.pi / (4 * np.sqrt(limit)) * np.pi * radius / 2


def timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return out, time.perf_counter() - t0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--limit", type=float, default=0.03)
    parser.add_argument("--shapes", action="store_true", help="the curved faces of patterns.samples.DOMES")
    args = parser.parse_args(argv)
    limit = args.limit
    print(f"strain limit {limit:.1%}\n")
    if args.shapes:
        return shapes(limit)
    print("| dome | triangles | worst, no darts | darts | worst | RMS | dart length / gore bound "
          "| legs differ by | time | / dartless | / libigl ARAP |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for name, model, radius in domes():
        plain, t_plain = timed(partial(patterns.flatten, model))
        darted, t_darts = timed(partial(patterns.flatten, model, max_strain=limit))
        t_igl = sum(timed(partial(bench.igl_arap, panel.vertices, panel.faces))[1] for panel in model.panels)
        before = max(triangle_strains(p.vertices, p.faces, p.uv).magnitude.max() for p in plain.panels)
        after = max(triangle_strains(p.vertices, p.faces, p.uv).magnitude.max() for p in darted.panels)
        rms = max(strain_rms(p.vertices, p.faces, p.uv) for p in darted.panels)
        darts = [d for p in darted.panels for d in p.darts]
        length = sum(d.length_3d for d in darts)
        legs = max((abs(np.subtract(*d.leg_lengths(p.uv))) for p in darted.panels for d in p.darts), default=0.0)
        area = sum(p.area for p in model.panels)
        share = area / (2 * np.pi * radius**2)  # of a hemisphere's area
        n = sum(len(p.faces) for p in model.panels)
        print(f"| {name} | {n:,} | {before:.1%} | {len(darts)} | {after:.2%} | {rms:.2%} "
              f"| {length:,.0f} / {gore_bound(radius, limit, share):,.0f} mm "
              f"({length / gore_bound(radius, limit, share):.2f}) | {legs:.3f} mm | {t_darts:.1f} s "
              f"| {t_darts / t_plain:.0f} x | {t_darts / t_igl:.0f} x |", flush=True)
    return 0


def worst_of(pattern) -> float:
    return max(float(triangle_strains(p.vertices, p.faces, p.uv).magnitude.max()) for p in pattern.panels)


def _bound(result, limit: float) -> str:
    """The gore bound of a panel's positive curvature, or of its negative curvature on a saddle (slashes)."""
    if is_saddle(result.vertices, result.faces, result.loops):
        negative = -angle_defects(result.vertices, result.faces, loops=result.loops)
        return f"{curvature_bound(result, limit, defects=negative):.1f} (saddle)"
    return f"{curvature_bound(result, limit):.1f}"


def shapes(limit: float) -> int:
    """The table of docs/garments.md "On other curved shapes"."""
    print("| shape | triangles | worst, no darts | gore bound | darts | worst | RMS | dart length | met | time "
          "| / dartless | up to 24 darts | gores | worst | gore sides differ by | met | time |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|---|---:|---:|---:|---|---:|")
    for name, make in samples.DOMES.items():
        model = patterns.load(make())
        plain, t_plain = timed(partial(patterns.flatten, model))
        darted, t_darts = timed(partial(patterns.flatten, model, max_strain=limit))
        gored, t_gores = timed(partial(patterns.flatten, model, max_strain=limit, gores=True))
        darts = [d for p in darted.panels for d in p.darts]
        inserts = sum(p.panel.insert_into is not None for p in darted.panels)
        rms = max(strain_rms(p.vertices, p.faces, p.uv) for p in darted.panels)
        after, in_gores = worst_of(darted), worst_of(gored)
        bound = max(_bound(p.flattening, limit) for p in plain.panels)
        more = "-"
        if after > limit:  # how many darts it takes where 12 are too few
            many, t_many = timed(partial(patterns.flatten, model, max_strain=limit, max_darts=24))
            n_many = sum(len(p.darts) for p in many.panels)
            more = f"{n_many} dart{'' if n_many == 1 else 's'}, {worst_of(many):.2%}, {t_many:.0f} s"
        new = gored.seams[len(model.seams):]
        sides = max((abs(fs.flat_lengths[0] - fs.flat_lengths[1]) for fs in new), default=0.0)
        n = sum(len(p.faces) for p in model.panels)
        cuts = f"{inserts} insert{'' if inserts == 1 else 's'}" if inserts else f"{len(darts)}"
        print(f"| {name} | {n:,} | {worst_of(plain):.1%} | {bound} | {cuts} | {after:.2%} | {rms:.2%} "
              f"| {sum(d.length_3d for d in darts):,.0f} mm | {'yes' if after <= limit else 'no'} | {t_darts:.1f} s "
              f"| {t_darts / t_plain:.0f} x | {more} | {len(gored.panels)} | {in_gores:.2%} | {sides:.3f} mm "
              f"| {'yes' if in_gores <= limit else 'no'} | {t_gores:.1f} s |", flush=True)
    return 0

if __name__ == "__main__":
    sys.exit(main())
