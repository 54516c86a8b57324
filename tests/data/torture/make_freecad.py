"""Build four sheet-metal parts with FreeCAD's SheetMetal workbench and write each as STEP plus its own flat pattern.

Run from the repository root, with FreeCAD's ``freecadcmd`` (0.20.2, Debian 12) and the workbench at commit
``cbef3f2`` in ``/tmp/FreeCAD_SheetMetal`` (``SHEETMETAL`` overrides the path; the workbench imports networkx)::

    apt-get install -y freecad python3-networkx
    git clone https://github.com/shaise/FreeCAD_SheetMetal /tmp/FreeCAD_SheetMetal
    git -C /tmp/FreeCAD_SheetMetal checkout cbef3f2
    FREECAD_USER_HOME=$(mktemp -d) QT_QPA_PLATFORM=offscreen taskset -c 0 \\
        freecadcmd tests/data/torture/make_freecad.py

(``freecadcmd`` passes no arguments to the script: the output folder is ``freecad/`` beside this file.)

Every part is made the way a FreeCAD user makes it, by the workbench's own feature classes (FeaturePython
objects in a FreeCAD document, recomputed by FreeCAD): a closed sketch (Sketcher) turned into a base plate by
``SheetMetalBaseCmd.SMBaseBend`` ("Make Base Wall"), walls added on edges of that plate by
``SheetMetalCmd.SMBendWall`` ("Make Wall", with its auto-miter and its bend-relief options), corner reliefs by
``SheetMetalCornerReliefCmd.SMCornerRelief`` ("Add Corner Relief"), and the flat pattern by
``SheetMetalUnfoldCmd.SMUnfold`` ("Unfold", new unfolder ``SheetMetalNewUnfolder``, K-factor ``K`` in the ANSI
convention: neutral line at K * thickness from the inside of the bend; the workbench's DIN K-factor is twice that),
with its "Generate unfold sketch" and "Separate sketch layers" options on.

Written into ``freecad/``, for each part ``<part>.step`` (the final feature's solid, by FreeCAD's STEP writer,
``Import.export``) and ``<part>.dxf`` (the unfold sketches, by FreeCAD's DXF writer ``importDXF.export``, which is
what the workbench's own "export unfold sketch" calls): the outline sketch ``Unfold_Sketch`` (outer contour),
``Unfold_Sketch_Holes`` (round holes), ``Unfold_Sketch_Internal`` (other inner contours) and ``Unfold_Sketch_Bends``
(bend centre lines), each in a group of that name, so that each lands on a DXF layer of that name.  A
``freecad/parts.json`` records each part's design dimensions (the numbers below) and what FreeCAD reported.

FreeCAD 0.20 shims (the same as ``benchmarks/freecad_sheetmetal.py``): ``FreeCAD.Base.Precision`` (absent before
1.0) is given OpenCascade's own values, ``Console.PrintUser*`` (absent before 0.21) go to ``PrintError``,
``Part.sortEdges`` is called without the tolerance 0.20 does not take.  Two more for running without the GUI:
``SheetMetalTools.taskRestoreDefaults`` (which restores the user's last-used values from the preferences and is
defined only when the GUI is up) is a no-op, so every feature starts from its class defaults and the values set here;
and the sketches the unfold makes get a stand-in ``ViewObject`` (``getUnfoldSketches`` sets the bend-line sketch's
``ViewObject.DrawStyle`` to dash-dot, and without the GUI a document object's ``ViewObject`` is None: the unfold
fails with "AttributeError: 'NoneType' object has no attribute 'DrawStyle'" otherwise).
"""

import json
import math
import os
import sys

WORKBENCH = os.environ.get("SHEETMETAL", "/tmp/FreeCAD_SheetMetal")
HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "freecad")
K = 0.4
"""K-factor of the flat patterns, ANSI (the workbench's Unfold default, 0.40)."""

PARTS = {
    # L bracket: 60 x 40 x 2 plate with a 8 mm hole, one 90 degree wall on a 40 mm edge, R 2, leg 30.
    "fc_l_bracket": {"t": 2.0, "base": (60.0, 40.0), "holes": [(30.0, 20.0, 4.0)],
                     "walls": [{"edge": "x+", "r": 2.0, "leg": 30.0}]},
    # U channel: 80 x 40 x 3 web with two 6 mm holes, walls on both 80 mm edges (one feature), R 3, legs 25.
    "fc_u_channel": {"t": 3.0, "base": (80.0, 40.0), "holes": [(20.0, 20.0, 3.0), (60.0, 20.0, 3.0)],
                     "walls": [{"edge": ("y-", "y+"), "r": 3.0, "leg": 25.0}]},
    # Tray: 100 x 70 x 1.5 base, four walls (one feature, auto-miter), R 1, legs 20; the workbench's circular
    # corner relief (size 3: radius 3 mm, centred where the two bends' flat zones meet) at the corner (0, 0) only.
    # Each corner relief adds some 120 KB of STEP (the workbench wraps every edge of the relief cut around the bend
    # as a B-spline through 50 points, SheetMetalBendSolid.wrap_face), so four of them would make a 556 KB file.
    "fc_tray": {"t": 1.5, "base": (100.0, 70.0), "holes": [],
                "walls": [{"edge": ("x-", "x+", "y-", "y+"), "r": 1.0, "leg": 20.0}],
                "corner_relief": {"type": "Circle", "size": 3.0, "corners": [(0.0, 0.0)]}},
    # Flange with bend relief: 80 x 50 x 2 plate with a 10 mm hole, a 30 mm wide wall on the 50 mm edge (gaps 10
    # and 10 from its ends), R 2, leg 25, rectangular bend reliefs 2 wide and 4 deep.
    "fc_relief_flange": {"t": 2.0, "base": (80.0, 50.0), "holes": [(40.0, 25.0, 5.0)],
                         "walls": [{"edge": "x+", "r": 2.0, "leg": 25.0, "gap1": 10.0, "gap2": 10.0,
                                    "relief": ("Rectangle", 2.0, 4.0)}]},
}

sys.path.insert(0, WORKBENCH)
import FreeCAD
import Part

if not hasattr(FreeCAD.Base, "Precision"):  # FreeCAD < 1.0: OpenCascade's own tolerances
    class Precision:
        approximation = staticmethod(lambda: 1e-6)
        angular = staticmethod(lambda: 1e-12)
        confusion = staticmethod(lambda: 1e-7)
    FreeCAD.Base.Precision = Precision
for _name in ("PrintUserError", "PrintUserWarning", "PrintTranslatedUserError", "PrintTranslatedUserWarning"):
    if not hasattr(FreeCAD.Console, _name):  # FreeCAD < 0.21
        setattr(FreeCAD.Console, _name, lambda *args: FreeCAD.Console.PrintError(str(args[-1])))
_sort_edges = Part.sortEdges


def _sort_edges_any(edges, *tolerance):  # FreeCAD < 1.0 takes no tolerance
    try:
        return _sort_edges(edges, *tolerance)
    except Exception:  # noqa: BLE001 - whatever 0.20 raises for the extra argument
        return _sort_edges(edges)


Part.sortEdges = _sort_edges_any
import SheetMetalTools

if not hasattr(SheetMetalTools, "taskRestoreDefaults"):  # defined only with the GUI up
    SheetMetalTools.taskRestoreDefaults = lambda obj, names: None
import Import
import importDXF
import SheetMetalBaseCmd
import SheetMetalCmd
import SheetMetalCornerReliefCmd
import SheetMetalNewUnfolder
import SheetMetalUnfoldCmd


class _NoView:
    """A sketch as ``SheetMetalNewUnfolder.getUnfoldSketches`` gets it, with a stand-in for its ViewObject: that
    function sets the bend-line sketch's ``ViewObject.DrawStyle``, and without the GUI ``ViewObject`` is None."""

    def __init__(self, obj):
        self.__dict__.update(_obj=obj, ViewObject=type("ViewObject", (), {})())

    def __getattr__(self, name):
        return getattr(self.__dict__["_obj"], name)

    def __setattr__(self, name, value):
        setattr(self.__dict__["_obj"], name, value)


if not FreeCAD.GuiUp:
    _to_sketch = SheetMetalNewUnfolder.SketchExtraction.edges_to_sketch_object
    SheetMetalNewUnfolder.SketchExtraction.edges_to_sketch_object = staticmethod(
        lambda *args, **kwargs: _NoView(_to_sketch(*args, **kwargs)))

V = FreeCAD.Vector
EPS = 1e-6


def _sketch(doc, width, depth, holes):
    """A closed sketch on XY: the rectangle (0, 0)-(width, depth) and circles (x, y, r)."""
    sketch = doc.addObject("Sketcher::SketchObject", "Sketch")
    corners = [V(0, 0, 0), V(width, 0, 0), V(width, depth, 0), V(0, depth, 0)]
    for i in range(4):
        sketch.addGeometry(Part.LineSegment(corners[i], corners[(i + 1) % 4]))
    for x, y, r in holes:
        sketch.addGeometry(Part.Circle(V(x, y, 0), V(0, 0, 1), r))
    return sketch


def _top_edge(shape, side, width, depth, t):
    """The name of the straight edge of the base plate's top face (z = t) on ``side`` (x-, x+, y-, y+)."""
    want = {"x-": (0.0, depth / 2), "x+": (width, depth / 2), "y-": (width / 2, 0.0), "y+": (width / 2, depth)}[side]
    for i, edge in enumerate(shape.Edges):
        c = edge.CenterOfMass
        if (edge.Curve.TypeId == "Part::GeomLine" and abs(c.z - t) < EPS and abs(c.x - want[0]) < EPS
                and abs(c.y - want[1]) < EPS):
            return f"Edge{i + 1}"
    raise RuntimeError(f"no top edge on side {side}")


def _base_face(shape, t):
    """The name of the base plate's top face (the plane z = t, the largest there): the unfold's fixed face."""
    faces = [(f.Area, i) for i, f in enumerate(shape.Faces)
             if f.Surface.TypeId == "Part::GeomPlane" and abs(f.CenterOfMass.z - t) < EPS
             and abs(abs(f.normalAt(0, 0).z) - 1) < EPS]
    return f"Face{max(faces)[1] + 1}"


def _corner_edges(shape, t, corner):
    """Names of the two edges where the base plate's top face meets the two bends at ``corner`` (x, y)."""
    top = shape.Faces[int(_base_face(shape, t)[4:]) - 1]
    found = []
    for i, edge in enumerate(shape.Edges):
        if edge.Curve.TypeId != "Part::GeomLine" or abs(edge.CenterOfMass.z - t) > EPS:
            continue
        if not any(e.isSame(edge) for e in top.Edges):
            continue
        if not any(f.Surface.TypeId == "Part::GeomCylinder" for f in shape.ancestorsOfType(edge, Part.Face)):
            continue
        ends = [v.Point for v in edge.Vertexes]
        found.append((min(math.hypot(p.x - corner[0], p.y - corner[1]) for p in ends), f"Edge{i + 1}"))
    found.sort()
    return [name for _, name in found[:2]]


def build(doc, name, spec):
    """The part's features in ``doc``; returns the last one."""
    width, depth = spec["base"]
    t = spec["t"]
    sketch = _sketch(doc, width, depth, spec["holes"])
    doc.recompute()
    base = doc.addObject("Part::FeaturePython", "BaseBend")
    SheetMetalBaseCmd.SMBaseBend(base, sketch)
    base.Thickness = t
    base.Radius = spec["walls"][0]["r"]
    doc.recompute()
    last = base
    for wall_spec in spec["walls"]:
        sides = wall_spec["edge"] if isinstance(wall_spec["edge"], tuple) else (wall_spec["edge"],)
        edges = [_top_edge(last.Shape, side, width, depth, t) for side in sides]
        wall = doc.addObject("Part::FeaturePython", "Bend")
        SheetMetalCmd.SMBendWall(wall, last, edges)
        wall.radius = wall_spec["r"]
        wall.length = wall_spec["leg"]
        wall.angle = 90.0
        wall.kfactor = K
        wall.gap1 = wall_spec.get("gap1", 0.0)
        wall.gap2 = wall_spec.get("gap2", 0.0)
        if "relief" in wall_spec:
            wall.reliefType, wall.reliefw, wall.reliefd = wall_spec["relief"]
        doc.recompute()
        last = wall
    if "corner_relief" in spec:
        for corner in spec["corner_relief"]["corners"]:
            relief = doc.addObject("Part::FeaturePython", "CornerRelief")
            SheetMetalCornerReliefCmd.SMCornerRelief(relief, last, _corner_edges(last.Shape, t, corner))
            relief.ReliefSketch = spec["corner_relief"]["type"]
            relief.Size = spec["corner_relief"]["size"]
            relief.kfactor = K
            doc.recompute()
            last = relief
    for obj in doc.Objects:
        if "Invalid" in obj.State or "Error" in obj.State:
            raise RuntimeError(f"{name}: feature {obj.Name} failed to recompute: {obj.State}")
    return last


def unfold(doc, feature, t):
    """The workbench's Unfold feature on ``feature`` (fixed face: the base plate's top), K ANSI; its sketches."""
    flat = doc.addObject("Part::FeaturePython", "Unfold")
    SheetMetalUnfoldCmd.SMUnfold(flat, feature, [_base_face(feature.Shape, t)])
    flat.KFactor = K
    flat.KFactorStandard = "ansi"
    flat.GenerateSketch = True
    flat.SeparateSketchLayers = True
    doc.recompute()
    if "Invalid" in flat.State or not flat.UnfoldSketches:
        raise RuntimeError(f"unfold failed: {flat.State}")
    return flat, [doc.getObject(name) for name in flat.UnfoldSketches]


def main():
    os.makedirs(OUT, exist_ok=True)
    record = {"freecad": ".".join(FreeCAD.Version()[:3]), "workbench": "FreeCAD_SheetMetal cbef3f2",
              "k_factor": K, "k_factor_standard": "ansi", "parts": {}}
    for name, spec in PARTS.items():
        doc = FreeCAD.newDocument(name)
        try:
            feature = build(doc, name, spec)
            shape = feature.Shape
            if not shape.isValid() or len(shape.Solids) != 1:
                raise RuntimeError(f"{name}: not one valid solid ({len(shape.Solids)} solids)")
            feature.Label = name  # the STEP product's name
            Import.export([feature], os.path.join(OUT, f"{name}.step"))
            flat, sketches = unfold(doc, feature, spec["t"])
            groups = []
            for sketch in sketches:  # one DXF layer per sketch: importDXF takes a group's label as the layer
                group = doc.addObject("App::DocumentObjectGroup", sketch.Label)
                group.addObject(sketch)
                groups.append(group)
            importDXF.export(sketches, os.path.join(OUT, f"{name}.dxf"))
            record["parts"][name] = dict(spec, ok=True, volume=shape.Volume, faces=len(shape.Faces),
                                         flat_area=flat.Shape.Volume / spec["t"],
                                         sketches=[s.Label for s in sketches],
                                         sketch_edges={s.Label: len(s.Shape.Edges) for s in sketches})
            print(f"MADE {name}: {len(shape.Faces)} faces, sketches {[s.Label for s in sketches]}", flush=True)
        except Exception as exc:  # noqa: BLE001 - recorded, and the next part is made
            record["parts"][name] = dict(spec, ok=False, error=" ".join(f"{type(exc).__name__}: {exc}".split()))
            print(f"FAILED {name}: {exc}", flush=True)
        FreeCAD.closeDocument(doc.Name)
    with open(os.path.join(OUT, "parts.json"), "w") as f:
        json.dump(record, f, indent=1)
        f.write("\n")


main()
