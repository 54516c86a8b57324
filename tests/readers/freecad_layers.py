"""Run with FreeCAD's command line: ``DXF=FILE.dxf freecadcmd freecad_layers.py``.

Imports FILE.dxf with FreeCAD's DXF importer (``importDXF.insert``, layers
grouped into one object each) and prints one line ``RESULT <json>``: per layer,
the number of edges, their total length, and the closed wires FreeCAD can
chain them into (length and enclosed area of each).
"""

import json
import os

import FreeCAD
import importDXF
import Part

FreeCAD.ParamGet("User parameter:BaseApp/Preferences/Mod/Draft").SetBool("groupLayers", True)
doc = FreeCAD.newDocument("check")
importDXF.insert(os.environ["DXF"], doc.Name)
out = {}
for obj in doc.Objects:
    shape = getattr(obj, "Shape", None)
    if shape is None or shape.isNull():
        continue
    wires = []
    for chain in Part.sortEdges(shape.Edges):
        wire = Part.Wire(chain)
        if wire.isClosed():
            wires.append({"length": wire.Length, "area": Part.Face(wire).Area})
    out[obj.Label] = {"edges": len(shape.Edges), "length": shape.Length, "closed_wires": wires}
print("RESULT " + json.dumps(out))
