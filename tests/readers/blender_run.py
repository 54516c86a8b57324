# ruff: noqa: I001 - bpy first: it puts Blender's own modules (addon_utils) on the path
"""Run with Blender's Python (``bpy`` as a module) and ``BLENDER_USER_SCRIPTS=<dir>``, the add-on installed in
``<dir>/addons`` by ``patterns blender install --target``, ``OUT=<folder>``: enables the add-on with
``addon_utils`` as Blender's Preferences do, runs its operators on a tube, a hemisphere and bad input, and
writes what it saw to ``OUT/blender.json`` (the meshes sent, the pieces made, the reports, the files written).
Nothing of the engine's is imported here: the add-on starts ``patterns serve`` beside Blender."""

import json
import math
import os
import sys

import bpy  # first: it puts Blender's own modules (addon_utils) on the path

import addon_utils

OUT = os.environ["OUT"]
seen = {"modules": []}


def error_of(call):
    """The message of an operator that reports an error (Blender raises it as a RuntimeError), or None."""
    try:
        call()
    except RuntimeError as exc:
        return str(exc)
    return None


def fresh():
    bpy.ops.object.select_all(action="SELECT")
    bpy.ops.object.delete()
    for c in list(bpy.data.collections):
        bpy.data.collections.remove(c)


def pieces_of(obj):
    out = []
    for piece in bpy.data.collections[obj.name + " pattern"].objects:
        if piece.parent is not None:
            continue
        me = piece.data
        strain = me.attributes["patterns_strain"]
        out.append({"name": piece.name, "panel": piece["patterns_panel"],
                    "vertices": [list(v.co) for v in me.vertices], "faces": [list(p.vertices) for p in me.polygons],
                    "strain": [d.value for d in strain.data],
                    "domain": strain.domain})
    return out


def sent(obj):
    """The mesh the add-on sends (the add-on's own function: what the engine got)."""
    from patterns_blender import geometry

    scale = geometry.mm_per_unit(bpy.context.scene)
    return geometry.mesh_of(obj, bpy.context.evaluated_depsgraph_get(), scale)[0]


addon_utils.enable("patterns_blender", default_set=True, handle_error=None)
seen["enabled"] = hasattr(bpy.types.Scene, "patterns")

# 1. An open tube, 50 mm radius (0.05 m in a default scene), 100 mm high, cut along one vertical seam
fresh()
bpy.ops.mesh.primitive_cylinder_add(vertices=64, radius=0.05, depth=0.1, end_fill_type="NOTHING")
tube = bpy.context.active_object
tube.name = "Tube"
for e in tube.data.edges:
    a, b = (tube.data.vertices[i].co for i in e.vertices)
    if abs(a.x - b.x) < 1e-9 and abs(a.y - b.y) < 1e-9 and a.x > 0.0499:
        e.use_seam = True
seen["tube_sent"] = sent(tube)
bpy.ops.patterns.flatten()
seen["tube_pieces"] = pieces_of(tube)
seen["tube_face_strain"] = [d.value for d in tube.data.attributes["patterns_strain"].data]
seen["tube_colour"] = tube.data.color_attributes.active_color.name
for name in ("tube.dxf", "tube.svg", "tube.json"):
    bpy.ops.patterns.export(filepath=os.path.join(OUT, name))

# 2. A hemisphere, seams on four meridians, darts to 3 %; in a scene in centimetres (scale_length 0.01)
fresh()
bpy.context.scene.unit_settings.scale_length = 0.01
bpy.ops.mesh.primitive_uv_sphere_add(segments=48, ring_count=24, radius=10.0)  # 10 cm
dome = bpy.context.active_object
dome.name = "Dome"
bpy.ops.object.mode_set(mode="EDIT")
bpy.ops.mesh.select_all(action="DESELECT")
bpy.ops.object.mode_set(mode="OBJECT")
for v in dome.data.vertices:
    v.select = v.co.z < -1e-6
bpy.ops.object.mode_set(mode="EDIT")
bpy.ops.mesh.delete(type="VERT")
bpy.ops.object.mode_set(mode="OBJECT")
first = min(math.atan2(v.co.y, v.co.x) for v in dome.data.vertices if math.hypot(v.co.x, v.co.y) > 1e-6)


def meridian(p):
    """Which of four meridians 90 degrees apart (from the sphere's first) a vertex is on; -1 for the pole."""
    if math.hypot(p.x, p.y) < 1e-6:
        return -1
    turn = (math.atan2(p.y, p.x) - first) / (math.pi / 2)
    return round(turn) % 4 if abs(turn - round(turn)) < 1e-6 else None


for e in dome.data.edges:  # the four meridians, pole to equator
    a, b = (meridian(dome.data.vertices[i].co) for i in e.vertices)
    e.use_seam = a is not None and b is not None and (a == b or -1 in (a, b))
dome.select_set(True)
bpy.context.view_layer.objects.active = dome
bpy.context.scene.patterns.dart_strain = "0.03"
bpy.context.scene.patterns.seam_allowance = 10.0
seen["dome_sent"] = sent(dome)
bpy.ops.patterns.flatten()
seen["dome_pieces"] = pieces_of(dome)
bpy.ops.patterns.check()
seen["dome_report"] = bpy.context.scene.patterns_report
bpy.context.scene.patterns.width = "1500"
for name in ("dome.dxf", "dome.svg", "dome.json"):
    bpy.ops.patterns.export(filepath=os.path.join(OUT, name))
bpy.ops.patterns.export(filepath=os.path.join(OUT, "dome_astm.dxf"), profile="astm")

# 3. A real soft-goods shape: BFF's bunny head (a plush's head, one open piece), read by Blender's OBJ importer
bpy.context.scene.patterns.width = ""
bpy.context.scene.patterns.dart_strain = ""
bpy.context.scene.patterns.seam_allowance = 0.0
bpy.context.scene.unit_settings.scale_length = 1.0
corpus = os.environ.get("CORPUS", "")
if corpus and os.path.isfile(os.path.join(corpus, "bff_bunnyhead.obj")):
    fresh()
    bpy.ops.wm.obj_import(filepath=os.path.join(corpus, "bff_bunnyhead.obj"))
    bunny = bpy.context.selected_objects[0]
    bunny.name = "Bunny"
    bpy.context.view_layer.objects.active = bunny
    seen["bunny_sent"] = sent(bunny)
    bpy.ops.patterns.flatten()
    seen["bunny_pieces"] = pieces_of(bunny)
    bpy.ops.patterns.export(filepath=os.path.join(OUT, "bunny.json"))
    bpy.ops.patterns.export(filepath=os.path.join(OUT, "bunny.dxf"))

# 4. What a user gets wrong: one line each, no traceback
bpy.context.scene.patterns.width = ""
fresh()
seen["no_mesh"] = error_of(lambda: bpy.ops.patterns.flatten())
bpy.ops.mesh.primitive_uv_sphere_add(segments=16, ring_count=8, radius=0.05)
seen["closed"] = error_of(lambda: bpy.ops.patterns.flatten())
fresh()
me = bpy.data.meshes.new("fin")  # three triangles on one edge: not a surface
me.from_pydata([(0, 0, 0), (0, 0, 0.1), (0.1, 0, 0), (-0.1, 0, 0), (0, 0.1, 0)], [], [(0, 1, 2), (0, 1, 3), (0, 1, 4)])
fin = bpy.data.objects.new("Fin", me)
bpy.context.scene.collection.objects.link(fin)
fin.select_set(True)
bpy.context.view_layer.objects.active = fin
seen["non_manifold"] = error_of(lambda: bpy.ops.patterns.flatten())
seen["bad_suffix"] = error_of(lambda: bpy.ops.patterns.export(filepath=os.path.join(OUT, "fin.pdf")))
os.environ["PATTERNS_ENGINE"] = "/nonexistent/python -m patterns"
from patterns_blender import engine as host_engine  # the add-on's own module, once it is enabled

host_engine.engine().stop()
host_engine._ENGINE = None
bpy.ops.mesh.primitive_cylinder_add(vertices=8, radius=0.05, depth=0.1, end_fill_type="NOTHING")
seen["no_engine"] = error_of(lambda: bpy.ops.patterns.flatten())
seen["modules"] = sorted(m for m in sys.modules if m.split(".")[0] in ("patterns", "OCP", "build123d", "scipy",
                                                                     "shapely", "ezdxf", "trimesh"))
with open(os.path.join(OUT, "blender.json"), "w", encoding="utf-8") as f:
    json.dump(seen, f)
sys.stdout.flush()
os._exit(0)
