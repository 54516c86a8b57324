# ruff: noqa: I001 - bpy first: it puts Blender's own modules (addon_utils) on the path
"""The pictures of docs/blender.md, rendered by Blender itself (Workbench, headless): run with Blender's Python
(``bpy``), ``BLENDER_USER_SCRIPTS=<dir>`` (the add-on installed in ``<dir>/addons`` by ``patterns blender install
--target``) and ``OUT=<folder>`` (docs/images).  A dome with seams on four meridians, flattened without darts:
its strain painted on it (red at 5 %), and its four pieces at 1:1."""

import math
import os
import sys

import bpy  # first: it puts Blender's own modules (addon_utils) on the path

import addon_utils
import bmesh

addon_utils.enable("patterns_blender", default_set=True, handle_error=None)
OUT = os.environ["OUT"]
bpy.ops.object.select_all(action="SELECT")
bpy.ops.object.delete()
bpy.ops.mesh.primitive_uv_sphere_add(segments=48, ring_count=24, radius=0.1)
dome = bpy.context.active_object
dome.name = "Dome"
mesh = bmesh.new()
mesh.from_mesh(dome.data)
bmesh.ops.delete(mesh, geom=[v for v in mesh.verts if v.co.z < -1e-6], context="VERTS")
mesh.to_mesh(dome.data)
mesh.free()
first = min(math.atan2(v.co.y, v.co.x) for v in dome.data.vertices if math.hypot(v.co.x, v.co.y) > 1e-6)


def meridian(p):
    if math.hypot(p.x, p.y) < 1e-6:
        return -1
    turn = (math.atan2(p.y, p.x) - first) / (math.pi / 2)
    return round(turn) % 4 if abs(turn - round(turn)) < 1e-6 else None


for edge in dome.data.edges:
    a, b = (meridian(dome.data.vertices[i].co) for i in edge.vertices)
    edge.use_seam = a is not None and b is not None and (a == b or -1 in (a, b))
bpy.context.scene.patterns.max_strain = "0.05"
bpy.ops.patterns.flatten()

scene = bpy.context.scene
scene.render.engine = "BLENDER_WORKBENCH"
scene.display.shading.light = "STUDIO"
scene.display.shading.color_type = "VERTEX"
scene.render.resolution_x, scene.render.resolution_y = 900, 600
camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
scene.collection.objects.link(camera)
scene.camera = camera


def shoot(name, location, rotation, scale=None, hide=()):
    camera.location, camera.rotation_euler = location, rotation
    if scale is not None:
        camera.data.type, camera.data.ortho_scale = "ORTHO", scale
    else:
        camera.data.type = "PERSP"
    for obj in scene.objects:
        obj.hide_render = obj.name in hide or (hide == "pattern" and obj.name != "Dome" and obj.type == "MESH")
    scene.render.filepath = os.path.join(OUT, name)
    bpy.ops.render.render(write_still=True)


pieces = [o for o in bpy.data.collections["Dome pattern"].objects]
shoot("blender_model.png", (0.32, -0.32, 0.28), (math.radians(58), 0, math.radians(45)), hide=[o.name for o in pieces])
xs = [v.co.x for o in pieces if o.parent is None for v in o.data.vertices]
ys = [v.co.y for o in pieces if o.parent is None for v in o.data.vertices]
dome.hide_render = True
shoot("blender_pieces.png", ((min(xs) + max(xs)) / 2, (min(ys) + max(ys)) / 2, 1.0), (0, 0, 0),
      scale=1.1 * max(max(xs) - min(xs), 1.5 * (max(ys) - min(ys))), hide=["Dome"])
sys.stdout.flush()
os._exit(0)
