"""Run with ``PATTERNS_SITE=<site-packages> SCENARIO=<name> [ARGS=<json>] freecadcmd freecad_api_run.py``.

Runs one scenario of ``patterns.freecad`` inside FreeCAD (headless) and prints ``RESULT <json>``.  The
test interpreter's site-packages (numpy 2, build123d, patterns itself) go in front of FreeCAD's own
Python path, as docs/freecad.md has a user do with the folder the workbench's dependencies go in.
"""

import json
import os
import site
import sys
import traceback

before = list(sys.path)
site.addsitedir(os.environ["PATTERNS_SITE"])
sys.path[:] = [p for p in sys.path if p not in before] + before

import FreeCAD
import Part

import patterns
import patterns.freecad as pf

ARGS = json.loads(os.environ.get("ARGS", "{}"))


def _cut(doc, length=200.0):
    box = doc.addObject("Part::Box", "Box")
    box.Length, box.Width, box.Height = length, 100, 50
    cyl = doc.addObject("Part::Cylinder", "Cylinder")
    cyl.Radius, cyl.Height = 20, 50
    cut = doc.addObject("Part::Cut", "Cut")
    cut.Base, cut.Tool = box, cyl
    doc.recompute()
    return box, cut


def _faces(obj):
    return sorted(round(f.Area, 6) for f in obj.Shape.Faces)


def box_minus_cylinder(step):
    """make_pattern of a Part::Cut (its STEP written for the API to read), then the box made longer."""
    doc = FreeCAD.newDocument("cut")
    box, cut = _cut(doc)
    cut.Shape.exportStep(step)
    pattern = pf.make_pattern(cut, seam_allowance=0)
    before = _faces(pattern)
    outlines = [[(v.X, v.Y) for v in f.OuterWire.OrderedVertexes] for f in pattern.Shape.Faces]
    box.Length = 250
    doc.recompute()
    marks = {child.Role: (len(child.Shape.Edges), len(child.Shape.Vertexes), list(child.Texts))
             for child in map(doc.getObject, pattern.Marks)}
    return {"areas": before, "outlines": outlines, "after": _faces(pattern), "ok": pattern.Ok,
            "pieces": pattern.Pieces, "face_strain": list(pattern.FaceStrain), "marks": marks,
            "report": pattern.Report, "z": max(abs(v.Z) for v in pattern.Shape.Vertexes)}


def bad_option():
    doc = FreeCAD.newDocument("bad")
    _, cut = _cut(doc)
    try:
        pf.make_pattern(cut, seam_allowance=-3)
    except patterns.InputError as exc:
        return {"error": str(exc), "objects": [o.Name for o in doc.Objects]}
    return {"error": None}


def blank_of(path, k_factor):
    """make_blank of a STEP part read into the document."""
    doc = FreeCAD.newDocument("blank")
    part = doc.addObject("Part::Feature", "Part")
    shape = Part.Shape()
    shape.read(path)
    part.Shape = shape
    doc.recompute()
    blank = pf.make_blank(part, k_factor=k_factor)
    faces = blank.Shape.Faces
    return {"area": sum(f.Area for f in faces), "faces": len(faces), "holes": sum(len(f.Wires) - 1 for f in faces),
            "bend_edges": len(blank.Shape.Edges) - sum(len(f.Edges) for f in faces), "ok": blank.Ok,
            "marks": sorted(doc.getObject(name).Role for name in blank.Marks)}


def export(path, step, options):
    """make_pattern of the Part::Cut, exported with the project's writers (and its STEP, for the CLI)."""
    doc = FreeCAD.newDocument("export")
    _, cut = _cut(doc)
    cut.Shape.exportStep(step)
    pattern = pf.make_pattern(cut, **options)
    for suffix in (".dxf", ".svg", ".json"):
        pf.export(pattern, path + suffix)
    return {"written": [path + s for s in (".dxf", ".svg", ".json")], "report_ok": pf.report_of(pattern).ok}


if __name__ in ("__main__", "freecad_api_run"):
    try:
        result = globals()[os.environ["SCENARIO"]](**ARGS)
    except Exception:  # noqa: BLE001 - said to the test, which fails with it
        result = {"traceback": traceback.format_exc()}
    print("RESULT " + json.dumps(result))
