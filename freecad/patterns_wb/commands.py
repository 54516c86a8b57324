"""The workbench's commands: Flatten, Unfold, Check and Export.

Flatten and Unfold take the selection (an object, or some of its faces), ask for their options in a
task panel made from the option records, and add a parametric ``Pattern`` or ``Blank``
(:func:`patterns.freecad.make_pattern`, :func:`patterns.freecad.make_blank`).  Check shows the
selected pattern's or blank's report; Export writes it with the project's writers (DXF, SVG, the JSON
report), never FreeCAD's DXF exporter.
"""

import os

import FreeCAD
import FreeCADGui as Gui

from . import ICONS

COMMANDS = ("Patterns_Flatten", "Patterns_Unfold", "Patterns_Check", "Patterns_Export")
"""The commands, in the toolbar's order."""


def _selection():
    """``(object, [sub-element names])`` of the first selected object with a shape, or None."""
    for sel in Gui.Selection.getSelectionEx():
        if getattr(sel.Object, "Shape", None) is not None:
            faces = [name for name in sel.SubElementNames if name.startswith("Face")]
            return sel.Object, faces
    return None


def _made():
    """The selected Pattern or Blank object, or None."""
    from patterns.freecad import BlankFeature, PatternFeature

    for obj in Gui.Selection.getSelection():
        if isinstance(getattr(obj, "Proxy", None), (PatternFeature, BlankFeature)):
            return obj
    return None


class _Make:
    """Flatten or Unfold: a task panel of options, then the parametric object."""

    def __init__(self, kind: str):
        self.kind = kind

    def GetResources(self):
        what = {"Pattern": ("flatten", "Flatten", "Lay the selected faces flat as a parametric cutting pattern"),
                "Blank": ("unfold", "Unfold", "Unfold the selected bent sheet-metal part into a parametric blank")}
        icon, text, tip = what[self.kind]
        return {"Pixmap": os.path.join(ICONS, f"{icon}.svg"), "MenuText": text, "ToolTip": tip}

    def IsActive(self):
        return FreeCAD.ActiveDocument is not None and _selection() is not None

    def Activated(self):
        import patterns.freecad as pf
        from patterns.freecad.features import BLANK_GROUPS, BLANK_RECORDS, BLANK_SKIP, PATTERN_GROUPS, PATTERN_RECORDS

        from .panels import OptionsPanel

        source = _selection()
        if self.kind == "Pattern":
            records, titles, skip, make = PATTERN_RECORDS, PATTERN_GROUPS, (), pf.make_pattern
        else:
            records, titles, skip, make = BLANK_RECORDS, BLANK_GROUPS, BLANK_SKIP, pf.make_blank
        panel = OptionsPanel(f"patterns: {self.kind.lower()} {source[0].Label}", records, titles,
                             lambda options: make(source, **options), skip)
        Gui.Control.showDialog(panel)


class _Check:
    def GetResources(self):
        return {"Pixmap": os.path.join(ICONS, "check.svg"), "MenuText": "Check",
                "ToolTip": "Show the check report of the selected pattern or blank"}

    def IsActive(self):
        return _made() is not None

    def Activated(self):
        from PySide import QtGui

        import patterns.freecad as pf

        report = pf.report_of(_made())
        FreeCAD.Console.PrintMessage(f"{report}\n")
        QtGui.QMessageBox.information(Gui.getMainWindow(), "patterns", str(report))


class _Export:
    def GetResources(self):
        return {"Pixmap": os.path.join(ICONS, "export.svg"), "MenuText": "Export",
                "ToolTip": "Write the selected pattern or blank as DXF, SVG or the JSON report"}

    def IsActive(self):
        return _made() is not None

    def Activated(self):
        from PySide import QtGui

        import patterns.freecad as pf

        obj = _made()
        path, _ = QtGui.QFileDialog.getSaveFileName(Gui.getMainWindow(), "Export the pieces", f"{obj.Label}.dxf",
                                                    "DXF (*.dxf);;SVG (*.svg);;JSON report (*.json)")
        if path:
            try:
                pf.export(obj, path)
            except Exception as exc:  # noqa: BLE001 - shown to the user
                QtGui.QMessageBox.critical(Gui.getMainWindow(), "patterns", str(exc))


def register():
    """Add the commands to FreeCAD."""
    for name, command in zip(COMMANDS, (_Make("Pattern"), _Make("Blank"), _Check(), _Export())):
        Gui.addCommand(name, command)
