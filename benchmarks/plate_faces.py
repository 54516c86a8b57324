"""Unfold time against the face count: flat 2 mm plates with a grid of Ø 5 mm holes, beside FreeCAD SheetMetal.

Run from the repository root::

    python benchmarks/plate_faces.py [--holes 32 71 141] [--workbench /tmp/FreeCAD_SheetMetal]

Each plate is n x n holes on a 10 mm pitch (n = 32, 71, 141: 1,030, 5,047 and 19,887 faces), built
with OpenCascade directly (one planar face with n² circular holes, extruded) and written as STEP into a
temporary folder.  For each it prints the faces, the file's size, and ours: the STEP read
(``patterns.reading.read_cad``), the unfold from the shape in memory (``patterns.unfold``), the
whole ``patterns unfold plate.step -o blank.dxf`` as a user runs it (a fresh process: reading,
unfolding, labels, DXF); the blank's area against the plate's own (n² holes out of the square, exact).
With ``--workbench`` (FreeCAD SheetMetal checked out, see ``benchmarks/freecad_sheetmetal.py``) FreeCAD's
unfolder runs on the same files in ``freecadcmd``: its unfold's wall time alone, from the shape
FreeCAD imported, and the ratio of ours (the unfold alone) to it.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

PITCH, RADIUS, THICKNESS = 10.0, 2.5, 2.0


def plate(n: int, path: Path) -> None:
    """Write the plate of ``n`` x ``n`` holes to ``path`` (STEP, mm): ``patterns.samples.holed_plate``."""
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

    from patterns.samples import holed_plate

    writer = STEPControl_Writer()
    writer.Transfer(holed_plate(n, pitch=PITCH, radius=RADIUS, thickness=THICKNESS), STEPControl_AsIs)
    writer.Write(str(path))


def ours(path: Path) -> dict:
    """Our read, unfold and whole command's times, s, and the blank's area against the plate's."""
    import patterns
    from patterns.reading import read_cad

    start = time.perf_counter()
    shape = read_cad(path)
    read = time.perf_counter() - start
    start = time.perf_counter()
    blank = patterns.unfold(shape, name=path.stem)
    unfold = time.perf_counter() - start
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "patterns", "unfold", str(path), "-o", str(path.with_suffix(".dxf"))],
                   check=True, capture_output=True)
    command = time.perf_counter() - start
    n = int(path.stem.removeprefix("plate"))
    exact = (n * PITCH) ** 2 - n * n * np.pi * RADIUS ** 2
    return {"read": read, "unfold": unfold, "command": command, "holes": len(blank.holes),
            "area_error": (blank.area - exact) / exact}


def freecad(path: Path, workbench: Path) -> dict:
    """FreeCAD SheetMetal's unfold of ``path`` (``benchmarks/freecad_sheetmetal.py``'s run of one part)."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from freecad_sheetmetal import _run

    return _run(path, workbench.resolve(), 0.5)


def ratio(ours_s: float, theirs_s: float | None) -> str:
    """``ours / theirs`` as ``0.42``, or empty without their time."""
    return f"{ours_s / theirs_s:.2f}" if theirs_s else ""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--holes", type=int, nargs="+", default=[32, 71, 141], help="holes along a side, per plate")
    parser.add_argument("--workbench", type=Path, default=None, help="FreeCAD SheetMetal checked out here")
    args = parser.parse_args()
    print("| faces | STEP MB | our read s | our unfold s | `patterns unfold` s | holes | area vs exact "
          "| FreeCAD SheetMetal unfold s | ours / FreeCAD |")
    print("|---|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for n in args.holes:
            path = Path(tmp) / f"plate{n}.step"
            plate(n, path)
            got = ours(path)
            theirs = freecad(path, args.workbench) if args.workbench else {}
            fc = theirs.get("seconds")
            print(f"| {n * n + 6} | {path.stat().st_size / 1e6:.1f} | {got['read']:.1f} | {got['unfold']:.1f} "
                  f"| {got['command']:.1f} | {got['holes']} | {got['area_error']:+.1e} "
                  f"| {f'{fc:.1f}' if fc is not None else theirs.get('error', '')} "
                  f"| {ratio(got['unfold'], fc)} |", flush=True)
            if theirs:
                theirs.pop("loops", None)
                print(json.dumps({k: v for k, v in theirs.items() if k != "bend_lines"}), file=sys.stderr)


if __name__ == "__main__":
    main()
