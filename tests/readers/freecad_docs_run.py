"""Run with ``PATTERNS_SITE=... BLOCKS=<json file> OUT=<json file> freecadcmd freecad_docs_run.py`` in a folder
where ``samples/`` is the repository's: runs the Python blocks of docs/freecad.md in order, in one
namespace, inside FreeCAD, and writes ``{line: "ok" or the traceback}`` to ``OUT``."""

import json
import os
import site
import sys
import traceback

before = list(sys.path)
site.addsitedir(os.environ["PATTERNS_SITE"])
sys.path[:] = [p for p in sys.path if p not in before] + before

namespace = {"__name__": "__docs__"}
results = {}
with open(os.environ["BLOCKS"], encoding="utf-8") as f:
    blocks = json.load(f)
for line, code in blocks:
    try:
        exec(compile(code, f"freecad.md:{line}", "exec"), namespace)  # noqa: S102 - the docs' own code
        results[str(line)] = "ok"
    except Exception:  # noqa: BLE001 - said to the test
        results[str(line)] = traceback.format_exc()
with open(os.environ["OUT"], "w", encoding="utf-8") as f:
    json.dump(results, f)
