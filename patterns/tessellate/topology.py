"""Topology: a B-rep's faces, edges and wires, numbered once; sewing; the panel groups.

The first stage of :func:`patterns.tessellate.mesh_shape`: everything later
refers to faces and edges by these numbers (build123d's ``shape.faces()`` and
``shape.edges()`` order).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import CadError, InputError
from ..units import LARGEST_LENGTH

__all__ = ["Topology", "closed_panels", "panel_groups", "read_topology", "sewn"]


class _Registry:
    """Unique sub-shapes (edges, vertices) by identity, in first-seen order."""

    def __init__(self):
        self.items = []
        self._by_hash = {}

    def index(self, item) -> int:
        bucket = self._by_hash.setdefault(hash(item), [])
        for i in bucket:
            if self.items[i].IsSame(item):
                return i
        self.items.append(item)
        bucket.append(len(self.items) - 1)
        return len(self.items) - 1


@dataclass(frozen=True, eq=False)
class Topology:
    """The faces, edges and wires of a shape.

    Attributes
    ----------
    name : str
        The shape's name, for messages.
    faces : tuple of OCP ``TopoDS_Face``
        In build123d's ``shape.faces()`` order.
    edges : tuple of OCP ``TopoDS_Edge``
        In ``shape.edges()`` order; degenerate edges (a sphere's pole, a
        cone's apex) after all the others.
    degenerate : tuple of bool
        Per edge.
    wires : tuple
        Per face, its wires; each a tuple of ``(edge index, oriented edge)``
        in the order the wire walks them on the face.
    edge_faces : tuple
        Per edge, the faces whose wires use it (a face twice along its own
        seam line).
    edge_vertices : tuple
        Per edge, ``(first, last)``: the numbers of its end vertices (each
        vertex of the shape numbered once, in first-seen order), in the edge's
        own direction; a wire that walks it reversed goes from ``last`` to
        ``first``.
    """

    name: str
    faces: tuple
    edges: tuple
    degenerate: tuple
    wires: tuple
    edge_faces: tuple
    edge_vertices: tuple = ()


def read_topology(shape, *, name: str) -> Topology:
    """Number the faces, edges and wires of an OCP shape; CadError if it has no faces."""
    from OCP.BRep import BRep_Tool
    from OCP.BRepTools import BRepTools_WireExplorer
    from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_WIRE
    from OCP.TopExp import TopExp, TopExp_Explorer
    from OCP.TopoDS import TopoDS

    faces = []
    seen = _Registry()
    ex = TopExp_Explorer(shape, TopAbs_FACE)
    while ex.More():
        face = TopoDS.Face(ex.Current())
        if seen.index(face) == len(faces):
            faces.append(face)
        ex.Next()
    if not faces:
        raise CadError(f"{name}: the shape has no faces (nothing to flatten)")
    _check_extent(shape, name)
    # Edges numbered as build123d's ``shape.edges()`` does: explorer order,
    # degenerate edges left out -- here they come after all the others.
    edges = _Registry()
    ex = TopExp_Explorer(shape, TopAbs_EDGE)
    while ex.More():
        edge = TopoDS.Edge(ex.Current())
        if not BRep_Tool.Degenerated_s(edge):
            edges.index(edge)
        ex.Next()
    wires = []
    for k, face in enumerate(faces):
        walks = []
        wx = TopExp_Explorer(face, TopAbs_WIRE)
        while wx.More():
            walk = []
            _check_wire(TopoDS.Wire(wx.Current()), face, k, name)
            we = BRepTools_WireExplorer(TopoDS.Wire(wx.Current()), face)
            while we.More():
                edge = we.Current()
                walk.append((edges.index(edge), edge))
                we.Next()
            if walk:
                walks.append(tuple(walk))
            wx.Next()
        wires.append(tuple(walks))
    edge_faces = [[] for _ in edges.items]
    for k, walks in enumerate(wires):
        for walk in walks:
            for e, _ in walk:
                edge_faces[e].append(k)
    vertices = _Registry()
    ends = tuple((vertices.index(TopExp.FirstVertex_s(e)), vertices.index(TopExp.LastVertex_s(e)))
                 for e in edges.items)
    return Topology(name=name, faces=tuple(faces), edges=tuple(edges.items),
                    degenerate=tuple(bool(BRep_Tool.Degenerated_s(e)) for e in edges.items),
                    wires=tuple(wires), edge_faces=tuple(tuple(f) for f in edge_faces), edge_vertices=ends)


CHECKED_WIRE_EDGES = 500
"""A face boundary (wire) of at most this many edges is checked for crossing itself; the check is
pairwise in its edges (a plate's thousands of holes are thousands of wires of one edge each)."""


def _check_wire(wire, face, index: int, name: str) -> None:
    """CadError if a face's boundary crosses itself (a bow-tie outline): the STEP and IGES readers no longer
    repair that (``reading._SKIPPED_REPAIRS``: the repair is pairwise over a face's wires), and such a face
    has no inside to mesh (its signed area cancels out).  Two edges that are not neighbours along the
    boundary may not meet; two neighbours are not asked (they meet at their vertex, and a real part's
    triangle of 2.9 mm² has two that OpenCascade finds crossing again within 1e-7 mm of it)."""
    from OCP.BRep import BRep_Tool
    from OCP.ShapeAnalysis import ShapeAnalysis_Wire

    check = ShapeAnalysis_Wire(wire, face, BRep_Tool.Tolerance_s(face))
    n = check.NbEdges()
    if n > CHECKED_WIRE_EDGES:
        return
    if any(check.CheckIntersectingEdges(i, j) for i in range(1, n + 1) for j in range(i + 2, n + 1)
           if not (i == 1 and j == n)):
        raise CadError(f"{name}: face {index}'s boundary crosses itself (a bow-tie or a loop through itself): the "
                       f"face is invalid; repair it in the CAD program and export it again")


def _check_extent(shape, name: str) -> None:
    """InputError if the shape reaches beyond LARGEST_LENGTH of the origin (a wrong unit, or garbage)."""
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib

    box = Bnd_Box()
    BRepBndLib.Add_s(shape, box)
    if box.IsVoid():
        return
    low, high = box.CornerMin(), box.CornerMax()
    corners = np.array([low.X(), low.Y(), low.Z(), high.X(), high.Y(), high.Z()])
    if not np.all(np.isfinite(corners)) or np.abs(corners).max() > LARGEST_LENGTH:
        raise InputError(f"{name}: the part reaches {np.abs(corners).max():.3g} mm from the origin, beyond "
                         f"{LARGEST_LENGTH:g} mm (10 km); parts are read in mm: check the file's unit")


def closed_panels(topology: Topology, panels) -> None:
    """InputError naming the first panel with no outline of its own: a closed surface (a sphere, a whole
    closed shell grouped as one panel), which no single cut lays flat without gross distortion."""
    for label, idx in panels:
        members = set(idx)
        touched = {e for k in idx for walk in topology.wires[k] for e, _ in walk if not topology.degenerate[e]}
        if all(len(topology.edge_faces[e]) >= 2 and set(topology.edge_faces[e]) <= members for e in touched):
            what = f"face {idx[0]}" if len(idx) == 1 else f"panel {label!r} (faces {', '.join(map(str, idx))})"
            raise InputError(f"{topology.name}: {what} closes on itself (a closed surface, like a sphere, with no "
                             f"outline): no single cut lays it flat without gross distortion; split it into "
                             f"panels first (two domes, or gores: build123d split)")


def panel_groups(topology: Topology, groups) -> tuple:
    """Panels as ``(name, face indices)``: the user's groups first (checked), then one per remaining face."""
    n = len(topology.faces)
    panels, taken = [], {}
    for label, idx in (groups or {}).items():
        for i in idx:
            if not 0 <= i < n:
                raise InputError(f"{topology.name}: panels[{label!r}] names CAD face {i}; "
                                 f"the shape has faces 0..{n - 1}")
            if i in taken:
                raise InputError(f"{topology.name}: face {i} is in two groups, {taken[i]!r} and {label!r}")
            taken[i] = label
        panels.append((str(label), sorted(set(idx))))
    panels += [(f"face{i}", [i]) for i in range(n) if i not in taken]
    closed_panels(topology, panels)
    return tuple(panels)


def sewn(shape, tolerance: float):
    """The shape with loose faces sewn along common edges, or the shape itself.

    Sewing is tried only when some edge bounds a single face while another
    edge of the same length and ends does too, i.e. two faces meet there
    without sharing the edge; the face count must survive the sewing.
    """
    from OCP.BRep import BRep_Tool
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Sewing
    from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
    from OCP.TopExp import TopExp, TopExp_Explorer
    from OCP.TopoDS import TopoDS

    faces = _Registry()
    ex = TopExp_Explorer(shape, TopAbs_FACE)
    while ex.More():
        faces.index(ex.Current())
        ex.Next()
    if len(faces.items) < 2:
        return shape
    edges = _Registry()
    owners = []
    for k, face in enumerate(faces.items):
        ee = TopExp_Explorer(face, TopAbs_EDGE)
        while ee.More():
            i = edges.index(ee.Current())
            if i == len(owners):
                owners.append(set())
            owners[i].add(k)
            ee.Next()
    free = []
    for edge, own in zip(edges.items, owners):
        edge = TopoDS.Edge(edge)
        if len(own) != 1 or BRep_Tool.Degenerated_s(edge):
            continue
        a = BRep_Tool.Pnt_s(TopExp.FirstVertex_s(edge))
        b = BRep_Tool.Pnt_s(TopExp.LastVertex_s(edge))
        free.append(tuple(sorted([(a.X(), a.Y(), a.Z()), (b.X(), b.Y(), b.Z())])))
    if len(free) < 2:
        return shape
    ends = np.array([np.r_[p, q] for p, q in free])
    close = np.linalg.norm(ends[:, None, :] - ends[None, :, :], axis=2) <= 2 * tolerance
    np.fill_diagonal(close, False)
    if not close.any():
        return shape
    sewing = BRepBuilderAPI_Sewing(tolerance)
    sewing.Add(shape)
    sewing.Perform()
    sewn = sewing.SewedShape()
    count = 0
    ex = TopExp_Explorer(sewn, TopAbs_FACE)
    while ex.More():
        count += 1
        ex.Next()
    return sewn if count == len(faces.items) else shape
