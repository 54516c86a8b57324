"""Sheet metal: our unfold of the four shared parts against SolidWorks' flat patterns (and FreeCAD's SheetMetal).

Run from the repository root, with ``../shared/sheetmetal`` beside it::

    python benchmarks/sheet_metal.py [--freecad /tmp/freecad_flat]
    python benchmarks/sheet_metal.py --folder DIR --material openamr-steel \
        --material-table benchmarks/openamr_materials.csv       # every NAME.STEP with a NAME.DXF in DIR

``--material`` gives each bend the K-factor of the table's row for its thickness and r/t (the OpenAMR
table: 0.47 as the robot's BOM states, 0.40 below r/t 1, where the Center bracket's flat pattern, R 1.5 in
2 mm sheet, was made); without it every part is unfolded at K = 0.47.

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

import build123d as bd

import patterns
from patterns.reading import read_cad

SHEETMETAL = Path(__file__).resolve().parent.parent.parent / "shared" / "sheetmetal"
K = 0.47


def _reference(path):
    """SolidWorks' flat pattern; one whose export left a contour open is read with that contour left out."""
    try:
        return patterns.read_flat_pattern(path)
    except patterns.InputError as exc:
        if "does not close" not in str(exc):
            raise
        print(f"({exc}: read with the open contour left out)", file=sys.stderr)
        return patterns.read_flat_pattern(path, open_contours="leave-out")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--freecad", type=Path, default=None, help="folder of FreeCAD SheetMetal flat patterns")
    parser.add_argument("--folder", type=Path, default=SHEETMETAL, help="folder of NAME.STEP and NAME.DXF pairs")
    parser.add_argument("--material", default=None, help="material name (with --material-table)")
    parser.add_argument("--material-table", default=None, help="material table CSV")
    args = parser.parse_args(argv)
    if not args.folder.is_dir():
        print(f"{args.folder} is absent", file=sys.stderr)
        return 2
    options = {"material": args.material, "material_table": args.material_table} if args.material else \
        {"k_factor": K}
    print("| part | who | faces | area mm² (vs SolidWorks) | outer perimeter mm (vs SW) | holes | bend lines | "
          "outline Hausdorff mm | outline within 0.1 mm | unfold s |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for step in sorted(args.folder.glob("*.STEP")):
        if not step.with_suffix(".DXF").is_file():
            continue
        reference = _reference(step.with_suffix(".DXF"))
        shape = read_cad(step)  # read once: both unfolders are timed from the shape in memory
        faces = len(bd.Shape(shape).faces())
        times = []
        for _ in range(3):
            start = time.perf_counter()
            blank = patterns.unfold(shape, name=step.stem, **options)
            times.append(time.perf_counter() - start)
        rows = [("patterns", patterns.compare_blank(blank, reference), min(times))]
        if args.freecad is not None and (args.freecad / f"{step.stem}.dxf").is_file():
            info = json.loads((args.freecad / f"{step.stem}.json").read_text())
            rows.append(("FreeCAD SheetMetal", patterns.compare_blank(args.freecad / f"{step.stem}.dxf", reference),
                         info.get("seconds")))
        for who, c, seconds in rows:
            ratio = "" if who == "patterns" or not seconds else f" ({seconds / rows[0][2]:.1f}x ours)"
            print(f"| {step.stem} | {who} | {faces} | {c.area:.1f} ({c.area_error:+.3%}) | {c.perimeter:.2f} "
                  f"({c.perimeter - c.perimeter_reference:+.2f}) | {c.holes}/{c.holes_reference} | "
                  f"{c.bend_lines}/{c.bend_lines_reference} | {c.hausdorff:.3f} | {c.within:.1%} | "
                  f"{seconds if seconds is None else f'{seconds:.2f}'}{ratio} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
