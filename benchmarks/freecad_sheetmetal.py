"""FreeCAD SheetMetal's unfolder on the shared sheet-metal parts (or any folder of parts), as a peer for ``patterns.unfold``.

Run from the repository root (FreeCAD's ``freecadcmd`` on the PATH, the SheetMetal
workbench checked out, ``../shared/sheetmetal`` beside the repository)::

    apt-get install -y freecad python3-networkx   # the workbench imports networkx
    git clone https://github.com/shaise/FreeCAD_SheetMetal /tmp/FreeCAD_SheetMetal
    git -C /tmp/FreeCAD_SheetMetal checkout cbef3f2
    python benchmarks/freecad_sheetmetal.py --workbench /tmp/FreeCAD_SheetMetal --out /tmp/freecad_flat
    python benchmarks/sheet_metal.py --freecad /tmp/freecad_flat

``--parts DIR`` runs it on every ``*.step``/``*.stp`` in ``DIR`` instead (the torture set:
``--parts tests/data/torture``, then ``benchmarks/torture.py --freecad``); where ``DIR`` holds a
``parts.csv`` with ``part`` and ``k_factor`` columns, each part listed there is unfolded with its own K-factor
(``--k-factor`` is for the rest).

On FreeCAD < 1.0 (Debian 12 packages 0.20.2) the workbench's ``FreeCAD.Base.Precision``
is supplied with OpenCascade's own values (confusion 1e-7, angular 1e-12,
approximation 1e-6), its ``Console.PrintUser*`` calls go to ``PrintError``, and
``Part.sortEdges`` is called without the tolerance 0.20 does not take.  The workbench at
commit cbef3f2 (2025-01-26, when it still ran on FreeCAD 0.21) is the one measured.  For each part, ``freecadcmd`` imports the STEP, picks the largest planar face as the
fixed face and unfolds with the workbench's new unfolder (``SheetMetalNewUnfolder.unfold``,
K = 0.47, ANSI); this script writes what it returns as ``<out>/<part>.dxf`` (the cut
contours on CUT, sampled within 0.001 mm; the bend lines on BEND) and
``<out>/<part>.json`` (the unfold's wall time alone, the versions, the bend count, or the
error, as one line: the exception FreeCAD raised, "no result: " and the last line FreeCAD printed when it
stopped without one, or "timed out after N s").  ``benchmarks/sheet_metal.py --freecad`` then compares these files
with SolidWorks' flat patterns by the same code as ours.
"""

from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

SHEETMETAL = Path(__file__).resolve().parent.parent.parent / "shared" / "sheetmetal"
SUFFIXES = (".step", ".stp")
TIMEOUT = 600
"""Seconds one part may take in ``freecadcmd``."""

INSIDE_FREECAD = r'''
import json, sys, time
sys.path.insert(0, WORKBENCH)
import FreeCAD, Part
if not hasattr(FreeCAD.Base, "Precision"):  # FreeCAD < 1.0 (Debian 12 has 0.20): OpenCascade's own tolerances
    class Precision:
        approximation = staticmethod(lambda: 1e-6)
        angular = staticmethod(lambda: 1e-12)
        confusion = staticmethod(lambda: 1e-7)
    FreeCAD.Base.Precision = Precision
for name in ("PrintUserError", "PrintUserWarning", "PrintTranslatedUserError", "PrintTranslatedUserWarning"):
    if not hasattr(FreeCAD.Console, name):  # FreeCAD < 0.21
        setattr(FreeCAD.Console, name, lambda *args: FreeCAD.Console.PrintError(str(args[-1])))
_sort_edges = Part.sortEdges
def _sort_edges_any(edges, *tolerance):  # FreeCAD < 1.0 takes no tolerance
    try:
        return _sort_edges(edges, *tolerance)
    except Exception:
        return _sort_edges(edges)
Part.sortEdges = _sort_edges_any
import SheetMetalNewUnfolder as smu
out = {"freecad": ".".join(FreeCAD.Version()[:3])}
try:
    shape = Part.read(STEP)
    planes = [i for i, f in enumerate(shape.Faces) if f.Surface.__class__.__name__ == "Plane"]
    root = max(planes, key=lambda i: shape.Faces[i].Area)
    bac = smu.BendAllowanceCalculator.from_single_value(K, "ansi")
    start = time.perf_counter()
    lines, bends = smu.unfold(shape, root, bac)
    out["seconds"] = time.perf_counter() - start
    move = smu.SketchExtraction.move_to_origin(Part.makeCompound(lines), shape.Faces[root])
    lines = [e.transformed(move) for e in lines]
    wires = smu.Edge2DCleanup.clean_and_structure_geometry(lines)
    face = Part.makeFace(wires, "Part::FaceMakerBullseye")
    out["loops"] = [[[p.x, p.y] for p in w.discretize(Deflection=0.001)] for w in face.Wires]
    out["bend_lines"] = [[[v.Point.x, v.Point.y] for v in getattr(b, "line", b).transformed(move).Vertexes]
                         for b in bends]
    out["ok"] = True
except Exception as exc:
    out.update(ok=False, error=" ".join(f"{type(exc).__name__}: {exc}".split()))
print("RESULT " + json.dumps(out))
'''


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workbench", type=Path, required=True, help="a checkout of FreeCAD_SheetMetal")
    parser.add_argument("--out", type=Path, required=True, help="folder for the flat patterns (made if missing)")
    parser.add_argument("--k-factor", type=float, default=0.47)
    parser.add_argument("--parts", type=Path, default=SHEETMETAL,
                        help="folder of STEP parts (default: ../shared/sheetmetal)")
    args = parser.parse_args(argv)
    if shutil.which("freecadcmd") is None:
        print("freecadcmd is not on the PATH (Debian: apt-get install freecad)", file=sys.stderr)
        return 2
    if not (args.workbench / "SheetMetalNewUnfolder.py").is_file():
        print(f"{args.workbench}: not a FreeCAD_SheetMetal checkout (no SheetMetalNewUnfolder.py)", file=sys.stderr)
        return 2
    steps = sorted(p for p in args.parts.glob("*") if p.suffix.lower() in SUFFIXES) if args.parts.is_dir() else []
    if not steps:
        print(f"{args.parts}: no STEP parts there", file=sys.stderr)
        return 2
    import ezdxf

    commit = subprocess.run(["git", "-C", str(args.workbench), "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True, check=False).stdout.strip()
    args.out.mkdir(parents=True, exist_ok=True)
    k_factors = _k_factors(args.parts)
    for step in steps:
        k_factor = k_factors.get(step.stem, args.k_factor)
        result = _run(step, args.workbench.resolve(), k_factor)
        result.update(workbench_commit=commit, k_factor=k_factor)
        loops, bends = result.pop("loops", []), result.pop("bend_lines", [])
        result["bend_lines"] = len(bends)
        if result["ok"]:
            doc = ezdxf.new("R2000", units=4)
            doc.layers.add("CUT")
            doc.layers.add("BEND")
            for loop in loops:
                doc.modelspace().add_lwpolyline(loop, close=True, dxfattribs={"layer": "CUT"})
            for a, b in bends:
                doc.modelspace().add_line(a, b, dxfattribs={"layer": "BEND"})
            doc.saveas(args.out / f"{step.stem}.dxf")
        (args.out / f"{step.stem}.json").write_text(json.dumps(result, indent=2) + "\n")
        print(f"{step.stem}: {'ok' if result['ok'] else 'FAILED ' + result.get('error', '')[:200]}, "
              f"{result.get('seconds', float('nan')):.2f} s, {result['bend_lines']} bend lines", flush=True)
    return 0


def _k_factors(folder: Path) -> dict:
    """``{part: K-factor}`` from ``folder/parts.csv`` (columns ``part`` and ``k_factor``), or ``{}`` without one."""
    import csv

    if not (folder / "parts.csv").is_file():
        return {}
    with open(folder / "parts.csv", newline="") as f:
        return {row["part"]: float(row["k_factor"]) for row in csv.DictReader(f) if row.get("k_factor")}


def _run(step: Path, workbench: Path, k_factor: float) -> dict:
    """FreeCAD SheetMetal's unfold of one part, as the JSON record ``INSIDE_FREECAD`` prints (``ok``, and
    ``error`` as one line when it fails)."""
    with tempfile.TemporaryDirectory() as tmp:
        script = Path(tmp) / "unfold.py"
        script.write_text(f"WORKBENCH = {str(workbench)!r}\nSTEP = {str(step.resolve())!r}\nK = {k_factor!r}\n"
                          + INSIDE_FREECAD)
        try:
            proc = subprocess.run(["freecadcmd", str(script)], capture_output=True, text=True, timeout=TIMEOUT,
                                  check=False, env={"QT_QPA_PLATFORM": "offscreen", "HOME": tmp, "PATH": "/usr/bin:/bin"})
        except subprocess.TimeoutExpired:
            return {"ok": False, "error": f"timed out after {TIMEOUT} s"}
    found = [line for line in proc.stdout.splitlines() if line.startswith("RESULT ")]
    if found:
        return json.loads(found[-1][7:])
    said = [line.strip() for line in proc.stderr.splitlines() if line.strip()]
    cause = " ".join(said[-1].split())[:300] if said else f"freecadcmd exited with code {proc.returncode}"
    return {"ok": False, "error": f"no result: {cause}"}


if __name__ == "__main__":
    sys.exit(main())
