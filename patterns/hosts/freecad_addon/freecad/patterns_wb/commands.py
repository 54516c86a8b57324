"""The workbench's commands: Flatten, Unfold, Check and Export.

Flatten and Unfold take the selection (an object, or some of its faces; for Unfold one face of a solid is
its fixed face), ask for the options in a task panel made from the engine's option schema, and add a
parametric ``Pattern`` or ``Blank``.  Check shows the selected object's verdict and figures; Export writes
it with the engine's writers (DXF, SVG, the JSON report), never FreeCAD's DXF exporter.  Where the engine
cannot answer, a dialog says what to run; nothing is added.
"""

import json
import os

import FreeCAD
import FreeCADGui as Gui

from .engine import ICONS, EngineError, engine

COMMANDS = ("Patterns_Flatten", "Patterns_Unfold", "Patterns_Check", "Patterns_Export")
"""The commands, in the toolbar's order."""
open_panel = None
"""The last task panel Flatten or Unfold opened (for macros and tests)."""


def _window():
    return Gui.getMainWindow()


def tell(title, text, *, error=True):
    """One dialog (and the Report view) saying ``text``."""
    from PySide import QtGui

    (FreeCAD.Console.PrintError if error else FreeCAD.Console.PrintMessage)(f"patterns: {text}\n")
    box = QtGui.QMessageBox.critical if error else QtGui.QMessageBox.information
    box(_window(), title, text)


def warm():
    """Start the engine (the workbench was activated); a dialog with the commands to run if it cannot."""
    try:
        engine().start()
    except EngineError as exc:
        tell("patterns: the engine is not available", str(exc))


def _selection():
    """``(object, [face names])`` of the first selected object with a shape, or None."""
    for sel in Gui.Selection.getSelectionEx():
        if getattr(sel.Object, "Shape", None) is not None:
            return sel.Object, [n for n in sel.SubElementNames if n.startswith("Face")]
    return None


def _made():
    """The selected Pattern or Blank object, or None."""
    from .features import BlankFeature, PatternFeature

    for obj in Gui.Selection.getSelection():
        if isinstance(getattr(obj, "Proxy", None), (PatternFeature, BlankFeature)):
            return obj
    return None


class _Make:
    """Flatten or Unfold: a task panel of options, then the parametric object."""

    def __init__(self, kind):
        self.kind = kind

    def GetResources(self):
        what = {"pattern": ("flatten", "Flatten", "Lay the selected object or faces flat as a parametric pattern"),
                "blank": ("unfold", "Unfold", ("Unfold the selected bent part into a parametric blank (a selected "
                                              "face stays put)"))}
        icon, text, tip = what[self.kind]
        return {"Pixmap": os.path.join(ICONS, f"{icon}.svg"), "MenuText": text, "ToolTip": tip}

    def IsActive(self):
        return FreeCAD.ActiveDocument is not None and _selection() is not None

    def Activated(self):
        from . import features
        from .panels import CreatePanel

        source, faces = _selection()
        try:
            schema = engine().options[self.kind]
        except EngineError as exc:
            tell("patterns: the engine is not available", str(exc))
            return
        make = features.make_pattern if self.kind == "pattern" else features.make_blank
        fixed = features._fixed_face(faces) if self.kind == "blank" else None
        global open_panel
        open_panel = CreatePanel(f"patterns: {self.kind} of {source.Label}", schema,
                                 lambda options: make((source, faces), **options), {"fixed_face": fixed} if fixed else {})
        Gui.Control.showDialog(open_panel)


def describe(obj):
    """The check's verdict and figures of a Pattern or Blank object, as lines a person reads."""
    figures = json.loads(obj.Figures) if obj.Figures else {}
    limit = figures.get("max_strain")
    lines = [obj.Report.splitlines()[0] if obj.Report else obj.Label]
    lines.append(f"checked against a strain limit of {limit * 100:.2f} %" if limit else "no strain limit given "
                 "(set max_strain on the Check page)")
    if figures.get("strain_max") is not None and figures.get("panels"):
        at = figures.get("strain_max_at") or [0, 0]
        lines.append(f"worst strain {figures['strain_max'] * 100:.2f} % in {figures['strain_max_panel']} "
                     f"at ({at[0]:.1f}, {at[1]:.1f}) mm")
    if figures.get("share_above_limit") is not None:
        lines.append(f"{figures['share_above_limit'] * 100:.1f} % of the area above the limit")
    if figures.get("seam_mismatch") is not None:
        lines.append(f"largest seam mismatch {figures['seam_mismatch']:.3f} mm ({figures['seam_mismatch_at']})")
    lines += obj.Report.splitlines()[1:]
    return "\n".join(lines)


class _Check:
    def GetResources(self):
        return {"Pixmap": os.path.join(ICONS, "check.svg"), "MenuText": "Check",
                "ToolTip": "Show the verdict and the figures of the selected pattern or blank"}

    def IsActive(self):
        return _made() is not None

    def Activated(self):
        obj = _made()
        tell(f"patterns: {obj.Label}", describe(obj), error=not obj.Ok)


class _Export:
    def GetResources(self):
        return {"Pixmap": os.path.join(ICONS, "export.svg"), "MenuText": "Export",
                "ToolTip": "Write the selected pattern or blank as DXF, SVG or the JSON report"}

    def IsActive(self):
        return _made() is not None

    def Activated(self):
        from PySide import QtGui

        from .features import PatternsError, export

        obj = _made()
        path, _ = QtGui.QFileDialog.getSaveFileName(_window(), "Export the pieces", f"{obj.Label}.dxf",
                                                    "DXF (*.dxf);;SVG (*.svg);;JSON report (*.json)")
        if path:
            try:
                export(obj, path)
            except PatternsError as exc:
                tell("patterns", str(exc))


def register():
    """Add the commands to FreeCAD."""
    for name, command in zip(COMMANDS, (_Make("pattern"), _Make("blank"), _Check(), _Export())):
        Gui.addCommand(name, command)
