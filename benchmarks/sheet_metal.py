"""Sheet metal: our unfold of the four shared parts against SolidWorks' flat patterns (and FreeCAD's SheetMetal).

Run from the repository root, with ``../shared/sheetmetal`` beside it::

    python benchmarks/sheet_metal.py [--freecad /tmp/freecad_flat]

For each part: area, outer perimeter, holes and bend lines of our blank beside
SolidWorks' DXF, the outline's Hausdorff distance after the best rigid alignment,
the share of the outline within 0.1 mm, and the unfold time (best of three, from the
shape in memory: the STEP file read before, as FreeCAD's time is taken).
With ``--freecad DIR`` (the output of ``benchmarks/freecad_sheetmetal.py``), FreeCAD
SheetMetal's flat patterns are compared with SolidWorks' by the same code, and its
unfold time (from its JSON) is set beside ours as a ratio.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import patterns
from patterns.reading import read_cad

SHEETMETAL = Path(__file__).resolve().parent.parent.parent / "shared" / "sheetmetal"
K = 0.47


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--freecad", type=Path, default=None, help="folder of FreeCAD SheetMetal flat patterns")
    args = parser.parse_args(argv)
    if not SHEETMETAL.is_dir():
        print(f"{SHEETMETAL} is absent", file=sys.stderr)
        return 2
    print("| part | who | area mm² (vs SolidWorks) | outer perimeter mm (vs SW) | holes | bend lines | "
          "outline Hausdorff mm | outline within 0.1 mm | unfold s |")
    print("|---|---|---|---|---|---|---|---|---|")
    for step in sorted(SHEETMETAL.glob("*.STEP")):
        reference = patterns.read_flat_pattern(step.with_suffix(".DXF"))
        shape = read_cad(step)  # read once: both unfolders are timed from the shape in memory
        times = []
        for _ in range(3):
            start = time.perf_counter()
            blank = patterns.unfold(shape, k_factor=K, name=step.stem)
            times.append(time.perf_counter() - start)
        rows = [("patterns", patterns.compare_blank(blank, reference), min(times))]
        if args.freecad is not None and (args.freecad / f"{step.stem}.dxf").is_file():
            info = json.loads((args.freecad / f"{step.stem}.json").read_text())
            rows.append(("FreeCAD SheetMetal", patterns.compare_blank(args.freecad / f"{step.stem}.dxf", reference),
                         info.get("seconds")))
        for who, c, seconds in rows:
            ratio = "" if who == "patterns" or not seconds else f" ({seconds / rows[0][2]:.1f}x ours)"
            print(f"| {step.stem} | {who} | {c.area:.1f} ({c.area_error:+.3%}) | {c.perimeter:.2f} "
                  f"({c.perimeter - c.perimeter_reference:+.2f}) | {c.holes}/{c.holes_reference} | "
                  f"{c.bend_lines}/{c.bend_lines_reference} | {c.hausdorff:.3f} | {c.within:.1%} | "
                  f"{seconds if seconds is None else f'{seconds:.2f}'}{ratio} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
