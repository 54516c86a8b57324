"""The sheet-metal torture set: ``patterns.unfold`` on each part, beside FreeCAD SheetMetal's unfolder.

Run from the repository root::

    python benchmarks/torture.py [--freecad /tmp/torture_freecad]

The parts are ``tests/data/torture/*.step`` (provenance, licence and what each
part tests in its ``PROVENANCE.md`` and ``parts.csv``), each unfolded with the K-factor
``parts.csv`` gives (0.44 for the Fusion 360 parts: the K-factor their own flat patterns were made with;
0.5 where the source names none).
Prints one markdown row per part: its faces, our result (the blank's size, bends, holes and
findings, or the one-line error), our blank's area against an independent reference (the
flat pattern Fusion 360 drew for the same part, in the source repository; the plate face's
area for a flat plate; else the solid's volume over the thickness, which is the blank's area
at K = 0.5 and is compared with a second unfold at K = 0.5), and the time of the
unfold (best of three, from the shape in memory, as FreeCAD's is taken).  With ``--freecad
DIR`` (the output of ``benchmarks/freecad_sheetmetal.py --parts tests/data/torture``, each
part at its own K-factor from ``parts.csv``) FreeCAD SheetMetal's result on the same part is set beside ours, measured
against the same reference.
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
import time
from pathlib import Path

import patterns
from patterns.errors import PatternsError
from patterns.reading import read_cad
from patterns.text import counted

TORTURE = Path(__file__).resolve().parent.parent / "tests" / "data" / "torture"


def parts(folder: Path = TORTURE) -> list:
    """The rows of ``parts.csv``: ``part``, ``source_cad``, ``origin``, ``k_factor``, ``reference``, ``tests``."""
    with open(folder / "parts.csv", newline="") as f:
        return list(csv.DictReader(f))


def reference_area(folder: Path, row: dict, thickness: float | None) -> tuple:
    """``(area mm², what it is)`` of the part's independent reference, or ``(None, "")``."""
    from build123d import import_step

    kind = row["reference"]
    if kind.endswith(".dxf"):
        return patterns.read_flat_pattern(folder / kind).area, "Fusion 360 flat pattern"
    if kind == "face":  # a flat plate: its largest face is the blank
        return max(f.area for f in import_step(folder / f"{row['part']}.step").faces()), "plate face"
    if kind == "volume" and thickness:  # the mid-surface's area: the blank's at K = 0.5
        return import_step(folder / f"{row['part']}.step").volume / thickness, "volume / t (the K 0.5 blank's)"
    return None, ""


def _against(area, reference) -> str:
    return "" if area is None or reference is None else f"{area:.1f} ({(area - reference) / reference:+.3%})"


def ours(step: Path, k_factor: float) -> tuple:
    """``(blank or None, one-line result, best of three seconds or None, faces)``."""
    try:
        shape = read_cad(step)
    except PatternsError as exc:
        return None, f"{type(exc).__name__}: {exc}", None, 0
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer

    explorer, faces = TopExp_Explorer(shape, TopAbs_FACE), 0
    while explorer.More():
        faces += 1
        explorer.Next()
    times, blank = [], None
    for _ in range(3):
        start = time.perf_counter()
        try:
            blank = patterns.unfold(shape, k_factor=k_factor, name=step.stem)
        except PatternsError as exc:
            return None, f"{type(exc).__name__}: {exc}", None, faces
        times.append(time.perf_counter() - start)
    w, h = blank.size
    found = sorted({f.code.value if hasattr(f.code, "value") else str(f.code) for f in blank.findings})
    text = (f"unfolds: {w:.1f} x {h:.1f} mm, {counted(len(blank.bends), 'bend')}, {counted(len(blank.holes), 'hole')}"
            + (f"; {', '.join(found)}" if found else "") + ("" if blank.ok else "; NOT OK"))
    return blank, text, min(times), faces


def freecad(folder: Path | None, stem: str) -> tuple:
    """``(area or None, one-line result, seconds or None)`` from ``benchmarks/freecad_sheetmetal.py``'s output."""
    if folder is None or not (folder / f"{stem}.json").is_file():
        return None, "", None
    info = json.loads((folder / f"{stem}.json").read_text())
    if not info.get("ok"):
        return None, " ".join(str(info.get("error", "failed")).split()), None
    flat = patterns.read_flat_pattern(folder / f"{stem}.dxf")
    xs, ys = flat.outline[:, 0], flat.outline[:, 1]
    text = (f"unfolds: {xs.max() - xs.min():.1f} x {ys.max() - ys.min():.1f} mm, "
            f"{counted(info.get('bend_lines', 0), 'bend line')}, {counted(len(flat.holes), 'hole')}")
    return flat.area, text, info.get("seconds")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--freecad", type=Path, default=None, help="FreeCAD SheetMetal's results on the same parts")
    parser.add_argument("--parts", type=Path, default=TORTURE, help="the torture set's folder")
    args = parser.parse_args(argv)
    print("| part | source CAD | faces | ours | ours vs reference, mm² | ours ms | FreeCAD SheetMetal | "
          "FreeCAD vs reference, mm² | FreeCAD ms | reference |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for row in parts(args.parts):
        step = args.parts / f"{row['part']}.step"
        blank, text, seconds, faces = ours(step, float(row["k_factor"]))
        reference, what = reference_area(args.parts, row, blank.thickness if blank else None)
        fc_area, fc_text, fc_seconds = freecad(args.freecad, row["part"])
        area = blank.area if blank else None
        if blank and row["reference"] == "volume":  # FreeCAD ran at the part's K-factor: no like for like
            area, fc_area = patterns.unfold(step, k_factor=0.5).area, None
        ms = "" if seconds is None else f"{seconds * 1e3:.0f}"
        fc_ms = "" if fc_seconds is None else f"{fc_seconds * 1e3:.0f}"
        print(f"| {row['part']} | {row['source_cad']} | {faces} | {text} | "
              f"{_against(area, reference)} | {ms} | {fc_text} | "
              f"{_against(fc_area, reference)} | {fc_ms} | {what + (f' {reference:.1f}' if reference else '')} |",
              flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
