"""Patterns for Blender: mark seams, get a sewing pattern that sews back true (docs/blender.md).

Blender and the standard library only: the engine (``patterns serve``) runs beside Blender in its own
environment, started from what ``patterns blender install`` recorded in ``engine.json`` beside this file.
"""

bl_info = {
    "name": "Patterns",
    "author": "patterns",
    "version": (0, 2, 0),
    "blender": (4, 2, 0),
    "location": "View3D > Sidebar > Patterns",
    "description": "Sewing patterns from marked seams: seams held to their 3D length, strain on the model, darts, "
                   "seam allowance, DXF and SVG for cutters",
    "category": "Import-Export",
}


def register():
    from . import ui

    ui.register()


def unregister():
    from . import ui

    ui.unregister()
