"""The bundled sample parts, built with build123d (millimetres).

Each function returns a build123d shape; :data:`SAMPLES` maps the STEP file
names in ``samples/`` to them (``samples/make_cad.py`` writes those files, and
``patterns demo`` builds the cup from here).

* ``duct_transition`` -- square-to-round duct transition: a 400 x 400 mm square
  at z = 0 to a 300 mm circle at z = 300, lofted with straight rulings (four
  ruled faces, one per side of the square, each ending on a quarter circle).
* ``hopper`` -- cone-frustum hopper: 600 mm across at the top, 200 mm at the
  bottom, 400 mm high; one conical face closed by its seam line.
* ``cup`` -- four-panel cup (garment): a hemisphere of radius 90 mm cut into four
  quarter panels by two vertical planes through its axis; the seams meet at
  the apex.
* ``hull_panel`` -- a curved boat-hull (or facade) panel, 1200 x 600 mm, doubly
  curved: one B-spline face through a 5 x 4 grid of points.
* ``square_to_round`` -- the classic sheet-metal square-to-round transition: a
  500 x 500 mm square at z = 0 to a 350 mm circle at z = 400, made of four
  planar triangles (a side of the square and the circle point facing it) and
  four oblique cones (a corner of the square and a quarter of the circle),
  each exactly developable.
* ``rolled_cylinder`` -- a rolled shell, 500 mm across and 500 mm high: one
  cylindrical face closed by its seam line (sheet metal: its blank is a
  rectangle, 2 pi times the neutral radius long).
* ``bracket`` -- a bent sheet-metal L bracket: 2 mm sheet, 60 and 40 mm legs
  (to the centre line), 40 mm wide, inside bend radius 3 mm, an 8 mm hole in
  the long leg (``patterns unfold samples/bracket.step``).

Two more parts, built here but not bundled as files (the seam tests and
``benchmarks/seams.py`` use them):

* ``bowl_segment`` -- a 90-degree segment of a bowl: a spline profile revolved
  (one freeform face, its rim a quarter circle of 150 mm) closed by three planes.
* ``sphere_gores`` -- a sphere of radius 100 mm split by two planes through its
  axis: four gores, pole to pole.

Curved faces for darts and gores (:data:`DOMES`; ``benchmarks/darts.py``, issue 36),
each one build123d face:

* ``spline_bowl`` -- a spline through (0, 0), (60, 8), (90, 30), (100, 60) mm
  revolved 360 degrees about z: 200 mm across, 60 deep.  The spline leaves
  the axis 8.5 degrees below horizontal: the bowl's bottom is a shallow cone
  point.
* ``oblate_dome`` / ``prolate_dome`` -- a quarter ellipse revolved: semi-axes
  150 (across) and 90 (high) mm, or 90 and 150.
* ``ellipsoid_cap`` -- the upper half of an ellipsoid of semi-axes 150, 110
  and 80 mm (a sphere scaled: a B-spline face).
* ``torus_patch`` -- the outer half of a torus (major radius 150, minor 50 mm)
  over a quarter turn: positive curvature everywhere.
* ``saddle`` -- a B-spline face through z = (x^2 - y^2) / 400 on a 200 mm
  square: negative curvature everywhere.
* ``freeform_cup`` -- an asymmetric cup, one B-spline face through a 9 x 9
  grid of points, 160 x 120 mm and 40 mm deep, its deepest point off centre;
  ``freeform_bag`` -- the same depth pressed into a flat sheet (a 5 x 5 grid
  whose outer ring is flat).
* ``seat`` -- a dome beside a saddle-shaped waist, one B-spline face through a
  13 x 9 grid, 300 x 200 mm: partly positive, partly negative curvature.
"""

from __future__ import annotations

from math import pi

import numpy as np

__all__ = [
    "DOMES",
    "SAMPLES",
    "bowl_segment",
    "cup",
    "duct_transition",
    "ellipsoid_cap",
    "freeform_bag",
    "freeform_cup",
    "holed_plate",
    "hopper",
    "hull_panel",
    "oblate_dome",
    "prolate_dome",
    "rolled_cylinder",
    "saddle",
    "seat",
    "sphere_gores",
    "spline_bowl",
    "square_to_round",
    "torus_patch",
]


def duct_transition():
    """Square 400 x 400 (z = 0) to circle 300 (z = 300), ruled loft, four faces."""
    from build123d import CenterArc, Polyline, Shell, Wire

    half = 200.0
    square = Polyline((-half, -half, 0), (half, -half, 0), (half, half, 0), (-half, half, 0), close=True)
    # The circle in four arcs facing the square's sides, starting at -135 degrees
    # like the square's first corner, so that the loft pairs side k with arc k.
    arcs = [CenterArc((0, 0, 300), 150.0, -135.0 + 90.0 * k, 90.0) for k in range(4)]
    return Shell.make_loft([Wire(square.edges()), Wire(arcs)], ruled=True)


def hopper():
    """Lateral surface of a cone frustum: radius 100 at z = 0 to radius 300 at z = 400."""
    from build123d import Shell, Solid

    cone = Solid.make_cone(100.0, 300.0, 400.0)
    lateral = [f for f in cone.faces() if f.geom_type.name == "CONE"]
    return Shell(lateral)


def cup():
    """Hemisphere of radius 90 (apex at z = -90), as four quarter faces sewn into one shell."""
    from build123d import Shell
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace, BRepBuilderAPI_Sewing
    from OCP.Geom import Geom_SphericalSurface
    from OCP.gp import gp_Ax3, gp_Dir, gp_Pnt

    sphere = Geom_SphericalSurface(gp_Ax3(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 90.0)
    sewing = BRepBuilderAPI_Sewing(1e-6)
    for k in range(4):
        face = BRepBuilderAPI_MakeFace(sphere, k * pi / 2, (k + 1) * pi / 2, -pi / 2, 0.0, 1e-7).Face()
        sewing.Add(face)
    sewing.Perform()
    return Shell(sewing.SewedShape())


def hull_panel():
    """A doubly curved panel, 1200 mm long and 600 mm wide, through a 5 x 4 grid."""
    from build123d import Face, Vector

    rows = []
    for i in range(5):
        x = -600.0 + 300.0 * i
        row = []
        for j in range(4):
            y = -300.0 + 200.0 * j
            # Bilge curvature across, sheer along, a little twist.
            z = 0.00035 * y * y + 0.00012 * x * x + 0.00004 * x * y
            row.append(Vector(x, y, z))
        rows.append(row)
    return Face.make_surface_from_array_of_points(rows, tol=1e-4)


def square_to_round(side: float = 500.0, diameter: float = 350.0, height: float = 400.0):
    """Classic square-to-round: four planar triangles and four oblique cones, sewn."""
    from build123d import CenterArc, Face, Shell, Vector, Vertex, Wire
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Sewing
    from OCP.BRepOffsetAPI import BRepOffsetAPI_ThruSections

    half, r = side / 2.0, diameter / 2.0
    corners = [Vector(-half, -half, 0), Vector(half, -half, 0), Vector(half, half, 0), Vector(-half, half, 0)]
    # The circle point facing side k (from corner k to corner k + 1).
    facing = [Vector(r * np.cos(np.radians(-90 + 90 * k)), r * np.sin(np.radians(-90 + 90 * k)), height)
              for k in range(4)]
    sewing = BRepBuilderAPI_Sewing(1e-6)
    for k in range(4):
        sewing.Add(Face(Wire.make_polygon([corners[k], corners[(k + 1) % 4], facing[k]], close=True)).wrapped)
        # The corner cone: straight lines from corner k + 1 to the quarter circle
        # between the points facing sides k and k + 1.
        sweep = BRepOffsetAPI_ThruSections(False, True)
        sweep.AddVertex(Vertex(corners[(k + 1) % 4]).wrapped)
        sweep.AddWire(Wire([CenterArc((0, 0, height), r, -90 + 90 * k, 90)]).wrapped)
        sweep.Build()
        for face in Shell(sweep.Shape()).faces():
            sewing.Add(face.wrapped)
    sewing.Perform()
    return Shell(sewing.SewedShape())


def rolled_cylinder():
    """Lateral surface of a cylinder: radius 250, height 500 (the inside skin of a rolled shell)."""
    from build123d import Shell, Solid

    cylinder = Solid.make_cylinder(250.0, 500.0)
    return Shell([f for f in cylinder.faces() if f.geom_type.name == "CYLINDER"])


def bowl_segment():
    """A spline profile revolved 90 degrees about z (a freeform face) and closed by three planes; a solid."""
    import build123d as bd

    with bd.BuildPart() as part:
        with bd.BuildSketch(bd.Plane.XZ):
            with bd.BuildLine():
                bd.Spline((0, 0), (80, 25), (150, 100), tangents=((1, 0), (0.4, 1)))
                bd.Line((150, 100), (0, 100))
                bd.Line((0, 100), (0, 0))
            bd.make_face()
        bd.revolve(axis=bd.Axis.Z, revolution_arc=90)
    return part.part


def sphere_gores():
    """The four spherical faces of a sphere of radius 100 split by the xz and yz planes, as one shell."""
    import build123d as bd

    halves = bd.Sphere(100).split(bd.Plane.XZ, keep=bd.Keep.BOTH)
    quarters = [q for h in halves for q in h.split(bd.Plane.YZ, keep=bd.Keep.BOTH)]
    return bd.Shell([q.faces().filter_by(bd.GeomType.SPHERE)[0] for q in quarters])


def bracket(thickness: float = 2.0, radius: float = 3.0, width: float = 40.0):
    """An L bracket bent from a ``thickness`` mm sheet (inside radius ``radius``, ``width`` wide): a
    rectangle swept along the filleted centre line (60 mm along x, then 40 mm along y), an 8 mm hole
    through the long leg's middle; a solid."""
    import build123d as bd

    with bd.BuildLine() as line:
        bd.FilletPolyline((60, 0), (0, 0), (0, 40), radius=radius + thickness / 2)
    path = line.wire()
    plane = bd.Plane(origin=path.position_at(0), x_dir=(0, 0, 1), z_dir=path.tangent_at(0))
    part = bd.sweep(plane * bd.Rectangle(width, thickness), path=path, transition=bd.Transition.RIGHT)
    return part - bd.Plane(origin=(30, 0, 0), z_dir=(0, 1, 0)) * bd.Cylinder(4, 50)



def holed_plate(holes: int, *, pitch: float = 10.0, radius: float = 2.5, thickness: float = 2.0):
    """A flat plate ``holes * pitch`` mm square and ``thickness`` thick with ``holes`` x ``holes`` round holes
    of ``radius`` on a ``pitch`` grid (``holes``² + 6 faces): built with OpenCascade directly, one planar face
    with every hole added as an inner wire, extruded (build123d's sketch took minutes at 5,000 holes); an OCP
    ``TopoDS_Shape``, corner at the origin."""
    from OCP.BRepBuilderAPI import (
        BRepBuilderAPI_MakeEdge,
        BRepBuilderAPI_MakeFace,
        BRepBuilderAPI_MakePolygon,
        BRepBuilderAPI_MakeWire,
    )
    from OCP.BRepPrimAPI import BRepPrimAPI_MakePrism
    from OCP.gp import gp_Ax2, gp_Circ, gp_Dir, gp_Pln, gp_Pnt, gp_Vec

    size = holes * pitch
    corners = [gp_Pnt(0, 0, 0), gp_Pnt(size, 0, 0), gp_Pnt(size, size, 0), gp_Pnt(0, size, 0)]
    maker = BRepBuilderAPI_MakeFace(gp_Pln(), BRepBuilderAPI_MakePolygon(*corners, True).Wire())
    for i in range(holes):
        for j in range(holes):  # each hole clockwise seen from +z (its axis down): an inner wire
            circle = gp_Circ(gp_Ax2(gp_Pnt(pitch * (i + 0.5), pitch * (j + 0.5), 0), gp_Dir(0, 0, -1)), radius)
            maker.Add(BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(circle).Edge()).Wire())
    return BRepPrimAPI_MakePrism(maker.Face(), gp_Vec(0, 0, thickness)).Shape()


def spline_bowl():
    """A spline through (0, 0), (60, 8), (90, 30) and (100, 60) mm revolved about z: one face."""
    import build123d as bd

    profile = bd.Edge.make_spline([(0, 0, 0), (60, 0, 8), (90, 0, 30), (100, 0, 60)])
    return bd.Face.revolve(profile, 360, bd.Axis.Z)


def _ellipse_dome(across: float, high: float):
    import build123d as bd

    quarter = bd.Edge.make_ellipse(across, high, bd.Plane.XZ, start_angle=0, end_angle=90)
    return bd.Face.revolve(quarter, 360, bd.Axis.Z)


def oblate_dome():
    """A quarter ellipse of semi-axes 150 mm (across) and 90 mm (high) revolved about z: one face."""
    return _ellipse_dome(150.0, 90.0)


def prolate_dome():
    """A quarter ellipse of semi-axes 90 mm (across) and 150 mm (high) revolved about z: one face."""
    return _ellipse_dome(90.0, 150.0)


def ellipsoid_cap():
    """The upper half of an ellipsoid of semi-axes 150, 110 and 80 mm: one B-spline face."""
    import build123d as bd

    half = bd.Sphere(1.0, arc_size1=0)
    (face,) = [f for f in half.faces() if f.geom_type != bd.GeomType.PLANE]
    return bd.scale(face, (150.0, 110.0, 80.0))


def torus_patch():
    """The outer half of a torus (major radius 150, minor 50 mm) over a quarter turn: one face."""
    import build123d as bd

    arc = bd.Edge.make_circle(50.0, bd.Plane.XZ.offset(0).shift_origin((150, 0, 0)), start_angle=-90, end_angle=90)
    return bd.Face.revolve(arc, 90, bd.Axis.Z)


def saddle():
    """z = (x^2 - y^2) / 400 over a 200 mm square: one B-spline face through a 9 x 9 grid of points."""
    import build123d as bd

    grid = np.linspace(-100.0, 100.0, 9)
    points = [[(x, y, (x * x - y * y) / 400.0) for x in grid] for y in grid]
    return bd.Face.make_surface_from_array_of_points(points)


def freeform_cup():
    """An asymmetric cup: one B-spline face through a 9 x 9 grid, 160 x 120 mm, 40 mm deep off centre.

    Depth ``40 (1 - u^2)(1 - v^2)(1 + u / 2) / 1.5`` over ``u, v`` in [-1, 1]: deepest towards +x.
    """
    import build123d as bd

    u = np.linspace(-1.0, 1.0, 9)
    points = [[(80.0 * a, 60.0 * b, -40.0 * (1 - a * a) * (1 - b * b) * (1 + a / 2) / 1.5) for a in u] for b in u]
    return bd.Face.make_surface_from_array_of_points(points)


def freeform_bag():
    """A bag pressed into a flat sheet: one B-spline face through a 5 x 5 grid, 160 x 120 mm, its
    outer ring of points flat, 40 mm deep off centre (darts from its outline must cross the flat)."""
    import build123d as bd

    depth = [[0, 0, 0, 0, 0], [0, 14, 20, 12, 0], [0, 24, 40, 22, 0], [0, 12, 24, 10, 0], [0, 0, 0, 0, 0]]
    xs, ys = np.linspace(-80.0, 80.0, 5), np.linspace(-60.0, 60.0, 5)
    points = [[(x, y, -float(depth[i][j])) for j, x in enumerate(xs)] for i, y in enumerate(ys)]
    return bd.Face.make_surface_from_array_of_points(points)


def seat():
    """A seat: a dome towards +x beside a saddle-shaped waist towards -x, one B-spline face through a 13 x 9
    grid, 300 x 200 mm (the dome 40 mm high; the waist rises along x and falls across it)."""
    import build123d as bd

    xs, ys = np.linspace(-150.0, 150.0, 13), np.linspace(-100.0, 100.0, 9)

    def z(x, y):
        dome = 40.0 * np.exp(-((x - 70.0) ** 2 + y ** 2) / 60.0 ** 2)
        waist = ((x + 70.0) ** 2 - y ** 2) / 300.0 * np.exp(-((x + 70.0) ** 2 + y ** 2) / 90.0 ** 2)
        return dome + waist

    points = [[(x, y, float(z(x, y))) for x in xs] for y in ys]
    return bd.Face.make_surface_from_array_of_points(points)


DOMES = {
    "spline bowl": spline_bowl,
    "oblate dome": oblate_dome,
    "prolate dome": prolate_dome,
    "ellipsoid": ellipsoid_cap,
    "torus patch": torus_patch,
    "saddle": saddle,
    "freeform cup": freeform_cup,
    "freeform bag": freeform_bag,
    "seat": seat,
}
"""The curved faces of the dart and gore benchmark, by name (each function returns one face)."""

SAMPLES = {
    "duct_transition.step": duct_transition,
    "hopper.step": hopper,
    "cup.step": cup,
    "hull_panel.step": hull_panel,
    "rolled_cylinder.step": rolled_cylinder,
    "square_to_round.step": square_to_round,
    "bracket.step": bracket,
}
