"""FreeCAD through the worker: a parametric pattern's recompute against the same flatten in-process.

Run from the repository root, with FreeCAD installed (``freecadcmd`` on the PATH)::

    python benchmarks/freecad_worker.py [--lengths 12] [--objects 3]

The workbench is installed by ``patterns freecad install`` into a temporary FreeCAD user folder, as a
user installs it.  In ``freecadcmd``: a Part::Cut (a 200 x 100 x 50 box less an R20 cylinder) and its
pattern; with the worker warm, the box's length is changed ``--lengths`` times and each
``doc.recompute()`` timed (the pattern's whole recompute: the BREP text out, the engine's work, the pieces
and marks back as Part shapes).  Beside it, in this process and on the same shapes (FreeCAD's BREP text
of the cut at each length, written by the run), the engine's own work for the same request
(``patterns.service.work.make``: load, flatten, pieces, check, the labels placed, the shapes as BREP text),
and its core alone (load, flatten, pieces, check), timed the same way.  Printed: the medians and their
ratios (the acceptance: at most 1.5 against the same request in-process).

Then a document with ``--objects`` patterns of the cut is saved and reopened in a new ``freecadcmd``;
the box is changed and the first recompute (every pattern) is timed, with the number of worker starts
(the acceptance: one, whatever the number of objects).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

INNER = textwrap.dedent('''
    import json, os, sys, time
    import FreeCAD
    from freecad.patterns_wb import make_pattern
    from freecad.patterns_wb.engine import engine

    out, folder = {}, os.environ["FOLDER"]
    if os.environ["STEP"] == "warm":
        doc = FreeCAD.newDocument("bench")
        box = doc.addObject("Part::Box", "Box")
        box.Length, box.Width, box.Height = 200, 100, 50
        cyl = doc.addObject("Part::Cylinder", "Cylinder")
        cyl.Radius, cyl.Height = 20, 50
        cut = doc.addObject("Part::Cut", "Cut")
        cut.Base, cut.Tool = box, cyl
        doc.recompute()
        t = time.perf_counter(); make_pattern(cut); out["first"] = time.perf_counter() - t
        times, worker = [], []
        asked = engine().request

        def request(op, **fields):  # the worker's own time on each request, to tell the boundary's cost
            result = asked(op, **fields)
            if op == "make":
                worker.append(result["seconds"])
            return result

        engine().request = request
        for k, length in enumerate(json.loads(os.environ["LENGTHS"])):
            box.Length = length
            box.recompute()
            cut.recompute()  # the cut first: the time below is the pattern's (and its marks')
            with open(os.path.join(folder, f"cut{k}.brep"), "w") as f:
                f.write(cut.Shape.exportBrepToString())
            t = time.perf_counter(); doc.recompute(); times.append(time.perf_counter() - t)
        out["recompute"], out["worker"] = times, worker
        engine().request = asked
        out["computed"] = engine().request("stats")["computed"]
        for n in range(1, int(os.environ["OBJECTS"])):
            make_pattern(cut, name=f"Pattern{n}")
        doc.saveAs(os.path.join(folder, "bench.FCStd"))
    else:
        doc = FreeCAD.openDocument(os.path.join(folder, "bench.FCStd"))
        doc.getObject("Box").Length = 333
        t = time.perf_counter(); doc.recompute(); out["reopened"] = time.perf_counter() - t
        out["starts"] = engine().starts
        out["valid"] = all(o.isValid() for o in doc.Objects)
        out["patterns"] = sum(1 for o in doc.Objects if o.Name.startswith("Pattern") and "_" not in o.Name)
    print("RESULT " + json.dumps(out))
    sys.stdout.flush()
    os._exit(0)
''')


def _freecad(step: str, folder: Path, user: Path, **env) -> dict:
    environ = dict(os.environ, FREECAD_USER_HOME=str(user), FOLDER=str(folder), STEP=step,
                   **{k: str(v) for k, v in env.items()})
    environ.pop("PATTERNS_ENGINE", None)
    proc = subprocess.run(["freecadcmd", str(folder / "inner.py")], capture_output=True, text=True, env=environ,
                          timeout=1800, check=False)
    lines = [x for x in proc.stdout.splitlines() if x.startswith("RESULT ")]
    if not lines:
        sys.exit(proc.stdout[-3000:] + proc.stderr[-3000:])
    return json.loads(lines[-1][7:])


def _in_process(folder: Path, count: int) -> tuple:
    """The engine's work for each recompute's request, in this process: ``(whole, core)`` times -- the whole
    request as the worker answers it (``work.make``: load, flatten, pieces, check, the labels placed, the
    shapes as BREP text) and its core alone (``work._compute``: load, flatten, pieces, check)."""
    from patterns.service.work import Results, _compute, make

    whole, core = [], []
    for k in range(count):
        request = {"kind": "pattern", "shape": (folder / f"cut{k}.brep").read_text(), "options": {}, "name": "Cut",
                   "faces": 7}
        if k == 0:
            make(Results(), request)  # warm: the imports and caches the warm worker has
        t = time.perf_counter()
        make(Results(), request)
        whole.append(time.perf_counter() - t)
        t = time.perf_counter()
        _compute("pattern", request["shape"], {}, "Cut")
        core.append(time.perf_counter() - t)
    return whole, core


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--lengths", type=int, default=12, help="box lengths timed (default 12)")
    parser.add_argument("--objects", type=int, default=3, help="patterns in the reopened document (default 3)")
    args = parser.parse_args()
    folder = Path(tempfile.mkdtemp(prefix="patterns-bench-"))
    user = folder / "freecad-user"
    subprocess.run([sys.executable, "-m", "patterns", "freecad", "install", "--user-dir", str(user)], check=True,
                   capture_output=True)
    (folder / "inner.py").write_text(INNER)
    lengths = [210.0 + 10 * k for k in range(args.lengths)]
    warm = _freecad("warm", folder, user, LENGTHS=json.dumps(lengths), OBJECTS=args.objects)
    whole, core = _in_process(folder, len(lengths))
    recompute, worker = warm["recompute"], warm["worker"]
    boundary = statistics.median(r - w for r, w in zip(recompute, worker))
    print(f"cut box, {len(lengths)} lengths: FreeCAD recompute through the warm worker best {min(recompute):.3f} s, "
          f"median {statistics.median(recompute):.3f} s; of which the worker's own work median "
          f"{statistics.median(worker):.3f} s, the rest (BREP out, pipes, JSON, the shapes and marks back in FreeCAD) "
          f"median {boundary * 1000:.1f} ms")
    print(f"  the same request in-process (work.make: flatten, pieces, check, labels, BREP) best {min(whole):.3f} s, "
          f"median {statistics.median(whole):.3f} s: ratio {min(recompute) / min(whole):.2f} best to best, "
          f"{statistics.median(recompute) / statistics.median(whole):.2f} median to median (acceptance <= 1.5)")
    print(f"  its core alone in-process (work._compute: flatten, pieces, check) best {min(core):.3f} s: ratio "
          f"{min(recompute) / min(core):.2f} best to best")
    print(f"first pattern (the worker's start included): {warm['first']:.2f} s; engine computations "
          f"{warm['computed']} for {1 + len(lengths)} patterns made")
    reopened = _freecad("reopen", folder, user)
    print(f"reopened with {reopened['patterns']} patterns, box changed: first recompute {reopened['reopened']:.2f} s, "
          f"worker starts {reopened['starts']} (acceptance: 1), all valid {reopened['valid']}")


if __name__ == "__main__":
    main()
