"""Run with the system's python3 (the one dxf2gcode is installed for):

    python3 dxf2gcode_contours.py FILE.dxf

Loads FILE.dxf with dxf2gcode's own DXF reader (``dxf2gcode.dxfimport.importer.
ReadDXF``, the code behind ``dxf2gcode FILE.dxf``) and prints, as JSON, the
contours it reduced the geometry to: per layer name, how many, how many are
closed, and the area each closed one encloses (its lines and arcs as dxf2gcode
holds them, arcs sampled every degree at most), in the file's drawing units.
(The command line ``dxf2gcode -q`` cannot be used for this: in Debian 12's
package the quiet mode still draws the route text with a float font size, which
PyQt5 rejects, after loading.)
"""

import json
import math
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


def _points(primitive, reverse):
    """The points of one line or arc, in the direction the contour runs (its start point first)."""
    start, end = (primitive.Pe, primitive.Ps) if reverse else (primitive.Ps, primitive.Pe)
    if not hasattr(primitive, "ext"):  # LineGeo
        return [(start.x, start.y)]
    ext = -primitive.ext if reverse else primitive.ext
    angle = math.atan2(start.y - primitive.O.y, start.x - primitive.O.x)
    n = max(int(abs(ext) / math.radians(1.0)) + 1, 2)
    return [(primitive.O.x + primitive.r * math.cos(angle + ext * k / n),
             primitive.O.y + primitive.r * math.sin(angle + ext * k / n)) for k in range(n)]


def _area(entities, cont):
    """The area a closed contour encloses (shoelace over its lines and sampled arcs)."""
    points = []
    for index, reverse in cont.order:
        entity = entities.geo[index]
        primitives = list(getattr(entity, "geo", [entity]))
        for primitive in (reversed(primitives) if reverse else primitives):
            points += _points(primitive, reverse)
    return abs(sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(points, points[1:] + points[:1]))) / 2


def summary(entities):
    out = {}
    for cont in entities.cont:
        geo = entities.geo[cont.order[0][0]]
        name = layers.get(geo.Layer_Nr, str(geo.Layer_Nr))
        row = out.setdefault(name, {"contours": 0, "closed": 0, "areas": []})
        row["contours"] += 1
        row["closed"] += int(bool(cont.closed))
        if cont.closed:
            row["areas"].append(_area(entities, cont))
    for row in out.values():
        row["areas"].sort()
    return out


print(json.dumps({
    "entities": summary(values.entities),
    "blocks": {block.Name: summary(block) for block in values.blocks.Entities},
    "metric": bool(g.config.metric),
}))
