"""FreeCAD shapes in and out: the pipeline's one reading path in, pieces as Part shapes out.

A FreeCAD shape reaches :func:`patterns.load` and :func:`patterns.unfold` the
way a STEP file does: as an OpenCascade shape of the library's own
OpenCascade (OCP, through build123d), rebuilt from the shape's BREP text --
FreeCAD and OCP each carry their own OpenCascade, and BREP is the one format
both write and read exactly.  Out, a piece's exact contours become Part edges
(lines as segments, arcs as arcs, a drilled hole one circle), its cut a face
with holes, at 1:1 in the XY plane.
"""

from __future__ import annotations

import itertools
import os
import tempfile

import FreeCAD
import numpy as np
import Part

from ..curves import Arc, Line, Loop
from ..pieces import Notch, Piece

__all__ = ["cut_face", "library_shape", "loop_wire", "mark_shapes"]


def library_shape(shape: Part.Shape, label: str):
    """The build123d shape of a FreeCAD shape, through its BREP text (the one reading path of the API)."""
    import build123d
    from OCP.BRep import BRep_Builder
    from OCP.BRepTools import BRepTools
    from OCP.TopoDS import TopoDS_Shape

    fd, path = tempfile.mkstemp(suffix=".brep", prefix="patterns-")
    try:
        with os.fdopen(fd, "w", encoding="ascii") as out:
            out.write(shape.exportBrepToString())
        read = TopoDS_Shape()
        if not BRepTools.Read_s(read, path, BRep_Builder()) or read.IsNull():
            raise FreeCAD.Base.FreeCADError(f"{label}: its shape could not be handed to patterns (BREP)")
    finally:
        os.unlink(path)
    return build123d.Shape.cast(read)


def _vector(p) -> FreeCAD.Vector:
    return FreeCAD.Vector(float(p[0]), float(p[1]), 0.0)


def loop_wire(loop: Loop) -> Part.Wire:
    """A closed contour as a Part wire: lines, arcs (a full circle one edge) and polylines, exactly."""
    edges = []
    for piece in loop.pieces:
        if isinstance(piece, Arc) and piece.is_circle:
            circle = Part.Circle(_vector(piece.center), FreeCAD.Vector(0, 0, 1), piece.radius)
            edges.append(circle.toShape())
        elif isinstance(piece, Arc):
            mid = piece.center + piece.radius * np.array([np.cos(piece.start + piece.sweep / 2),
                                                          np.sin(piece.start + piece.sweep / 2)])
            edges.append(Part.Arc(_vector(piece.start_point), _vector(mid), _vector(piece.end_point)).toShape())
        elif isinstance(piece, Line):
            edges.append(Part.LineSegment(_vector(piece.start), _vector(piece.end)).toShape())
        else:
            pts = piece.points()
            edges += [Part.LineSegment(_vector(a), _vector(b)).toShape() for a, b in itertools.pairwise(pts)
                      if np.linalg.norm(b - a) > 1e-9]
    return Part.Wire(Part.__sortEdges__(edges))


def cut_face(piece: Piece) -> Part.Face:
    """What is cut of a piece: its outline, less its holes, as one face in the XY plane."""
    wires = [loop_wire(piece.outline)] + [loop_wire(h) for h in piece.holes]
    face = Part.makeFace(wires, "Part::FaceMakerBullseye")
    if face.Faces[0].normalAt(0, 0).z < 0:
        face.reverse()
    return face.Faces[0]


def _segments(pairs) -> list:
    return [Part.LineSegment(_vector(a), _vector(b)).toShape() for a, b in pairs if np.linalg.norm(np.subtract(b, a)) > 0]


def _notch_lines(notch: Notch) -> list:
    return [(notch.at, notch.tip)] if notch.mouth is None else [(notch.tip, end) for end in notch.mouth]


def mark_shapes(pieces) -> dict:
    """``{role: Part shape}`` of the marks of ``pieces``: ``sew`` (the seam lines, with an allowance),
    ``notch``, ``grain``, ``drill`` (points), ``bend_up``, ``bend_down``, ``bend`` (rulings); roles with
    nothing to draw are left out."""
    lines = {"sew": [], "notch": [], "grain": [], "bend_up": [], "bend_down": [], "bend": [], "drill": []}
    for piece in pieces:
        if piece.allowance:
            for loop in piece.sew:
                closed = np.vstack([loop, loop[:1]])
                lines["sew"] += _segments(itertools.pairwise(closed))
        for notch in piece.notches:
            lines["notch"] += _segments(_notch_lines(notch))
        if piece.grain is not None:
            lines["grain"] += _segments([piece.grain])
        for bend in piece.bends:
            role = {"up": "bend_up", "down": "bend_down"}.get(bend.direction, "bend")
            lines[role] += _segments([bend.line])
        lines["drill"] += [Part.Vertex(_vector(p)) for p in piece.drills]
    return {role: Part.Compound(shapes) for role, shapes in lines.items() if shapes}
