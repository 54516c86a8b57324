"""Shapes across the process boundary: a host's shape in, pieces out, as BREP text.

BREP is the one format both sides' OpenCascades write and read exactly (FreeCAD carries its own, the
engine OCP's, through build123d).  In, a host's shape is read from its BREP text by the library's one
reading path (:func:`patterns.reading.read_cad`), as a ``.brep`` file is.  Out, a piece's exact contours become edges (lines as segments, arcs as arcs, a drilled hole
one circle), its cut a face with holes, at 1:1 in the XY plane; marks are edges and points.  Written as
BREP format version 1, which every OpenCascade since 6.x reads (FreeCAD 0.20's 7.6 among them).
"""

from __future__ import annotations

import itertools
import os
import shutil
import tempfile

import numpy as np

from ..curves import Arc, Line, Loop
from ..errors import CadError
from ..pieces import Notch, Piece

__all__ = ["from_brep", "marks", "pieces_brep", "to_brep"]


def from_brep(text: str, label: str):
    """The build123d shape of BREP ``text`` (a host's shape), read as a ``.brep`` file is
    (:func:`patterns.reading.read_cad`: OpenCascade's complaints kept off the protocol), or CadError
    naming ``label``."""
    import build123d

    from ..reading import read_cad

    if not isinstance(text, str) or not text.strip():
        raise CadError(f"{label}: no shape was sent (empty BREP text)")
    folder = tempfile.mkdtemp(prefix="patterns-")
    path = os.path.join(folder, "shape.brep")
    try:
        with open(path, "w", encoding="utf-8") as out:
            out.write(text)
        try:
            shape = read_cad(path)
        except CadError as exc:
            raise CadError(f"{label}: its shape could not be read ({str(exc).replace(path, 'BREP text')})") from None
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    return build123d.Shape.cast(shape)


def to_brep(shape) -> str:
    """BREP text (format version 1, no triangulation) of an OCP ``TopoDS_Shape``."""
    from OCP.BRepTools import BRepTools
    from OCP.TopTools import TopTools_FormatVersion

    fd, path = tempfile.mkstemp(suffix=".brep", prefix="patterns-")
    os.close(fd)
    try:
        BRepTools.Write_s(shape, path, False, False, TopTools_FormatVersion.TopTools_FormatVersion_VERSION_1)
        with open(path, encoding="utf-8") as f:
            return f.read()
    finally:
        os.unlink(path)


def _point(p):
    from OCP.gp import gp_Pnt

    return gp_Pnt(float(p[0]), float(p[1]), 0.0)


def _segment(a, b):
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge

    return BRepBuilderAPI_MakeEdge(_point(a), _point(b)).Edge()


def _edges(loop: Loop) -> list:
    """The edges of a closed contour, in order: lines, arcs (a full circle one edge), polylines' segments."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge
    from OCP.GC import GC_MakeArcOfCircle
    from OCP.gp import gp_Ax2, gp_Circ, gp_Dir

    edges = []
    for piece in loop.pieces:
        if isinstance(piece, Arc) and piece.is_circle:
            axis = gp_Ax2(_point(piece.center), gp_Dir(0, 0, 1))
            edges.append(BRepBuilderAPI_MakeEdge(gp_Circ(axis, float(piece.radius))).Edge())
        elif isinstance(piece, Arc):
            middle = piece.start + piece.sweep / 2
            mid = piece.center + piece.radius * np.array([np.cos(middle), np.sin(middle)])
            arc = GC_MakeArcOfCircle(_point(piece.start_point), _point(mid), _point(piece.end_point)).Value()
            edges.append(BRepBuilderAPI_MakeEdge(arc).Edge())
        elif isinstance(piece, Line):
            edges.append(_segment(piece.start, piece.end))
        else:
            pts = piece.points()
            edges += [_segment(a, b) for a, b in itertools.pairwise(pts) if np.linalg.norm(b - a) > 1e-9]
    return edges


def _wire(loop: Loop):
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeWire

    maker = BRepBuilderAPI_MakeWire()
    for edge in _edges(loop):
        maker.Add(edge)
    if not maker.IsDone():
        raise CadError("a piece's contour does not close (its edges do not meet)")
    return maker.Wire()


def cut_face(piece: Piece):
    """What is cut of a piece: its outline less its holes, one face in the XY plane, its normal +Z."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
    from OCP.gp import gp_Pln
    from OCP.ShapeFix import ShapeFix_Face

    maker = BRepBuilderAPI_MakeFace(gp_Pln(), _wire(piece.outline), True)
    for hole in piece.holes:
        maker.Add(_wire(hole))
    fix = ShapeFix_Face(maker.Face())
    fix.FixOrientation()
    fix.Perform()
    return fix.Face()


def _compound(shapes):
    from OCP.BRep import BRep_Builder
    from OCP.TopoDS import TopoDS_Compound

    compound, builder = TopoDS_Compound(), BRep_Builder()
    builder.MakeCompound(compound)
    for shape in shapes:
        builder.Add(compound, shape)
    return compound


def _vertex(p):
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeVertex

    return BRepBuilderAPI_MakeVertex(_point(p)).Vertex()


def pieces_brep(pieces, *, bends: bool) -> str:
    """BREP text of the pieces' cut faces (and, with ``bends``, a blank's bend lines as edges beside them)."""
    shapes = [cut_face(p) for p in pieces]
    if bends:
        shapes += [_segment(*b.line) for p in pieces for b in p.bends]
    return to_brep(_compound(shapes))


def _notch_lines(notch: Notch) -> list:
    return [(notch.at, notch.tip)] if notch.mouth is None else [(notch.tip, end) for end in notch.mouth]


def _segments(pairs) -> list:
    return [_segment(a, b) for a, b in pairs if np.linalg.norm(np.subtract(b, a)) > 0]


def marks(pieces, labels) -> dict:
    """``{role: BREP text}`` of the pieces' marks: ``sew`` (the seam lines, with an allowance), ``notch``,
    ``grain``, ``drill`` (points), ``bend_up``, ``bend_down``, ``bend`` (rulings), ``label`` (each label's
    point, ``labels`` in order); roles with nothing to draw are left out."""
    lines: dict = {"sew": [], "notch": [], "grain": [], "bend_up": [], "bend_down": [], "bend": [], "drill": [],
                   "label": [_vertex(lb.at) for lb in labels]}
    for piece in pieces:
        if piece.allowance:
            for loop in piece.sew:
                lines["sew"] += _segments(itertools.pairwise(np.vstack([loop, loop[:1]])))
        for notch in piece.notches:
            lines["notch"] += _segments(_notch_lines(notch))
        if piece.grain is not None:
            lines["grain"] += _segments([piece.grain])
        for bend in piece.bends:
            lines[{"up": "bend_up", "down": "bend_down"}.get(bend.direction, "bend")] += _segments([bend.line])
        lines["drill"] += [_vertex(p) for p in piece.drills]
    return {role: to_brep(_compound(shapes)) for role, shapes in lines.items() if shapes}
