"""Build the bundled CAD samples with build123d and write their STEP files.

Run from the repository root (the STEP files are committed; this script is how
they were made)::

    python samples/make_cad.py

All four are surfaces (shells), in millimetres, as a sheet-metal or garment
designer would model them:

* ``duct_transition.step`` -- square-to-round duct transition: a 400 x 400 mm
  square at z = 0 to a 300 mm circle at z = 300, lofted with straight rulings
  (four ruled faces, one per side of the square, each ending on a quarter of
  the circle).
* ``hopper.step`` -- cone-frustum hopper: 600 mm across at the top, 200 mm at
  the bottom, 400 mm high; one conical face closed by its seam line.
* ``cup.step`` -- four-panel cup (garment): a hemisphere of radius 90 mm, cut
  into four quarter panels by two vertical planes through its axis; the four
  seams meet at the apex.
* ``hull_panel.step`` -- a curved boat-hull (or facade) panel, 1200 x 600 mm,
  doubly curved: one B-spline face through a 5 x 4 grid of points.
"""

from __future__ import annotations

from math import pi
from pathlib import Path

from build123d import (
    CenterArc,
    Face,
    Polyline,
    Shell,
    Vector,
    Wire,
    export_step,
)

HERE = Path(__file__).resolve().parent


def duct_transition() -> Shell:
    """Square 400 x 400 (z = 0) to circle 300 (z = 300), ruled loft, four faces."""
    half = 200.0
    square = Polyline((-half, -half, 0), (half, -half, 0), (half, half, 0), (-half, half, 0), close=True)
    # The circle in four arcs facing the square's sides, starting at -135 degrees
    # like the square's first corner, so that the loft pairs side k with arc k.
    arcs = [CenterArc((0, 0, 300), 150.0, -135.0 + 90.0 * k, 90.0) for k in range(4)]
    return Shell.make_loft([Wire(square.edges()), Wire(arcs)], ruled=True)


def hopper() -> Shell:
    """Lateral surface of a cone frustum: radius 100 at z = 0 to radius 300 at z = 400."""
    from build123d import Solid

    cone = Solid.make_cone(100.0, 300.0, 400.0)
    lateral = [f for f in cone.faces() if f.geom_type.name == "CONE"]
    return Shell(lateral)


def cup() -> Shell:
    """Hemisphere of radius 90 (apex at z = -90), as four quarter faces sewn into one shell."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace, BRepBuilderAPI_Sewing
    from OCP.Geom import Geom_SphericalSurface
    from OCP.gp import gp_Ax3, gp_Dir, gp_Pnt

    sphere = Geom_SphericalSurface(gp_Ax3(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 90.0)
    sewing = BRepBuilderAPI_Sewing(1e-6)
    for k in range(4):
        face = BRepBuilderAPI_MakeFace(sphere, k * pi / 2, (k + 1) * pi / 2, -pi / 2, 0.0, 1e-7).Face()
        sewing.Add(face)
    sewing.Perform()
    shell = Shell(sewing.SewedShape())
    # Outward normals (away from the sphere's centre).
    return shell


def hull_panel() -> Face:
    """A doubly curved panel, 1200 mm long and 600 mm wide, through a 5 x 4 grid."""
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


SAMPLES = {
    "duct_transition.step": duct_transition,
    "hopper.step": hopper,
    "cup.step": cup,
    "hull_panel.step": hull_panel,
}


def main() -> None:
    for name, make in SAMPLES.items():
        shape = make()
        export_step(shape, HERE / name)
        print(f"wrote samples/{name}: {len(shape.faces())} faces, {len(shape.edges())} edges, "
              f"area {shape.area:.1f} mm^2")


if __name__ == "__main__":
    main()
