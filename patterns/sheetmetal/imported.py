"""Stage 0 of an unfold: a part as another CAD system exported it, made ready to unfold.

Real STEP files are not always written the way the unfolder reads them best:

* one file may hold several solids (an assembly, or two parts exported together): an unfold takes
  one part, so that is refused by name instead of being read as one odd sheet;
* planes, cylinders and cones may be written as B-spline surfaces (NURBS exports, some CAD
  systems' translators, a "convert to spline" step): each B-spline or Bezier face that *is* a plane,
  cylinder or cone to 1e-6 mm is rebuilt on that analytic surface, with its own edges, so that it
  is developed exactly (a bend gets its bend line) instead of being meshed.
"""

from __future__ import annotations

from ..errors import InputError

__all__ = ["ANALYTIC_TOLERANCE", "prepared"]

ANALYTIC_TOLERANCE = 1e-6
"""mm: a B-spline face within this of a plane, cylinder or cone is rebuilt on it."""


def _count(shape, kind) -> int:
    from OCP.TopExp import TopExp_Explorer

    explorer, n = TopExp_Explorer(shape, kind), 0
    while explorer.More():
        n += 1
        explorer.Next()
    return n


def _analytic(shape):
    """The shape with every B-spline/Bezier face that is a plane, cylinder or cone rebuilt on that surface."""
    from OCP.BRep import BRep_Builder, BRep_Tool
    from OCP.BRepAdaptor import BRepAdaptor_Surface
    from OCP.BRepTools import BRepTools_ReShape
    from OCP.GeomAbs import GeomAbs_BezierSurface, GeomAbs_BSplineSurface
    from OCP.GeomConvert import GeomConvert_SurfToAnaSurf
    from OCP.ShapeFix import ShapeFix_Face, ShapeFix_Shape
    from OCP.TopAbs import TopAbs_FACE, TopAbs_WIRE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopLoc import TopLoc_Location
    from OCP.TopoDS import TopoDS, TopoDS_Face

    reshape, changed = BRepTools_ReShape(), 0
    faces = TopExp_Explorer(shape, TopAbs_FACE)
    while faces.More():
        face = TopoDS.Face(faces.Current())
        faces.Next()
        if BRepAdaptor_Surface(face).GetType() not in (GeomAbs_BSplineSurface, GeomAbs_BezierSurface):
            continue
        where = TopLoc_Location()
        surface = GeomConvert_SurfToAnaSurf(BRep_Tool.Surface_s(face, where)).ConvertToAnalytical(ANALYTIC_TOLERANCE)
        if surface is None:
            continue
        new, builder = TopoDS_Face(), BRep_Builder()
        builder.MakeFace(new, surface, where, ANALYTIC_TOLERANCE)
        wires = TopExp_Explorer(face, TopAbs_WIRE)
        while wires.More():
            builder.Add(new, wires.Current())
            wires.Next()
        new.Orientation(face.Orientation())
        fix = ShapeFix_Face(new)
        fix.Perform()
        reshape.Replace(face, fix.Face())
        changed += 1
    if not changed:
        return shape
    fix = ShapeFix_Shape(reshape.Apply(shape))
    fix.Perform()
    return fix.Shape()


def prepared(shape, name: str):
    """The part ready to unfold: one solid (InputError naming the count otherwise), analytic faces where they are.

    A shape with no solid at all (a closed shell) is passed as it is: it unfolds when it is a sheet.
    """
    from OCP.TopAbs import TopAbs_SOLID

    solids = _count(shape, TopAbs_SOLID)
    if solids > 1:
        raise InputError(f"{name}: {solids} solids in one file (an assembly, or parts exported together): unfold "
                         f"takes one part; export each part on its own")
    return _analytic(shape)
