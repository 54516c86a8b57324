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
saddle, an asymmetric freeform cup and bag), each three ways: darts on the one
panel only (``max_gores=0``; inserts on the saddle); as ``flatten(max_strain=...)``
does by default (darts, and where they fall short the panel parted into pieces
with darts, or else gores: ``patterns.flattening.parted``); in gores (at most
``max_gores``, 24). Columns: the worst and RMS strain, the darts' total 3D
length or the piece count, whether the limit was met, the largest difference
between the two flat sides of a seam the limit cut, and the time against the
dartless flattening.

    python benchmarks/darts.py [--limit 0.03] [--shapes [--shape NAME ...]]
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
    parser.add_argument("--shape", action="append", choices=list(samples.DOMES),
                        help="with --shapes: only this face (repeatable)")
    args = parser.parse_args(argv)
    limit = args.limit
    print(f"strain limit {limit:.1%}\n")
    if args.shapes:
        return shapes(limit, args.shape)
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


def _cuts(pattern) -> str:
    """What the strain limit cut: darts (per piece where the panel was parted), inserts, or gores."""
    inserts = sum(p.panel.insert_into is not None for p in pattern.panels)
    darts = [len(p.darts) for p in pattern.panels if p.panel.insert_into is None]
    with_inserts = f"{inserts} insert{'' if inserts == 1 else 's'}" if inserts else ""
    if len(darts) == 1:
        return with_inserts or f"{darts[0]}"
    kind = f"pieces: {' + '.join(map(str, darts))}" if any(darts) else "pieces" if inserts else "gores"
    return f"{len(darts)} {kind}" + (f", {with_inserts}" if inserts else "")


def _sides(pattern, model) -> float:
    """The largest difference between the two flat sides of a seam the limit cut, mm."""
    new = pattern.seams[len(model.seams):]
    return max((abs(fs.flat_lengths[0] - fs.flat_lengths[1]) for fs in new), default=0.0)


def shapes(limit: float, only=None) -> int:
    """The table of docs/garments.md "On other curved shapes": each face with darts on the one panel only
    (``max_gores=0``), as ``flatten(max_strain=...)`` does by default (parted into pieces with darts, or
    gores, where darts alone fall short), and in gores."""
    print("| shape | triangles | worst, no darts | gore bound | darts, one panel | worst | time "
          "| default: cut | worst | RMS | dart length | sides differ by | met | time | / dartless "
          "| gores | worst | sides differ by | met | time |")
    print("|---|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|---|---:|")
    for name, make in samples.DOMES.items():
        if only and name not in only:
            continue
        model = patterns.load(make())
        plain, t_plain = timed(partial(patterns.flatten, model))
        alone, t_alone = timed(partial(patterns.flatten, model, max_strain=limit, max_gores=0))
        darted, t_darts = timed(partial(patterns.flatten, model, max_strain=limit))
        gored, t_gores = timed(partial(patterns.flatten, model, max_strain=limit, gores=True))
        darts = [d for p in darted.panels for d in p.darts]
        rms = max(strain_rms(p.vertices, p.faces, p.uv) for p in darted.panels)
        after, in_gores = worst_of(darted), worst_of(gored)
        bound = max(_bound(p.flattening, limit) for p in plain.panels)
        n = sum(len(p.faces) for p in model.panels)
        print(f"| {name} | {n:,} | {worst_of(plain):.1%} | {bound} | {_cuts(alone)} | {worst_of(alone):.2%} "
              f"| {t_alone:.1f} s | {_cuts(darted)} | {after:.2%} | {rms:.2%} "
              f"| {sum(d.length_3d for d in darts):,.0f} mm | {_sides(darted, model):.3f} mm "
              f"| {'yes' if after <= limit else 'no'} | {t_darts:.1f} s | {t_darts / t_plain:.0f} x "
              f"| {len(gored.panels)} | {in_gores:.2%} | {_sides(gored, model):.3f} mm "
              f"| {'yes' if in_gores <= limit else 'no'} | {t_gores:.1f} s |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
