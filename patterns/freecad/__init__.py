"""Deprecated: ``patterns.freecad`` ran the engine inside FreeCAD's own Python; it now runs beside it.

Since 0.2.0 the workbench (``patterns freecad install``) imports nothing of the engine's environment into
FreeCAD: scripts use ``from freecad.patterns_wb import make_pattern, make_blank, export, report_of``,
the same functions with the same options.  This module forwards those names to the workbench, with a
``DeprecationWarning``, where both can be imported (a FreeCAD whose path was set up for 0.1.0); it goes
in 0.3.0 (CHANGELOG.md).
"""

import importlib
import warnings

warnings.warn("patterns.freecad is deprecated and goes in 0.3.0: use `from freecad.patterns_wb import make_pattern, "
              "make_blank, export, report_of` (run `patterns freecad install` once; docs/freecad.md)",
              DeprecationWarning, stacklevel=2)

__all__ = ["export", "make_blank", "make_pattern", "report_of"]


def __getattr__(name: str):
    """The workbench's function of that name (``freecad.patterns_wb``)."""
    if name in __all__:
        return getattr(importlib.import_module("freecad.patterns_wb"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
