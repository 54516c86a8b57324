"""The sidebar panel (View3D > Sidebar > Patterns) and the add-on's registration."""

import bpy

from . import operators, settings


class PATTERNS_PT_panel(bpy.types.Panel):
    bl_label = "Patterns"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "Patterns"

    def draw(self, context):
        layout = self.layout
        options = context.scene.patterns
        if not settings.properties():
            layout.label(text="Run `patterns blender install` (no options recorded)", icon="ERROR")
        shown = {p["name"] for p in settings.properties()}
        for name in settings.MAIN:
            if name in shown:
                layout.prop(options, name)
        row = layout.row(align=True)
        row.operator("patterns.flatten", icon="MOD_UVPROJECT")
        row.operator("patterns.check", icon="CHECKMARK")
        layout.operator("patterns.export", icon="EXPORT")


class PATTERNS_PT_options(bpy.types.Panel):
    bl_label = "All options"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "Patterns"
    bl_parent_id = "PATTERNS_PT_panel"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        options = context.scene.patterns
        group = None
        for p in settings.properties():
            if p["group"] != group:
                group = p["group"]
                self.layout.label(text=group)
            self.layout.prop(options, p["name"])


_REGISTERED = []


def register():
    classes = (settings.settings_class(), *operators.CLASSES, PATTERNS_PT_panel, PATTERNS_PT_options)
    for cls in classes:
        bpy.utils.register_class(cls)
    _REGISTERED[:] = classes
    bpy.types.Scene.patterns = bpy.props.PointerProperty(type=classes[0])
    bpy.types.Scene.patterns_report = bpy.props.StringProperty(name="Patterns report", default="")


def unregister():
    del bpy.types.Scene.patterns
    del bpy.types.Scene.patterns_report
    for cls in reversed(_REGISTERED):
        bpy.utils.unregister_class(cls)
    _REGISTERED.clear()
