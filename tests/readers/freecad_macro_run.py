"""Run with ``MACRO=... OUT=... freecadcmd freecad_macro_run.py``: loads the
example macro headless and flattens a FreeCAD cylinder with it; prints
``RESULT <json>`` with the command's output."""

import json
import os

import FreeCAD
import Part

namespace = {"__name__": "freecad_macro"}
with open(os.environ["MACRO"], encoding="utf-8") as f:
    exec(compile(f.read(), os.environ["MACRO"], "exec"), namespace)
doc = FreeCAD.newDocument("macro")
tube = doc.addObject("Part::Feature", "Tube")
tube.Shape = Part.makeCylinder(50, 120)
doc.recompute()
output = namespace["flatten_objects"]([tube], os.environ["OUT"], seam_allowance=5.0)
print("RESULT " + json.dumps({"output": output}))
