"""Nesting on sparrow against the previous nester, side by side on the same pieces (issue 22).

The marker of the issue: four pieces of every panel of the cup, duct and hopper samples (36
pieces) on a 1500 mm roll with a 10 mm gap, turned by multiples of 90 degrees; then the same with
the grain kept along the roll (0 or 180 degrees); then spyrrow alone on the same outlines and budget
(what the budget's set-up costs); then the same 36 on 2500 x 1250 mm sheets, on stock of several sizes,
and on a strip as wide as the sheets (the sheets a strip cut to length would take).
The previous nester (bottom-left, largest first, shapely collision tests; removed by issue 22) is
read from git at the commit given (``--old``, default 5138836, the last commit that had it) and run
on the same pieces; each marker is checked with shapely (every gap kept, nothing off the roll).
Sparrow searches anew every time (``cache=False``): what is timed is the search, and the "rerun"
column says whether a second search, same seed and budget, stopped at the same marker.

    python benchmarks/nesting.py [--old COMMIT] [--budget S ...] [--no-old]
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time
import types
from importlib.metadata import version
from pathlib import Path

import numpy as np
import shapely

import patterns
from patterns.pattern import Pattern

REPO = Path(__file__).resolve().parent.parent
SAMPLES = REPO / "samples"


def parts():
    return [patterns.flatten(patterns.load(SAMPLES / f"{n}.step")) for n in ("cup", "duct_transition", "hopper")]


def old_nester(commit: str):
    """The bottom-left nester as it was at ``commit``, as a module."""
    text = subprocess.run(["git", "show", f"{commit}:patterns/nesting.py"], cwd=REPO, capture_output=True, text=True,
                          check=True).stdout
    text = text.replace("from .errors", "from patterns.errors").replace("from .options", "from patterns.options") \
        .replace("from .predicates", "from patterns.predicates")
    module = types.ModuleType("old_nesting")
    sys.modules["old_nesting"] = module  # dataclasses look their module up
    exec(compile(text, f"{commit}:patterns/nesting.py", "exec"), module.__dict__)  # noqa: S102 - our own history
    return module


def outlines(nest) -> list:
    """The placed outlines of a nest: sparrow's pieces, or the previous nester's laid-out pattern's panels."""
    if hasattr(nest, "pieces"):
        return [shapely.Polygon(p.outline.points()) for p in nest.pieces]
    return [shapely.Polygon(f.uv[f.loops[0]]) for f in nest.pattern.panels]


def checked_gap(polys, gap: float, width: float) -> float:
    """The least distance between two placed outlines, after checking every piece lies on the roll."""
    x = np.concatenate([np.asarray(p.exterior.coords)[:, 0] for p in polys])
    assert x.min() >= -1e-6 and x.max() <= width + 1e-6
    tree = shapely.STRtree(polys)
    a, b = tree.query(polys, predicate="dwithin", distance=gap * 2)
    d = min((polys[i].distance(polys[j]) for i, j in zip(a, b) if i < j), default=float("inf"))
    assert d >= gap - 1e-6, d
    return d


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--old", default="5138836", help="the commit whose bottom-left nester to run beside")
    parser.add_argument("--budget", type=int, nargs="+", default=[10, 30], help="sparrow's time budgets, s")
    parser.add_argument("--no-old", action="store_true", help="leave the previous nester out (it takes a minute)")
    parser.add_argument("--orders", action="store_true", help="only: spyrrow alone on the 36 pieces in three "
                                                               "orders, seeds 0-2 (does the order of items matter?)")
    args = parser.parse_args(argv)
    base = parts()
    if args.orders:
        print("| seed | four in a row | patterns.layout's order | one item, demand 4 |\n|---|---|---|---|")
        for seed in range(3):
            lengths = [sparrow_alone(base, args.budget[0], seed=seed, order=o)[0] for o in ("rows", "layout", "demand")]
            print(f"| {seed} | " + " | ".join(f"{x:.1f}" for x in lengths) + " |", flush=True)
        return 0
    combined = Pattern.combined(base)  # the previous nester took one pattern
    four = combined.with_copies([4] * len(combined.panels))
    print(f"36 pieces ({len(combined.panels)} panels x 4), area {sum(f.area for f in four.panels) / 1e6:.3f} m^2; "
          f"roll 1500 mm, gap 10 mm\n")
    print("| nester | turns | budget s | roll used mm | efficiency | seconds | least gap mm | rerun |")
    print("|---|---|---|---|---|---|---|---|")
    rows = {}
    if not args.no_old:
        old = old_nester(args.old)
        for turns, grain in (("quarter", False), ("grain", True)):
            start = time.perf_counter()
            nest = old.layout(four, width=1500.0, gap=10.0, allow_rotation=True, respect_grain=grain)
            seconds = time.perf_counter() - start
            gap = checked_gap(outlines(nest), 10.0, 1500.0)
            rows[("old", turns)] = (nest.length, seconds)
            print(f"| bottom-left ({args.old}) | {turns} | - | {nest.length:.1f} | {nest.efficiency:.3f} | "
                  f"{seconds:.1f} | {gap:.2f} | - |", flush=True)
    for turns in ("quarter", "grain"):
        for budget in args.budget:
            runs = []
            for _ in range(2):
                start = time.perf_counter()
                nest = patterns.layout(base, width=1500.0, gap=10.0, copies=4, rotations=turns, time_limit=budget,
                                       cache=False)  # the search itself, timed; the rerun, searched anew
                runs.append((nest, time.perf_counter() - start))
            nest, seconds = runs[0]
            gap = checked_gap(outlines(nest), 10.0, 1500.0)
            same = "same" if runs[1][0].length == nest.length else f"{runs[1][0].length:.1f}"
            old = rows.get(("old", turns))
            vs = f" ({nest.length / old[0] - 1:+.1%} length, {seconds / old[1]:.2f}x time)" if old else ""
            print(f"| sparrow{vs} | {turns} | {budget} | {nest.length:.1f} | {nest.efficiency:.3f} | {seconds:.1f} | "
                  f"{gap:.2f} | {same} |", flush=True)
    budget = args.budget[0]
    print(f"\nsparrow alone (spyrrow {version('spyrrow')} in this process, the same outlines and strip as "
          f"patterns.layout gives it, quarter turns), {budget} s, against patterns.layout's {budget} s budget "
          f"(making the pieces and sparrow's set-up inside it):\n")
    print("| nester | budget s | roll used mm | seconds |")
    print("|---|---|---|---|")
    length, seconds = sparrow_alone(base, budget)
    print(f"| spyrrow alone | {budget} | {length:.1f} | {seconds:.1f} |")
    start = time.perf_counter()
    nest = patterns.layout(base, width=1500.0, gap=10.0, copies=4, rotations="quarter", time_limit=budget,
                           cache=False)
    print(f"| patterns.layout ({nest.length / length - 1:+.1%} length) | {budget} | {nest.length:.1f} | "
          f"{time.perf_counter() - start:.1f} |", flush=True)
    print("\nsheets, the same 36 pieces, turned by multiples of 90 degrees, against sparrow's strip as wide as the "
          "sheet (its length over the sheet's: the sheets a strip cut to length would take, a bound no sheet "
          "nest beats):\n")
    print("| stock | budget s | sheets | usage, sheet by sheet | in all | seconds | strip 1250 mm: length, sheets |")
    print("|---|---|---|---|---|---|---|")
    strip = patterns.layout(base, width=1250.0, gap=10.0, copies=4, rotations="quarter", time_limit=budget,
                            cache=False)
    for stock, label in (((2500.0, 1250.0), "2500 x 1250"),
                         ([(2500.0, 1250.0), (1250.0, 1250.0)], "2500 x 1250 and 1250 x 1250 remnants"),
                         ([(2500.0, 1250.0), (1250.0, 1250.0, 1), (800.0, 1250.0, 2)],
                          "2500 x 1250, one 1250 x 1250 and two 800 x 1250 on hand")):
        start = time.perf_counter()
        nest = patterns.layout(base, sheet=stock, gap=10.0, copies=4, rotations="quarter", time_limit=budget,
                               cache=False)
        seconds = time.perf_counter() - start
        gap = checked_gap(outlines(nest), 10.0, 1250.0)
        assert gap >= 10.0 - 1e-6
        print(f"| {label} | {budget} | {len(nest.sheets)} | "
              + ", ".join(f"{s.usage:.1%} ({len(s.pieces)} on {s.size[0]:g})" for s in nest.sheets)
              + f" | {nest.efficiency:.1%} | {seconds:.1f} | {strip.length:.1f} mm, {strip.length / 2500.0:.2f} |",
              flush=True)
    return 0


def sparrow_alone(base, budget: int, *, seed: int = 0, order: str = "rows") -> tuple:
    """``(strip length used mm, seconds)``: spyrrow itself on the outlines patterns.layout hands it (the 36 pieces
    on the 1500 mm roll, 10 mm gap, quarter turns), one worker, in this process; ``order``: each piece four
    times in a row (``rows``), each piece then the copies as layout gives them (``layout``), or each piece
    one item of demand 4 (``demand``)."""
    import spyrrow

    from patterns.nesting import SIMPLIFY, _item_points, _outline
    from patterns.pieces import pieces_of

    base_pieces = pieces_of(base)
    pieces = ([p for p in base_pieces for _ in range(4)] if order == "rows" else
              [p for _ in range(4) for p in base_pieces] if order == "layout" else list(base_pieces))
    items = [spyrrow.Item(str(k), [tuple(q) for q in _item_points(_outline(p, 0.0))],
                          demand=4 if order == "demand" else 1, allowed_orientations=[0.0, 90.0, 180.0, 270.0])
             for k, p in enumerate(pieces)]
    edge = 10.0 + SIMPLIFY
    instance = spyrrow.StripPackingInstance("alone", strip_height=1500.0 + 2 * edge, items=items)
    config = spyrrow.StripPackingConfig(early_termination=True, total_computation_time=budget,
                                        min_items_separation=10.0, seed=seed, num_workers=1)
    start = time.perf_counter()
    solution = instance.solve(config)
    seconds = time.perf_counter() - start
    far = 0.0  # as patterns.layout measures the roll used: to the furthest outline's end, from the roll's start
    for item in solution.placed_items:
        pts = np.array(items[int(item.id)].shape)  # a demand-4 item's copies share its id
        turn = np.radians(item.rotation)
        x = pts[:, 0] * np.cos(turn) - pts[:, 1] * np.sin(turn) + item.translation[0]
        far = max(far, float(x.max()))
    return far - edge - SIMPLIFY, seconds


if __name__ == "__main__":
    sys.exit(main())
