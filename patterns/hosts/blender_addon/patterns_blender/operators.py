"""The operators: ``patterns.flatten``, ``patterns.check`` and ``patterns.export``.

Each sends the selected meshes, their marked seams and the scene's options to the engine; an error is one
report in Blender's status bar (no traceback): no mesh selected, a mesh the engine refuses (non-manifold,
closed without seams, ...), the engine missing (with the commands that install it).
"""

import os

import bpy

from . import geometry, settings
from .engine import EngineError, Refused, engine


def _meshes(context):
    return [o for o in context.selected_objects if o.type == "MESH"]


def _make(context, obj):
    """``(reply, triangles' polygons, polygon count, mm per unit)`` of the engine's pattern of ``obj``."""
    scale = geometry.mm_per_unit(context.scene)
    mesh, polygons, n_polygons = geometry.mesh_of(obj, context.evaluated_depsgraph_get(), scale)
    reply = engine().request("make", kind="pattern", name=obj.name, mesh=mesh,
                             options=settings.values(context.scene.patterns))
    return reply, polygons, n_polygons, scale, mesh


def _failed(operator, exc) -> set:
    message = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
    operator.report({"ERROR"}, f"patterns: {message}")
    return {"CANCELLED"}


class PATTERNS_OT_flatten(bpy.types.Operator):
    """Flatten the selected meshes along their marked seams into a 1:1 pattern (pieces in the XY plane)"""

    bl_idname = "patterns.flatten"
    bl_label = "Flatten"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        objects = _meshes(context)
        if not objects:
            self.report({"ERROR"}, "patterns: select one or more mesh objects to flatten")
            return {"CANCELLED"}
        said = []
        for obj in objects:
            try:
                reply, polygons, n_polygons, scale, mesh = _make(context, obj)
            except (EngineError, Refused) as exc:
                return _failed(self, exc)
            limit = settings.limit(context.scene.patterns)
            geometry.add_pieces(obj, reply["flat"], scale, context, limit)
            painted = geometry.paint_strain(obj, reply["triangle_strain"], polygons, n_polygons, limit)
            figures = reply["figures"]
            seams = "" if mesh["seams"] else " (no seams marked: one panel per connected part)"
            said.append(f"{obj.name}: {reply['pieces']} pieces, worst strain {100 * (figures['strain_max'] or 0):.2f} %"
                        f"{'' if reply['ok'] else ', NOT ok'}{seams}"
                        f"{'' if painted else '; strain not shown on the model (its modifiers change its faces)'}")
        self.report({"INFO"}, "; ".join(said))
        return {"FINISHED"}


class PATTERNS_OT_check(bpy.types.Operator):
    """Check the selected meshes' patterns: the verdict, the worst strain and where, the seams' mismatch"""

    bl_idname = "patterns.check"
    bl_label = "Check"

    def execute(self, context):
        objects = _meshes(context)
        if not objects:
            self.report({"ERROR"}, "patterns: select one or more mesh objects to check")
            return {"CANCELLED"}
        for obj in objects:
            try:
                reply = _make(context, obj)[0]
            except (EngineError, Refused) as exc:
                return _failed(self, exc)
            f = reply["figures"]
            mismatch = "" if f["seam_mismatch"] is None else f", seam mismatch {f['seam_mismatch']:.3f} mm"
            self.report({"INFO"} if f["ok"] else {"WARNING"},
                        f"{obj.name}: {'ok' if f['ok'] else 'NOT ok'}, {f['panels']} panels, {f['seams']} seams, "
                        f"worst strain {100 * (f['strain_max'] or 0):.2f} % on {f['strain_max_panel']}{mismatch}")
            context.scene.patterns_report = reply["report"]
        return {"FINISHED"}


class PATTERNS_OT_export(bpy.types.Operator):
    """Write the active mesh's pattern: DXF (machine or ASTM), SVG or the JSON report, by the file's suffix"""

    bl_idname = "patterns.export"
    bl_label = "Export Pattern"

    filepath: bpy.props.StringProperty(name="File", subtype="FILE_PATH",
                                       description="A .dxf, .svg or .json file")
    profile: bpy.props.EnumProperty(name="DXF", items=[("machine", "Machine", "DXF for lasers, knives, plotters"),
                                                       ("astm", "ASTM D6673", "DXF for garment CAD")],
                                    default="machine")
    filter_glob: bpy.props.StringProperty(default="*.dxf;*.svg;*.json", options={"HIDDEN"})

    def invoke(self, context, event):
        obj = context.active_object
        if not self.filepath and obj is not None:
            self.filepath = bpy.path.ensure_ext(bpy.path.clean_name(obj.name), ".dxf")
        context.window_manager.fileselect_add(self)
        return {"RUNNING_MODAL"}

    def execute(self, context):
        obj = context.active_object
        if obj is None or obj.type != "MESH":
            self.report({"ERROR"}, "patterns: make a mesh object active to export its pattern")
            return {"CANCELLED"}
        path = os.path.abspath(bpy.path.abspath(self.filepath))  # the engine runs in another folder
        if not path.lower().endswith((".dxf", ".svg", ".json")):
            self.report({"ERROR"}, f"patterns: {path}: write a .dxf, .svg or .json file")
            return {"CANCELLED"}
        scale = geometry.mm_per_unit(context.scene)
        mesh = geometry.mesh_of(obj, context.evaluated_depsgraph_get(), scale)[0]
        write = {"profile": self.profile} if path.lower().endswith(".dxf") else {}
        try:
            engine().request("export", kind="pattern", name=obj.name, mesh=mesh,
                             options=settings.values(context.scene.patterns), path=path, write=write)
        except (EngineError, Refused) as exc:
            return _failed(self, exc)
        self.report({"INFO"}, f"patterns: wrote {path}")
        return {"FINISHED"}


CLASSES = (PATTERNS_OT_flatten, PATTERNS_OT_check, PATTERNS_OT_export)
