"""Run with ``FREECAD_USER_HOME=<dir> BLOCKS=<json file> OUT=<json file> freecadcmd freecad_docs_run.py`` in a
folder where ``samples/`` is the repository's, the workbench installed in ``<dir>`` by ``patterns freecad
install``: runs the Python blocks of docs/freecad.md in order, in one namespace, inside FreeCAD, and writes
``{line: "ok" or the traceback}`` to ``OUT``."""

import json
import os
import sys
import traceback

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
sys.stdout.flush()
os._exit(0)
