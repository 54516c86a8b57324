"""Run in FreeCAD's GUI (``xvfb-run freecad freecad_gui_run.py``, the workbench installed by ``patterns freecad
install`` into ``$FREECAD_USER_HOME``): activates the workbench while its engine cannot start (one dialog),
gives it the engine back, runs Flatten through its task panel, moves
the pattern, opens its options by double-click, runs Check, switches the strain overlay on and off, deletes
the pattern, runs FreeCAD's own Unwrap Mesh, saves screenshots (``$SHOT``, ``$PANEL``) and writes the
findings as JSON to ``$OUT``, then quits.  The dialogs the workbench would show are recorded, not shown
(a modal dialog would wait for a click)."""

import json
import os
import sys
import traceback

import FreeCAD
import FreeCADGui as Gui
from PySide import QtGui

out = {"dialogs": []}


def _record(kind):
    def box(parent, title, text, *args, **kwargs):
        out["dialogs"].append([kind, title, text])
        return QtGui.QMessageBox.Ok

    return box


QtGui.QMessageBox.critical = _record("critical")
QtGui.QMessageBox.information = _record("information")
QtGui.QMessageBox.warning = _record("warning")


def _yes():
    """Answer FreeCAD's own "delete its dependents too?" question as a user who deletes a pattern does."""
    widget = QtGui.QApplication.activeModalWidget()
    if isinstance(widget, QtGui.QMessageBox):
        out["dialogs_answered"] = out.get("dialogs_answered", 0) + 1
        button = widget.button(QtGui.QMessageBox.Yes)
        (button or widget.defaultButton()).click()


def _field_of(panel, name):
    """The panel's field of one option, found as a user finds it: by its label."""
    (label,) = [w for w in panel.form.findChildren(QtGui.QLabel) if w.text() == name.replace("_", " ")]
    form = label.parentWidget().layout()
    row, _ = form.getWidgetPosition(label)
    return form.itemAt(row, QtGui.QFormLayout.FieldRole).widget()


def _grab(path):
    Gui.updateGui()
    QtGui.QApplication.primaryScreen().grabWindow(0).save(path)


def _colours(obj):
    return [[round(c, 3) for c in colour] for colour in obj.ViewObject.DiffuseColor]


def run():
    window = Gui.getMainWindow()
    window.showMaximized()
    out["workbenches"] = sorted(Gui.listWorkbenches())
    os.environ["PATTERNS_ENGINE"] = "/nonexistent/python -m patterns"  # the engine not there at first
    Gui.activateWorkbench("PatternsWorkbench")
    Gui.updateGui()
    out["active"] = type(Gui.activeWorkbench()).__name__
    out["commands"] = sorted(c for c in Gui.listCommands() if c.startswith("Patterns_"))
    from freecad.patterns_wb import commands
    from freecad.patterns_wb.engine import engine

    out["missing"], out["dialogs"] = out["dialogs"], []
    out["started_without"] = engine().alive()
    del os.environ["PATTERNS_ENGINE"]  # now it is (engine.json's): the commands work, no restart
    doc = FreeCAD.newDocument("gui")
    box = doc.addObject("Part::Box", "Box")
    box.Length, box.Width, box.Height = 200, 100, 50
    cyl = doc.addObject("Part::Cylinder", "Cylinder")
    cyl.Radius, cyl.Height = 20, 50
    cut = doc.addObject("Part::Cut", "Cut")
    cut.Base, cut.Tool = box, cyl
    doc.recompute()
    cut.ViewObject.DiffuseColor = [(0.2, 0.4, 0.8, 0.0)] * len(cut.Shape.Faces)
    Gui.SendMsgToActiveView("ViewFit")
    computed = [engine().request("stats")["computed"]]
    Gui.Selection.clearSelection()
    Gui.Selection.addSelection(cut)
    Gui.runCommand("Patterns_Flatten")
    Gui.updateGui()
    panel = commands.open_panel
    out["panel_open"] = bool(Gui.Control.activeDialog())
    out["panel_height"] = panel.form.sizeHint().height()
    if os.environ.get("PANEL"):
        _grab(os.environ["PANEL"])
    _field_of(panel, "seam_allowance").setText("5")
    _field_of(panel, "max_strain").setText("0.03")
    accepted = panel.accept()
    Gui.updateGui()
    computed.append(engine().request("stats")["computed"])
    pattern = doc.getObject("Pattern")
    out["accepted"] = accepted
    out["engine_started"] = engine().alive()
    pattern.Placement.Base = FreeCAD.Vector(0, -450, 0)
    doc.recompute()
    computed.append(engine().request("stats")["computed"])
    out["computed"] = computed
    out["pattern_ok"] = bool(pattern.Ok)
    pattern.ViewObject.Proxy.doubleClicked(pattern.ViewObject)
    Gui.updateGui()
    out["edit_open"] = bool(Gui.Control.activeDialog())
    Gui.ActiveDocument.resetEdit()
    Gui.Selection.clearSelection()
    Gui.Selection.addSelection(pattern)
    Gui.runCommand("Patterns_Check")
    out["check"] = out["dialogs"].pop()[2] if out["dialogs"] else ""
    _overlay_and_delete(doc, cut, pattern)


def _overlay_and_delete(doc, cut, pattern):
    """The strain overlay on, off, on again; the pattern deleted (FreeCAD's question answered yes); then
    FreeCAD's own Unwrap Mesh, the docs' picture and the modules of this process."""
    colours = {"own": _colours(cut)}
    pattern.ShowStrain = True
    colours["strain"] = _colours(cut)
    pattern.ShowStrain = False
    colours["off"] = _colours(cut)
    pattern.ShowStrain = True
    colours["overlay_again"] = _colours(cut)
    Gui.Selection.clearSelection()
    Gui.Selection.addSelection(pattern)
    timer = QtGui.QApplication.instance().findChild(QtGui.QWidget)  # noqa: F841 - keeps the app's children alive
    from PySide import QtCore

    answer = QtCore.QTimer()
    answer.timeout.connect(_yes)
    answer.start(200)
    Gui.runCommand("Std_Delete")
    answer.stop()
    Gui.updateGui()
    colours["deleted"] = _colours(cut)
    out["colours"] = colours
    out["left"] = [o.Name for o in doc.Objects]
    import flatmesh
    import MeshPart
    import numpy as np
    import Part

    mesh = MeshPart.meshFromShape(Shape=Part.makeSphere(20, FreeCAD.Vector(), FreeCAD.Vector(0, 0, 1), 0, 90),
                                  LinearDeflection=1)
    unwrapper = flatmesh.FaceUnwrapper(np.array([[p.x, p.y, p.z] for p in mesh.Points]),
                                       np.array([list(f) for f in mesh.Topology[1]]))
    unwrapper.findFlatNodes(5, 0.95)
    out["flatmesh"] = len(unwrapper.ze_nodes)
    _picture(os.environ["SHOT"])
    prefix = os.path.realpath(os.environ["ENGINE_PREFIX"])
    out["foreign"] = sorted(name for name, module in list(sys.modules.items())
                            if os.path.realpath(getattr(module, "__file__", None) or "/").startswith(prefix))


def _picture(path):
    """docs/freecad.md's picture: the four-panel cup sample, its pattern beside it (10 mm seam allowance,
    checked at 15 %), the strain overlay on the cup."""
    import Part
    from freecad.patterns_wb import make_pattern

    doc = FreeCAD.newDocument("cup")
    cup = doc.addObject("Part::Feature", "Cup")
    cup.Shape = Part.read(os.path.join(os.environ["SAMPLES"], "cup.step"))
    doc.recompute()
    pattern = make_pattern(cup, seam_allowance=10, max_strain=0.15)
    pattern.Placement.Base = FreeCAD.Vector(130, -60, 0)
    pattern.ShowStrain = True
    doc.recompute()
    Gui.Selection.clearSelection()
    view = Gui.activeDocument().activeView()
    view.viewAxonometric()
    Gui.updateGui()
    view.fitAll()
    Gui.updateGui()
    _grab(path)
    out["picture_ok"] = bool(pattern.isValid())


try:
    run()
except Exception:  # noqa: BLE001 - said to the test
    out["traceback"] = traceback.format_exc()
with open(os.environ["OUT"], "w", encoding="utf-8") as f:
    json.dump(out, f)
os._exit(0)
