"""Run in FreeCAD's GUI (``xvfb-run freecad freecad_gui_run.py``, the repository linked into the user's Mod
folder): activates the patterns workbench, lists its commands, makes a pattern of a Part::Cut, saves a
screenshot to ``$SHOT`` and the findings as JSON to ``$OUT``, then quits."""

import json
import os
import traceback

import FreeCAD
import FreeCADGui as Gui

out = {}
try:
    out["workbenches"] = sorted(Gui.listWorkbenches())
    Gui.activateWorkbench("PatternsWorkbench")
    out["active"] = type(Gui.activeWorkbench()).__name__
    out["commands"] = sorted(c for c in Gui.listCommands() if c.startswith("Patterns_"))
    import patterns.freecad as pf

    doc = FreeCAD.newDocument("gui")
    box = doc.addObject("Part::Box", "Box")
    box.Length, box.Width, box.Height = 200, 100, 50
    cyl = doc.addObject("Part::Cylinder", "Cylinder")
    cyl.Radius, cyl.Height = 20, 50
    cut = doc.addObject("Part::Cut", "Cut")
    cut.Base, cut.Tool = box, cyl
    doc.recompute()
    pattern = pf.make_pattern(cut, seam_allowance=5)
    pattern.Placement.Base = FreeCAD.Vector(0, -450, 0)
    doc.recompute()
    out["pattern_ok"] = bool(pattern.Ok)
    Gui.SendMsgToActiveView("ViewFit")
    Gui.activeDocument().activeView().viewIsometric()
    Gui.SendMsgToActiveView("ViewFit")
    Gui.updateGui()
    view = os.environ.get("VIEW")
    if view:  # the 3D view alone, rendered off screen (what the window grab leaves to OpenGL)
        Gui.activeDocument().activeView().saveImage(view, 1200, 800, "White")
    from PySide import QtGui

    window = Gui.getMainWindow()
    window.showMaximized()
    Gui.updateGui()
    Gui.SendMsgToActiveView("ViewFit")
    Gui.updateGui()
    # the screen as the X server shows it: the 3D view (OpenGL) included, which a widget grab leaves blank
    Gui.Selection.clearSelection()
    Gui.updateGui()
    QtGui.QApplication.primaryScreen().grabWindow(0).save(os.environ["SHOT"])
    panel = os.environ.get("PANEL")
    if panel:  # the Flatten command's task panel, its options made from the option records
        Gui.Selection.clearSelection()
        Gui.Selection.addSelection(cut)
        Gui.runCommand("Patterns_Flatten")
        Gui.updateGui()
        QtGui.QApplication.primaryScreen().grabWindow(0).save(panel)
        out["panel"] = bool(Gui.Control.activeDialog())
except Exception:  # noqa: BLE001 - said to the test
    out["traceback"] = traceback.format_exc()
with open(os.environ["OUT"], "w", encoding="utf-8") as f:
    json.dump(out, f)
os._exit(0)
