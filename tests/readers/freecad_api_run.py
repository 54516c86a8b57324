"""Run with ``FREECAD_USER_HOME=<dir> SCENARIO=<name> [ARGS=<json>] freecadcmd freecad_api_run.py``.

Runs one scenario of the Patterns workbench inside FreeCAD (headless), installed in ``<dir>/Mod`` by
``patterns freecad install --user-dir <dir>`` as a user installs it, and prints ``RESULT <json>``.  Nothing
is put on FreeCAD's path: the workbench's engine runs in its own process.  Every scenario also says which
modules of FreeCAD's process come from outside FreeCAD's own Python (``foreign``), and runs FreeCAD's own
MeshPart ``flatmesh.FaceUnwrapper`` after the workbench has worked (``flatmesh``).
"""

import json
import os
import sys
import traceback

import FreeCAD
import Part
from freecad.patterns_wb import PatternsError, export, make_blank, make_pattern, report_of
from freecad.patterns_wb.engine import engine

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


def _computed():
    return engine().request("stats")["computed"]


def _marks(doc, obj):
    return {child.Role: (len(child.Shape.Edges), len(child.Shape.Vertexes), list(child.Texts))
            for child in map(doc.getObject, obj.Marks)}


def box_minus_cylinder(step):
    """make_pattern of a Part::Cut (its STEP written for the API to read); moved (no engine call); the box
    made longer (one engine call)."""
    doc = FreeCAD.newDocument("cut")
    box, cut = _cut(doc)
    cut.Shape.exportStep(step)
    pattern = make_pattern(cut, seam_allowance=0)
    made = _computed()
    before = _faces(pattern)
    laid = pattern.Shape.BoundBox.YMin
    beside = [pattern.Shape.BoundBox.XMin - cut.Shape.BoundBox.XMax, laid - cut.Shape.BoundBox.YMin]
    pattern.Placement.Base = pattern.Placement.Base + FreeCAD.Vector(0, -450, 0)
    doc.recompute()
    moved = _computed()
    z = max(abs(v.Z) for v in pattern.Shape.Vertexes)
    box_of = lambda shape: [shape.BoundBox.XMin, shape.BoundBox.YMin, shape.BoundBox.XMax, shape.BoundBox.YMax]
    moved_box = box_of(pattern.Shape)
    marks_box = box_of(Part.makeCompound([doc.getObject(n).Shape for n in pattern.Marks
                                          if not doc.getObject(n).Shape.isNull()]))
    box.Length = 250
    doc.recompute()
    return {"areas": before, "after": _faces(pattern), "ok": pattern.Ok, "pieces": pattern.Pieces,
            "face_strain": list(pattern.FaceStrain), "marks": _marks(doc, pattern), "report": pattern.Report,
            "z": z, "computed": [made, moved, _computed()], "moved": moved_box, "marks_moved": marks_box,
            "laid": laid, "beside": beside}


def bad_option():
    doc = FreeCAD.newDocument("bad")
    _, cut = _cut(doc)
    out = {}
    for options in ({"seam_allowance": -3}, {"no_such_option": 1}):
        try:
            make_pattern(cut, **options)
        except PatternsError as exc:
            out[next(iter(options))] = str(exc)
    out["objects"] = [o.Name for o in doc.Objects]
    out["text_number"] = make_pattern(cut, seam_allowance="5", marks=False).seam_allowance  # as a form gives it
    return out


def failed_create():
    """A source the engine refuses (one edge: no face to flatten): nothing is left in the document."""
    doc = FreeCAD.newDocument("failed")
    edge = doc.addObject("Part::Feature", "Edge")
    edge.Shape = Part.makeLine(FreeCAD.Vector(0, 0, 0), FreeCAD.Vector(10, 0, 0))
    doc.recompute()
    try:
        make_pattern(edge)
        error = None
    except PatternsError as exc:
        error = str(exc)
    return {"error": error, "objects": [o.Name for o in doc.Objects]}


def blank_of(path, k_factor, face=None):
    """make_blank of a STEP part read into the document (``face``: one selected face, SheetMetal's way)."""
    doc = FreeCAD.newDocument("blank")
    part = doc.addObject("Part::Feature", "Part")
    shape = Part.Shape()
    shape.read(path)
    part.Shape = shape
    doc.recompute()
    blank = make_blank((part, [face]) if face else part, k_factor=k_factor)
    faces = blank.Shape.Faces
    return {"area": sum(f.Area for f in faces), "faces": len(faces), "holes": sum(len(f.Wires) - 1 for f in faces),
            "bend_edges": len(blank.Shape.Edges) - sum(len(f.Edges) for f in faces), "ok": blank.Ok,
            "marks": sorted(doc.getObject(name).Role for name in blank.Marks), "source": list(blank.Source[1]),
            "mark_edges": {doc.getObject(name).Role: len(doc.getObject(name).Shape.Edges) for name in blank.Marks},
            "fixed_face": blank.fixed_face, "n_faces": len(shape.Faces)}


def export_all(path, step, options):
    """make_pattern of the Part::Cut, exported with the project's writers (and its STEP, for the CLI)."""
    doc = FreeCAD.newDocument("export")
    _, cut = _cut(doc)
    cut.Shape.exportStep(step)
    pattern = make_pattern(cut, **options)
    made = _computed()
    for suffix in (".dxf", ".svg", ".json"):
        export(pattern, path + suffix)
    return {"report_ok": report_of(pattern).ok, "computed": [made, _computed()]}


def cup(limit):
    """The hemisphere cup against a strain limit: the verdict and the figures the Check command shows."""
    doc = FreeCAD.newDocument("cup")
    sphere = doc.addObject("Part::Sphere", "Cup")
    sphere.Radius, sphere.Angle1 = 50, 0
    doc.recompute()
    pattern = make_pattern(sphere, max_strain=limit, marks=False)
    return {"ok": pattern.Ok, "figures": report_of(pattern).figures, "report": pattern.Report,
            "face_strain": list(pattern.FaceStrain)}


def killed_worker():
    """The worker killed between two recomputes: the next recompute starts a new one and works."""
    import signal

    doc = FreeCAD.newDocument("killed")
    box, cut = _cut(doc)
    pattern = make_pattern(cut, marks=False)
    first = engine().hello["pid"]
    os.kill(first, signal.SIGKILL)
    engine().process.wait()
    box.Length = 250
    doc.recompute()
    return {"valid": pattern.isValid(), "areas": _faces(pattern), "starts": engine().starts,
            "pids": [first, engine().hello["pid"]]}


def reopened(path):
    """Saved and reopened (the engine stopped, as in a new session): the recompute reuses the pieces (no
    engine started), a Marks object recomputed alone keeps its lines, and a real change calls it once."""
    doc = FreeCAD.newDocument("saved")
    _, cut = _cut(doc)
    pattern = make_pattern(cut, seam_allowance=5)
    areas, sew = _faces(pattern), len(doc.getObject(f"{pattern.Name}_sew").Shape.Edges)
    doc.saveAs(path)
    FreeCAD.closeDocument(doc.Name)
    engine().stop()
    starts = engine().starts
    doc = FreeCAD.openDocument(path)
    pattern = doc.getObject("Pattern")
    for obj in doc.Objects:
        obj.touch()
    doc.recompute()
    quiet = not engine().alive() and engine().starts == starts
    reopened_areas = _faces(pattern)
    marks = doc.getObject(f"{pattern.Name}_sew")
    marks.touch()
    marks.recompute()
    kept = len(marks.Shape.Edges)
    doc.getObject("Box").Length = 250
    doc.recompute()
    return {"areas": [areas, reopened_areas], "quiet": quiet, "computed": _computed(), "sew": [sew, kept],
            "valid": all(o.isValid() for o in doc.Objects), "sew_after": len(marks.Shape.Edges)}


def allowance_later():
    """A seam allowance set after creation: the sew lines follow (a Marks object added for them)."""
    doc = FreeCAD.newDocument("later")
    _, cut = _cut(doc)
    pattern = make_pattern(cut)
    roles = sorted(doc.getObject(n).Role for n in pattern.Marks)
    pattern.seam_allowance = 5.0
    doc.recompute()
    sew = [doc.getObject(n) for n in pattern.Marks if doc.getObject(n).Role == "sew"]
    sew_edges = len(sew[0].Shape.Edges) if sew else 0
    pattern.seam_allowance = -3.0  # made bad later: the recompute fails, and the verdict says so
    doc.recompute()
    return {"before": roles, "after": sorted(doc.getObject(n).Role for n in pattern.Marks), "sew_edges": sew_edges,
            "bad_later": [pattern.isValid(), pattern.Ok, pattern.Report]}


def engine_missing():
    """No engine: one error with the commands to run, nothing added; then the engine given, and the same
    call works in the same session."""
    os.environ["PATTERNS_ENGINE"] = "/nonexistent/python -m patterns"
    engine().stop()
    doc = FreeCAD.newDocument("missing")
    _, cut = _cut(doc)
    try:
        make_pattern(cut)
        error = None
    except PatternsError as exc:
        error = str(exc)
    objects = [o.Name for o in doc.Objects]
    del os.environ["PATTERNS_ENGINE"]  # engine.json's, as installed
    pattern = make_pattern(cut, marks=False)
    return {"error": error, "objects": objects, "then": pattern.Pieces}


def _flatmesh():
    """FreeCAD's own Unwrap Mesh, in this process, after the workbench has worked."""
    import flatmesh
    import MeshPart
    import numpy as np

    mesh = MeshPart.meshFromShape(Shape=Part.makeSphere(20, FreeCAD.Vector(), FreeCAD.Vector(0, 0, 1), 0, 90),
                                  LinearDeflection=1)
    points = np.array([[p.x, p.y, p.z] for p in mesh.Points])
    faces = np.array([list(f) for f in mesh.Topology[1]])
    unwrapper = flatmesh.FaceUnwrapper(points, faces)
    unwrapper.findFlatNodes(5, 0.95)
    return {"nodes": len(unwrapper.ze_nodes), "numpy": np.__version__, "numpy_file": np.__file__}


def _foreign():
    """Modules of this process whose files lie in the engine's environment."""
    prefix = os.path.realpath(os.environ["ENGINE_PREFIX"])
    return sorted(name for name, module in list(sys.modules.items())
                  if os.path.realpath(getattr(module, "__file__", None) or "/").startswith(prefix))


if __name__ in ("__main__", "freecad_api_run"):
    try:
        result = globals()[os.environ["SCENARIO"]](**ARGS)
        result["flatmesh"] = _flatmesh()
        result["foreign"] = _foreign()
        result["patterns_loaded"] = sorted(m for m in sys.modules if m == "patterns" or m.startswith("patterns."))
    except Exception:  # noqa: BLE001 - said to the test, which fails with it
        result = {"traceback": traceback.format_exc()}
    print("RESULT " + json.dumps(result))
    sys.stdout.flush()
    os._exit(0)
