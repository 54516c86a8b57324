"""The patterns workbench's GUI: a toolbar and a menu with Flatten, Unfold, Check and Export."""

import os

import FreeCADGui as Gui

from .engine import ICONS


class PatternsWorkbench(Gui.Workbench):
    """Flat, seam-true, strain-checked patterns of any face, and sheet-metal blanks, parametric."""

    MenuText = "Patterns"
    ToolTip = "Flatten faces into cutting patterns and unfold bent sheet metal, live in the document"
    Icon = os.path.join(ICONS, "patterns.svg")

    def Initialize(self):
        from . import commands

        commands.register()
        self.appendToolbar("Patterns", list(commands.COMMANDS))
        self.appendMenu("Patterns", list(commands.COMMANDS))

    def Activated(self):
        """Start the engine now, so the first Flatten does not wait; where it cannot start, one dialog says
        the commands to run (the commands stay, and work once that is done, without a restart)."""
        from . import commands

        commands.warm()

    def GetClassName(self):
        return "Gui::PythonWorkbench"


Gui.addWorkbench(PatternsWorkbench())
