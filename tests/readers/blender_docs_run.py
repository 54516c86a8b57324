# ruff: noqa: I001 - bpy first: it puts Blender's own modules (addon_utils) on the path
"""Run with Blender's Python (``bpy`` as a module), ``BLENDER_USER_SCRIPTS=<dir>`` (the add-on installed in
``<dir>/addons`` by ``patterns blender install --target``), ``BLOCKS=<json file> OUT=<json file>``: enables the
add-on as Blender's Preferences do, runs the Python blocks of docs/blender.md in order, in one namespace, and
writes ``{line: "ok" or the traceback}`` to ``OUT``."""

import json
import os
import sys
import traceback

import bpy  # noqa: F401 - first: it puts Blender's own modules (addon_utils) on the path

import addon_utils

addon_utils.enable("patterns_blender", default_set=True, handle_error=None)
namespace = {"__name__": "__docs__"}
results = {}
with open(os.environ["BLOCKS"], encoding="utf-8") as f:
    blocks = json.load(f)
for line, code in blocks:
    try:
        exec(compile(code, f"blender.md:{line}", "exec"), namespace)  # noqa: S102 - the docs' own code
        results[str(line)] = "ok"
    except Exception:  # noqa: BLE001 - said to the test
        results[str(line)] = traceback.format_exc()
with open(os.environ["OUT"], "w", encoding="utf-8") as f:
    json.dump(results, f)
sys.stdout.flush()
os._exit(0)
