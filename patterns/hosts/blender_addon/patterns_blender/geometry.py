"""Meshes out of Blender and flat pieces back in: millimetres for the engine, the scene's units for Blender.

A Blender unit is ``scene.unit_settings.scale_length`` metres (1 in a default scene): a vertex goes to the
engine at ``1000 * scale_length`` mm per unit, in world space, modifiers applied; a flat piece comes back
at the same scale, 1:1, in the XY plane.
"""

import bpy

STRAIN = "patterns_strain"
"""The face attribute each flattened object and each piece gets: the dominant principal strain (0.01 = 1 %)."""
COLOUR = "patterns_strain_colour"
"""The colour layer that shows it on the model: white none, red at the limit and above, blue squeezed."""


def mm_per_unit(scene) -> float:
    """Millimetres in one Blender unit of ``scene``."""
    return 1000.0 * float(scene.unit_settings.scale_length or 1.0)


def mesh_of(obj, depsgraph, scale: float) -> tuple:
    """``(mesh request, triangle's polygon per triangle)``: ``obj`` evaluated (modifiers applied), in world
    space and mm, triangulated; its marked seams (edge ``use_seam``) as vertex pairs."""
    evaluated = obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    try:
        mesh.calc_loop_triangles()
        world = obj.matrix_world
        vertices = [[c * scale for c in (world @ v.co)] for v in mesh.vertices]
        faces = [list(t.vertices) for t in mesh.loop_triangles]
        polygons = [t.polygon_index for t in mesh.loop_triangles]
        seams = [list(e.vertices) for e in mesh.edges if e.use_seam]
        n_polygons = len(mesh.polygons)
    finally:
        evaluated.to_mesh_clear()
    return {"vertices": vertices, "faces": faces, "seams": seams}, polygons, n_polygons


def paint_strain(obj, triangle_strain, polygons, n_polygons, limit: float) -> bool:
    """The model's faces get the strain of their worst triangle (``patterns_strain``) and a colour (the
    active colour layer); False (nothing written) where its modifiers changed its faces."""
    mesh = obj.data
    if len(mesh.polygons) != n_polygons:
        return False
    per_face = [0.0] * n_polygons
    for strain, polygon in zip(triangle_strain, polygons):
        if abs(strain) > abs(per_face[polygon]):
            per_face[polygon] = strain
    attribute = mesh.attributes.get(STRAIN) or mesh.attributes.new(STRAIN, "FLOAT", "FACE")
    attribute.data.foreach_set("value", per_face)
    colours = mesh.color_attributes.get(COLOUR) or mesh.color_attributes.new(COLOUR, "FLOAT_COLOR", "CORNER")
    rgba = []
    for polygon in mesh.polygons:
        rgba += colour(per_face[polygon.index], limit) * polygon.loop_total
    colours.data.foreach_set("color", rgba)
    mesh.color_attributes.active_color = colours
    mesh.update()
    return True


def colour(strain: float, limit: float) -> list:
    """RGBA of a strain: white at 0, red at ``limit`` and above, blue at ``-limit`` and below."""
    t = min(abs(strain) / limit, 1.0) if limit > 0 else 0.0
    return [1.0, 1.0 - t, 1.0 - t, 1.0] if strain >= 0 else [1.0 - t, 1.0 - t, 1.0, 1.0]


def add_pieces(obj, pieces, scale: float, context, limit: float = 0.05) -> bpy.types.Collection:
    """The flat pieces as mesh objects in a collection named after ``obj`` (its earlier pieces replaced),
    each with its strain per face (and its colour, red at ``limit``) and its cut outline (a child of edges)."""
    name = f"{obj.name} pattern"
    collection = bpy.data.collections.get(name)
    if collection is None:
        collection = bpy.data.collections.new(name)
        context.scene.collection.children.link(collection)
    for old in list(collection.objects):
        data = old.data
        bpy.data.objects.remove(old, do_unlink=True)
        if data is not None and data.users == 0:
            bpy.data.meshes.remove(data)
    for piece in pieces:
        mesh = bpy.data.meshes.new(piece["name"])
        mesh.from_pydata([(x / scale, y / scale, 0.0) for x, y in piece["vertices"]], [], piece["faces"])
        mesh.update()
        attribute = mesh.attributes.new(STRAIN, "FLOAT", "FACE")
        attribute.data.foreach_set("value", piece["strain"])
        colours = mesh.color_attributes.new(COLOUR, "FLOAT_COLOR", "CORNER")
        rgba = []
        for polygon in mesh.polygons:
            rgba += colour(piece["strain"][polygon.index], limit) * polygon.loop_total
        colours.data.foreach_set("color", rgba)
        mesh.color_attributes.active_color = colours
        flat = bpy.data.objects.new(piece["name"], mesh)
        flat["patterns_panel"] = piece["panel"]
        collection.objects.link(flat)
        ring = piece["outline"]
        edges = bpy.data.meshes.new(f"{piece['name']} cut")
        edges.from_pydata([(x / scale, y / scale, 0.0) for x, y in ring],
                          [(i, (i + 1) % len(ring)) for i in range(len(ring))], [])
        cut = bpy.data.objects.new(f"{piece['name']} cut", edges)
        cut.parent = flat
        collection.objects.link(cut)
    return collection
