"""The patterns workbench for FreeCAD: flat patterns and sheet-metal blanks, parametric in the document.

FreeCAD imports this package at start-up (in the GUI and in ``freecadcmd``), from the addon's folder
in ``Mod`` (its ``freecad/`` namespace folder).  It puts the folders of the Python packages
``patterns`` needs that FreeCAD's own Python lacks -- numpy 2, build123d, spyrrow, qdldl: see
docs/freecad.md for the one command that installs them -- in front of FreeCAD's path, so that the
workbench and ``import patterns.freecad`` in the Python console find them.  The GUI part is
``init_gui``.
"""

import os
import site
import sys

import FreeCAD

HERE = os.path.dirname(os.path.abspath(__file__))
ICONS = os.path.join(HERE, "resources", "icons")
"""The workbench's icons."""

DEPENDENCIES = os.path.join(FreeCAD.getUserAppDataDir(), "patterns", "site-packages")
"""Where docs/freecad.md's command installs what FreeCAD's Python lacks (``pip install --target``)."""


def dependency_folders() -> list:
    """The folders put in front of FreeCAD's path: ``$PATTERNS_SITE`` (a virtual environment's
    site-packages), then :data:`DEPENDENCIES`, those that exist."""
    folders = [os.environ.get("PATTERNS_SITE", ""), DEPENDENCIES]
    return [f for f in folders if f and os.path.isdir(f)]


def use_dependencies() -> list:
    """Put :func:`dependency_folders` in front of ``sys.path`` (their ``.pth`` files read too); returns them."""
    folders = dependency_folders()
    before = list(sys.path)
    for folder in reversed(folders):
        site.addsitedir(folder)
    added = [p for p in sys.path if p not in before]
    sys.path[:] = added + [p for p in before if p not in added]
    return folders


use_dependencies()
