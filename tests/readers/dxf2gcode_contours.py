"""Run with the system's python3 (the one dxf2gcode is installed for):

    python3 dxf2gcode_contours.py FILE.dxf

Loads FILE.dxf with dxf2gcode's own DXF reader (``dxf2gcode.dxfimport.importer.
ReadDXF``, the code behind ``dxf2gcode FILE.dxf``) and prints, as JSON, the
contours it reduced the geometry to: per layer name, how many, and how many are
closed.  (The command line ``dxf2gcode -q`` cannot be used for this: in Debian
12's package the quiet mode still draws the route text with a float font size,
which PyQt5 rejects, after loading.)
"""

import json
import os
import sys

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

import dxf2gcode.globals.globals as g
from dxf2gcode.globals.config import MyConfig
from PyQt5.QtWidgets import QApplication

app = QApplication(sys.argv[:1])
g.folder = os.path.join(os.path.expanduser("~"), ".config/dxf2gcode")  # as /usr/bin/dxf2gcode sets it
g.config = MyConfig()
from dxf2gcode.dxfimport.importer import ReadDXF

values = ReadDXF(sys.argv[1])
layers = {i: layer.name for i, layer in enumerate(values.layers)}


def summary(entities):
    out = {}
    for cont in entities.cont:
        geo = entities.geo[cont.order[0][0]]
        name = layers.get(geo.Layer_Nr, str(geo.Layer_Nr))
        row = out.setdefault(name, {"contours": 0, "closed": 0})
        row["contours"] += 1
        row["closed"] += int(bool(cont.closed))
    return out


print(json.dumps({
    "entities": summary(values.entities),
    "blocks": {block.Name: summary(block) for block in values.blocks.Entities},
    "metric": bool(g.config.metric),
}))
