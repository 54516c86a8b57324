"""How patterns, blanks and marks look in the GUI: icons, marks under their pattern, double-click for the
options, and the strain overlay on the source's faces (switched on and off, the part's own colours back)."""

import json
import os

import FreeCAD

from .engine import ICONS
from .proxies import Stateless, marks_of

_ACI = {1: (1.0, 0.0, 0.0), 2: (0.8, 0.7, 0.0), 3: (0.0, 0.6, 0.0), 4: (0.0, 0.7, 0.7), 5: (0.0, 0.0, 1.0),
        6: (0.8, 0.0, 0.8), 7: (0.1, 0.1, 0.1)}
"""The AutoCAD colours (ACI) of the layers, as FreeCAD's view shows them."""


def _gui(obj):
    return FreeCAD.GuiUp and getattr(obj, "ViewObject", None) is not None


class ViewPieces(Stateless):
    """The view of a pattern or blank: its Marks under it in the tree, its icon, its options on double-click,
    and, when it goes, its source's own colours back."""

    def __init__(self, view):
        view.Proxy = self

    def attach(self, view):
        self.Object = view.Object

    def claimChildren(self):
        return marks_of(self.Object)

    def getIcon(self):
        return os.path.join(ICONS, "flatten.svg" if self.Object.Proxy.KIND == "pattern" else "unfold.svg")

    def doubleClicked(self, view):
        import FreeCADGui as Gui

        Gui.ActiveDocument.setEdit(view.Object.Name, 0)
        return True

    def setEdit(self, view, mode=0):
        if mode != 0:
            return None  # the transform dragger and the other modes: FreeCAD's own
        import FreeCADGui as Gui

        from .panels import EditPanel

        Gui.Control.showDialog(EditPanel(view.Object))
        return True

    def unsetEdit(self, view, mode=0):
        import FreeCADGui as Gui

        Gui.Control.closeDialog()
        return True

    def onDelete(self, view, subelements):
        obj = view.Object
        if "SourceColours" in obj.PropertiesList:
            restore_colours(obj)
        for child in self.claimChildren():
            child.Document.removeObject(child.Name)
        return True


class ViewMarks(ViewPieces):
    """The view of a Marks object: lines in the colour of its role's layer, labels as points."""

    def claimChildren(self):
        return []

    def getIcon(self):
        return os.path.join(ICONS, "patterns.svg")

    def doubleClicked(self, view):
        return False

    def setEdit(self, view, mode=0):
        return None  # FreeCAD's own (a Marks object has no options)

    def onDelete(self, view, subelements):
        return True


def view_pieces(obj):
    if _gui(obj):
        ViewPieces(obj.ViewObject)


def view_marks(obj, colour):
    """Give a new Marks object its view, in ``colour`` (its layer's ACI number, the engine's)."""
    if _gui(obj):
        ViewMarks(obj.ViewObject)
        obj.ViewObject.LineColor = _ACI.get(colour, (0.1, 0.1, 0.1))
        obj.ViewObject.PointColor = obj.ViewObject.LineColor
        obj.ViewObject.PointSize = 4.0


def _limit(obj):
    figures = json.loads(obj.Figures) if obj.Figures else {}
    return figures.get("max_strain") or getattr(obj, "dart_strain", "") and float(obj.dart_strain) or 0.05


def restore_colours(obj):
    """Give the source back its own face colours (kept while the strain was shown)."""
    source = obj.Source[0] if obj.Source else None
    if obj.SourceColours and source is not None and _gui(source):
        source.ViewObject.DiffuseColor = [tuple(c) for c in json.loads(obj.SourceColours)]
    obj.SourceColours = ""


def show_strain(obj):
    """Colour the source's faces by their strain when ``ShowStrain`` is on (white none, red at the check's
    limit, or the darts', or 5 %); its own colours back when off."""
    source = obj.Source[0] if obj.Source else None
    if source is None or not _gui(source):
        return
    if not obj.ShowStrain:
        restore_colours(obj)
        return
    if obj.Source[1] or not obj.FaceStrain:
        return
    if not obj.SourceColours:
        obj.SourceColours = json.dumps([list(c) for c in source.ViewObject.DiffuseColor])
    limit = _limit(obj)
    own = [tuple(c) for c in json.loads(obj.SourceColours)] or [(0.8, 0.8, 0.8, 0.0)]
    colours = []
    for i, strain in enumerate(obj.FaceStrain):
        t = min(max(strain / limit, 0.0), 1.0)  # the 4th value as the part's own (transparency, or 1.0's alpha)
        colours.append((1.0, 1.0 - t, 1.0 - t, own[min(i, len(own) - 1)][3]))
    source.ViewObject.DiffuseColor = colours
