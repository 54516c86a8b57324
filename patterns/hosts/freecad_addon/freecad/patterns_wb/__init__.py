"""The patterns workbench for FreeCAD: flat patterns and sheet-metal blanks, parametric in the document.

FreeCAD imports this package at start-up (in the GUI and in ``freecadcmd``) from its ``Mod`` folder, where
``patterns freecad install`` put it.  It imports nothing at start-up and changes nothing of FreeCAD's
Python: the engine runs beside FreeCAD, in its own process and environment (:mod:`.engine`).  For
scripts and the Python console::

    from freecad.patterns_wb import make_pattern, make_blank, export, report_of

The GUI part is ``init_gui``.
"""

__all__ = ["PatternsError", "export", "make_blank", "make_pattern", "report_of"]

def __getattr__(name):
    """The scripting API, imported when first asked for (FreeCAD's start-up stays light)."""
    if name in __all__:
        from . import features

        return getattr(features, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
