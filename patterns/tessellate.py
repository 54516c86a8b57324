"""CAD faces to triangle meshes, with build123d (OpenCascade) tessellation.

build123d is imported only when a CAD object is tessellated (the import takes
seconds).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse import csgraph

from .cut import cut_to_disk
from .errors import CadError, InputError
from .mesh import drop_unused, face_areas, unique_ints, validate_mesh
from .model import Bookkeeping, Model, Panel, Seam, Surface, SurfaceKind
from .options import Options, option

__all__ = ["DEFAULT_TRIANGLES", "MAX_TRIANGLES", "MIN_FACE_TRIANGLES", "MeshingOptions", "mesh_shape", "parse_panel",
           "tessellate_face"]


def tessellate_face(face, *, tolerance: float = 0.05, angular_tolerance: float = 0.1) -> tuple[np.ndarray, np.ndarray]:
    """Triangulate one build123d ``Face``.

    Parameters
    ----------
    face : build123d.Face
        Any surface type; its unit is the model's (mm in build123d).
    tolerance : float
        Largest distance from the triangles to the true surface (chordal
        deviation), in the model's unit; > 0.
    angular_tolerance : float
        Largest angle between neighbouring triangles' normals, radians; > 0.

    Returns
    -------
    vertices : (n, 3) float64
    faces : (m, 3) int64
        Wound with the face's outward orientation.  Zero-area triangles, which
        OpenCascade puts at the poles of spheres and cones, are removed, and the
        vertices they leave unused dropped.

    Raises
    ------
    InputError
        Not a build123d Face, or a tolerance that is not positive.
    CadError
        The face could not be tessellated.
    """
    import build123d  # heavy; only when CAD is used

    if not isinstance(face, build123d.Face):
        raise InputError(f"expected a build123d Face, got {type(face).__name__}")
    if not (tolerance > 0 and angular_tolerance > 0):
        raise InputError(f"tolerances must be positive, got {tolerance!r} and {angular_tolerance!r}")
    try:
        points, triangles = face.tessellate(tolerance, angular_tolerance)
    except Exception as exc:  # noqa: BLE001 - OpenCascade raises many kinds
        raise CadError(f"tessellation of the face failed ({exc})") from None
    if not triangles:
        raise CadError("tessellation of the face produced no triangles")
    vertices = np.array([(p.X, p.Y, p.Z) for p in points], dtype=np.float64)
    faces = np.asarray(triangles, dtype=np.int64)
    faces = faces[face_areas(vertices, faces) > 0]
    vertices, faces, _ = drop_unused(vertices, faces)
    return vertices, faces


# --------------------------------------------------------------------------- #
# CAD shapes to panels and seams
# --------------------------------------------------------------------------- #

DEFAULT_TRIANGLES = 4000
"""With no ``max_edge``, the target edge length gives about this many triangles over
the whole shape's area (before curvature refines it)..."""

MIN_FACE_TRIANGLES = 1000
"""... and each face at least about this many of its own."""

MAX_TRIANGLES = 4_000_000
"""Meshing that would make more triangles than this is refused (CadError) before it starts:
a tiny ``max_edge`` or ``tolerance`` must not hang the machine."""

_GRID = 41  # samples per parameter direction of a face's development table


def _panel_groups(value, option):
    """``{name: [CAD face index, ...]}``, checked (indices against the shape later); the CLI gives pairs."""
    if not hasattr(value, "items"):
        try:
            value = dict(value)  # [(name, [indices]), ...] from repeated --panel flags
        except (TypeError, ValueError):
            raise InputError(f"{option} must map panel names to lists of CAD face indices, "
                             f"e.g. {{'front': [0, 1]}}") from None
    out = {}
    for label, members in value.items():
        try:
            idx = [int(i) for i in members]
        except (TypeError, ValueError):
            raise InputError(f"{option}[{label!r}] must be a list of CAD face indices") from None
        if not idx:
            raise InputError(f"{option}[{label!r}] is empty")
        out[str(label)] = idx
    return out


def parse_panel(text: str):
    """``"NAME=0,1,2"`` (command line) as ``(name, [0, 1, 2])``."""
    name, sep, members = text.partition("=")
    if not sep or not name:
        raise ValueError(f"expected NAME=FACE,FACE,..., got {text!r}")
    return name, [int(i) for i in members.split(",")]


@dataclass(frozen=True, repr=False)
class MeshingOptions(Options):
    """How CAD faces are meshed (:func:`mesh_shape`; :func:`patterns.load` of a CAD file or build123d shape)."""

    max_edge: float | None = option(None, "CAD: target triangle edge length, mm (default: about 4000 triangles "
                                          "over the part, and at least about 1000 on every face)",
                                    low=0, low_open=True, optional=True, metavar="MM")
    chord_tolerance: float = option(0.05, "CAD: largest distance from a triangle or segment to the true surface "
                                          "or edge, mm; curved faces get shorter edges to meet it; also the "
                                          "sewing tolerance", low=0, low_open=True, metavar="MM")
    angular_tolerance: float = option(0.2, "CAD: largest angle between the normals at the two ends of a "
                                           "triangle edge, radians", low=0, low_open=True, metavar="RAD")
    panels: object = option(None, "CAD: groups of CAD faces (indices in shape.faces() order) cut as one panel "
                                  "each, e.g. {'front': [0, 1]}; on the command line NAME=0,1 (repeatable)",
                            check=_panel_groups, parse=parse_panel, repeat=True, flag="--panel", metavar="NAME=FACES")
    sew: bool = option(True, "CAD: sew faces that meet along an edge without sharing it (a file of loose "
                             "faces), so that the edge becomes a seam; --no-sew leaves them apart")


def mesh_shape(shape, options: MeshingOptions | None = None, *, name: str = "shape", **keywords):
    """Mesh a CAD shape into panels joined by seams, with well-shaped triangles.

    Every CAD edge is divided once, at equal arc length, and both faces along
    it use the same points; each face is then filled with a near-equilateral
    lattice of interior points (laid out in a development of the face that
    keeps lengths along its parameter lines) and triangulated (Delaunay,
    checked to keep every boundary segment).  All points lie on the exact CAD
    surface and edges.

    Parameters
    ----------
    shape : OCP ``TopoDS_Shape`` or build123d shape
    options : MeshingOptions, optional
        The options as a record; keywords (any field of
        :class:`MeshingOptions`) go over it.  ``max_edge``: target edge
        length, mm (default: the length that gives about
        :data:`DEFAULT_TRIANGLES` triangles over the shape's area, shorter on a
        face that would get fewer than :data:`MIN_FACE_TRIANGLES`).
        ``chord_tolerance``: largest distance from a triangle or segment to the
        true surface or edge, mm.  ``angular_tolerance``: largest angle
        between the normals (tangents) at two ends of a triangle edge
        (segment), radians.  ``panels``: groups of CAD faces (indices into
        ``shape.faces()``) to cut as one panel each, e.g. ``{"front": [0,
        1]}``; the other faces are panels of their own, named ``"face<i>"``.
        ``sew``: faces that meet along an edge without sharing it (a STEP or
        IGES of loose faces) are sewn first (OpenCascade
        ``BRepBuilderAPI_Sewing``, at the chord tolerance), so that their
        common edges become seams; already sewn shapes are left as they are.
    name : str
        For error messages and the model's name.

    Returns
    -------
    patterns.Model

    Raises
    ------
    InputError
        Bad options or groups.
    CadError
        A shape without faces, or a face that could not be meshed.
    """
    from OCP.TopoDS import TopoDS_Shape

    opts = MeshingOptions.of(options, keywords, name=name)
    wrapped = shape.wrapped if hasattr(shape, "wrapped") else shape
    if not isinstance(wrapped, TopoDS_Shape) or wrapped.IsNull():
        raise InputError(f"{name}: expected a build123d shape or an OCP TopoDS_Shape, got {type(shape).__name__}")
    if opts.sew:
        wrapped = _sewn(wrapped, opts.chord_tolerance)
    mesher = _ShapeMesher(wrapped, name=name)
    groups = mesher.groups(opts.panels)
    return mesher.run(groups, max_edge=opts.max_edge, tolerance=opts.chord_tolerance,
                      angular_tolerance=opts.angular_tolerance)


def _sewn(shape, tolerance: float):
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


class _Development:
    """A near-isometric 2D layout of a face's parameter domain, for meshing.

    ``y`` is the arc length along the v direction on the middle u line, ``x``
    the arc length along each u line from the middle u.  Exact on planes and
    cylinders, keeps lengths along parameter lines everywhere else.
    """

    def __init__(self, surface, u0, u1, v0, v1, n=_GRID):
        from OCP.gp import gp_Pnt, gp_Vec

        self.u = np.linspace(u0, u1, n)
        self.v = np.linspace(v0, v1, n)
        pts = np.empty((n, n, 3))
        normals = np.full((n, n, 3), np.nan)
        p, du, dv = gp_Pnt(), gp_Vec(), gp_Vec()
        for j, v in enumerate(self.v):
            for i, u in enumerate(self.u):
                surface.D1(u, v, p, du, dv)
                pts[j, i] = (p.X(), p.Y(), p.Z())
                nrm = du.Crossed(dv)
                mag = nrm.Magnitude()
                if mag > 1e-12 * (du.Magnitude() * dv.Magnitude() + 1e-300):
                    normals[j, i] = (nrm.X() / mag, nrm.Y() / mag, nrm.Z() / mag)
        self.points = pts
        self.normals = normals
        row = np.linalg.norm(np.diff(pts, axis=1), axis=2)  # (n, n-1) along u
        x = np.concatenate([np.zeros((n, 1)), np.cumsum(row, axis=1)], axis=1)
        mid = n // 2
        self.x = x - x[:, [mid]]
        col = np.linalg.norm(np.diff(pts[:, mid], axis=0), axis=1)
        self.y = np.concatenate([[0.0], np.cumsum(col)])
        # Keep y strictly increasing (a degenerate column would stall it).
        span = max(float(self.y[-1]), 1e-12)
        self.y = self.y + np.linspace(0.0, 1e-9 * span, n)

    def curvature(self) -> float:
        """Normal curvature between neighbouring samples, 1/mm (0 if flat): the 95th
        percentile, so that a point where it has no bound (a cone's apex) does not
        make the whole face fine."""
        k = []
        size = float(np.ptp(self.points.reshape(-1, 3), axis=0).max())
        for axis in (0, 1):
            dn = np.diff(self.normals, axis=axis)
            dp = np.diff(self.points, axis=axis)
            ang = np.linalg.norm(dn, axis=2)
            dist = np.linalg.norm(dp, axis=2)
            ok = np.isfinite(ang) & (dist > 1e-6 * size)
            if ok.any():
                k.append((ang[ok] / dist[ok]).ravel())
        return float(np.percentile(np.concatenate(k), 95)) if k else 0.0

    def forward(self, uv: np.ndarray) -> np.ndarray:
        """(k, 2) parameters -> (k, 2) development coordinates, mm."""
        u, v = uv[:, 0], uv[:, 1]
        n = len(self.u)
        fu = np.clip((u - self.u[0]) / (self.u[-1] - self.u[0]) * (n - 1), 0, n - 1 - 1e-12)
        fv = np.clip((v - self.v[0]) / (self.v[-1] - self.v[0]) * (n - 1), 0, n - 1 - 1e-12)
        i, j = fu.astype(int), fv.astype(int)
        a, b = fu - i, fv - j
        x = ((1 - a) * (1 - b) * self.x[j, i] + a * (1 - b) * self.x[j, i + 1]
             + (1 - a) * b * self.x[j + 1, i] + a * b * self.x[j + 1, i + 1])
        y = np.interp(v, self.v, self.y)
        return np.column_stack([x, y])

    def inverse(self, xy: np.ndarray) -> np.ndarray:
        """(k, 2) development coordinates -> (k, 2) parameters (inverse of :meth:`forward`)."""
        n = len(self.u)
        v = np.interp(xy[:, 1], self.y, self.v)
        fv = np.clip((v - self.v[0]) / (self.v[-1] - self.v[0]) * (n - 1), 0, n - 1 - 1e-12)
        j = fv.astype(int)
        b = (fv - j)[:, None]
        rows = (1 - b) * self.x[j] + b * self.x[j + 1]  # (k, n), increasing along u
        x = xy[:, 0]
        i = np.clip(np.sum(rows < x[:, None], axis=1) - 1, 0, n - 2)
        lo = rows[np.arange(len(x)), i]
        hi = rows[np.arange(len(x)), i + 1]
        with np.errstate(divide="ignore", invalid="ignore"):
            a = np.where(hi > lo, (x - lo) / (hi - lo), 0.5)
        u = self.u[i] + np.clip(a, 0, 1) * (self.u[1] - self.u[0])
        return np.column_stack([u, v])


class _ShapeMesher:
    def __init__(self, shape, *, name):
        from OCP.BRep import BRep_Tool
        from OCP.BRepTools import BRepTools_WireExplorer
        from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_WIRE
        from OCP.TopExp import TopExp_Explorer
        from OCP.TopoDS import TopoDS

        self.name = name
        self.faces = []
        seen = _Registry()
        ex = TopExp_Explorer(shape, TopAbs_FACE)
        while ex.More():
            face = TopoDS.Face(ex.Current())
            if seen.index(face) == len(self.faces):
                self.faces.append(face)
            ex.Next()
        if not self.faces:
            raise CadError(f"{name}: the shape has no faces (nothing to flatten)")
        # Edges numbered as build123d's ``shape.edges()`` does: explorer order,
        # degenerate edges (a sphere's poles, a cone's apex) left out -- here
        # they come after all the others.
        self.edges = _Registry()
        ex = TopExp_Explorer(shape, TopAbs_EDGE)
        while ex.More():
            edge = TopoDS.Edge(ex.Current())
            if not BRep_Tool.Degenerated_s(edge):
                self.edges.index(edge)
            ex.Next()
        self.vertices = _Registry()
        # Each face's wires as lists of oriented edges: (edge index, oriented edge).
        self.wires = []
        for face in self.faces:
            wires = []
            wx = TopExp_Explorer(face, TopAbs_WIRE)
            while wx.More():
                wire = TopoDS.Wire(wx.Current())
                walk = []
                we = BRepTools_WireExplorer(wire, face)
                while we.More():
                    edge = we.Current()
                    walk.append((self.edges.index(edge), edge))
                    we.Next()
                if walk:
                    wires.append(walk)
                wx.Next()
            self.wires.append(wires)
        self._degenerate = [BRep_Tool.Degenerated_s(e) for e in self.edges.items]

    # -- groups --------------------------------------------------------------
    def groups(self, faces):
        """Panels as (name, face indices); user groups first, then one per remaining face."""
        n = len(self.faces)
        panels, taken = [], {}
        if faces is not None:
            for label, idx in faces.items():
                for i in idx:
                    if not 0 <= i < n:
                        raise InputError(f"{self.name}: panels[{label!r}] names CAD face {i}; "
                                         f"the shape has faces 0..{n - 1}")
                    if i in taken:
                        raise InputError(f"{self.name}: face {i} is in two groups, "
                                         f"{taken[i]!r} and {label!r}")
                    taken[i] = label
                panels.append((str(label), sorted(set(idx))))
        panels += [(f"face{i}", [i]) for i in range(n) if i not in taken]
        return panels

    # -- sizes ---------------------------------------------------------------
    def run(self, groups, *, max_edge, tolerance, angular_tolerance):
        from OCP.BRepAdaptor import BRepAdaptor_Surface
        from OCP.BRepGProp import BRepGProp
        from OCP.BRepTools import BRepTools
        from OCP.GProp import GProp_GProps


        areas, self.surfaces, self.devs = [], [], []
        for k, face in enumerate(self.faces):
            props = GProp_GProps()
            BRepGProp.SurfaceProperties_s(face, props)
            areas.append(abs(props.Mass()))
            surface = BRepAdaptor_Surface(face)
            try:
                u0, u1, v0, v1 = BRepTools.UVBounds_s(face)
            except Exception as exc:  # noqa: BLE001
                raise CadError(f"{self.name}: face {k} has no parameter bounds ({exc})") from None
            if not (np.isfinite([u0, u1, v0, v1]).all() and u1 > u0 and v1 > v0):
                raise CadError(f"{self.name}: face {k} has empty or infinite parameter bounds")
            self.surfaces.append(surface)
            self.devs.append(_Development(surface, u0, u1, v0, v1))
        total = float(sum(areas))
        if not total > 0:
            raise CadError(f"{self.name}: the faces have no area")
        def spacing(area, triangles):
            return float(np.sqrt(4 * area / (np.sqrt(3) * triangles)))

        h = float(max_edge) if max_edge is not None else spacing(total, DEFAULT_TRIANGLES)
        self.h = h
        face_h = []
        for dev, area in zip(self.devs, areas):
            kappa = dev.curvature()
            # By default a small face still gets MIN_FACE_TRIANGLES of its own.
            hf = h if max_edge is not None else min(h, spacing(area, MIN_FACE_TRIANGLES))
            if kappa > 0:
                hf = min(hf, np.sqrt(8 * tolerance / kappa), angular_tolerance / kappa)
            face_h.append(max(hf, h / 50))
        self.face_h = face_h
        estimate = sum(a / (0.433 * hf * hf) for a, hf in zip(areas, face_h))
        if estimate > MAX_TRIANGLES:
            raise CadError(f"{self.name}: meshing at max_edge {min(face_h):.3g} mm (tolerance {tolerance:g} mm) "
                           f"would make about {estimate:.3g} triangles, over the limit of {MAX_TRIANGLES:.0e}; "
                           f"use a larger max_edge or tolerance")
        edge_faces = [[] for _ in self.edges.items]
        for k, wires in enumerate(self.wires):
            for walk in wires:
                for e, _ in walk:
                    edge_faces[e].append(k)
        self.edge_faces = edge_faces
        self.edge_count = [None] * len(self.edges.items)
        self.edge_data = [None] * len(self.edges.items)
        self._points = []  # global point coordinates
        self._vertex_gid = {}
        for e in range(len(self.edges.items)):
            hs = [face_h[k] for k in edge_faces[e]] or [h]
            self._discretize(e, min(hs), tolerance, angular_tolerance)
        meshes = [None] * len(self.faces)
        todo = set(range(len(self.faces)))
        for _round in range(8):
            refine = set()
            for k in sorted(todo):
                result = self._mesh_face(k)
                if isinstance(result, set):
                    refine |= result
                else:
                    meshes[k] = result
            if not refine:
                break
            todo = set()
            for e in refine:
                self._discretize(e, None, tolerance, angular_tolerance, double=True)
                todo |= set(self.edge_faces[e])
        else:
            raise CadError(f"{self.name}: faces {sorted(todo)} could not be meshed with their edges kept "
                           f"(a very thin or self-touching face?)")
        panels, seams = self._assemble(groups, meshes)
        return Model(name=self.name, panels=tuple(panels), seams=tuple(seams), max_edge=h,
                     bookkeeping=Bookkeeping(cuts=sum(s.cad_edge is None for s in seams)))

    # -- edges ---------------------------------------------------------------
    def _vertex(self, vertex) -> int:
        from OCP.BRep import BRep_Tool

        i = self.vertices.index(vertex)
        if i not in self._vertex_gid:
            p = BRep_Tool.Pnt_s(vertex)
            self._points.append((p.X(), p.Y(), p.Z()))
            self._vertex_gid[i] = len(self._points) - 1
        return self._vertex_gid[i]

    def _discretize(self, e, h, tolerance, angular_tolerance, double=False):
        """Divide edge ``e`` at equal arc length; its points get global ids."""
        from OCP.BRepAdaptor import BRepAdaptor_Curve
        from OCP.GCPnts import GCPnts_AbscissaPoint, GCPnts_UniformAbscissa
        from OCP.TopAbs import TopAbs_FORWARD
        from OCP.TopExp import TopExp
        from OCP.TopoDS import TopoDS

        edge = TopoDS.Edge(self.edges.items[e].Oriented(TopAbs_FORWARD))
        first = self._vertex(TopExp.FirstVertex_s(edge))
        last = self._vertex(TopExp.LastVertex_s(edge))
        if self._degenerate[e]:
            self.edge_data[e] = (np.zeros(1), np.array([first]), 0.0)
            return
        curve = BRepAdaptor_Curve(edge)
        t0, t1 = curve.FirstParameter(), curve.LastParameter()
        length = GCPnts_AbscissaPoint.Length_s(curve)
        if double:
            count = 2 * self.edge_count[e]
        else:
            t = np.linspace(t0, t1, 65)
            p = np.array([(q.X(), q.Y(), q.Z()) for q in (curve.Value(x) for x in t)])
            seg = np.diff(p, axis=0)
            seglen = np.linalg.norm(seg, axis=1)
            ok = seglen > 0
            kappa = 0.0
            if ok.sum() > 1:
                d = seg[ok] / seglen[ok, None]
                turn = np.arccos(np.clip(np.einsum("ij,ij->i", d[1:], d[:-1]), -1, 1))
                kappa = float(np.max(turn / (0.5 * (seglen[ok][1:] + seglen[ok][:-1]))))
            he = h
            if kappa > 0:
                he = min(he, np.sqrt(8 * tolerance / kappa), angular_tolerance / kappa)
            count = max(int(np.ceil(length / he - 1e-9)), 1)
            if first == last:
                count = max(count, 3)  # a closed edge: at least a triangle
        self.edge_count[e] = count
        params = np.linspace(t0, t1, count + 1)
        if count > 1:
            ua = GCPnts_UniformAbscissa(curve, count + 1, t0, t1)
            if ua.IsDone() and ua.NbPoints() == count + 1:
                params = np.array([ua.Parameter(i + 1) for i in range(count + 1)])
        gids = np.empty(count + 1, dtype=np.int64)
        gids[0], gids[-1] = first, last
        for i in range(1, count):
            q = curve.Value(params[i])
            self._points.append((q.X(), q.Y(), q.Z()))
            gids[i] = len(self._points) - 1
        self.edge_data[e] = (params, gids, float(length))

    # -- faces ---------------------------------------------------------------
    def _mesh_face(self, k):
        """Mesh face ``k``; returns its mesh, or the set of edges to divide finer."""
        import shapely
        from OCP.BRepAdaptor import BRepAdaptor_Curve2d
        from OCP.TopAbs import TopAbs_REVERSED
        from OCP.TopoDS import TopoDS
        from scipy.spatial import Delaunay

        face, dev, h = self.faces[k], self.devs[k], self.face_h[k]
        loops = []  # per wire: list of (gid, xy, occurrence, position)
        occurrences = []  # (edge index, number of points)
        for walk in self.wires[k]:
            raw = []
            for e, edge in walk:
                params, gids, _ = self.edge_data[e]
                occ = len(occurrences)
                if self._degenerate[e]:
                    c2 = BRepAdaptor_Curve2d(TopoDS.Edge(edge), face)
                    mid = 0.5 * (c2.FirstParameter() + c2.LastParameter())
                    q = c2.Value(mid)
                    uv = np.array([[q.X(), q.Y()]])
                    occurrences.append((e, 1))
                    raw.append((gids[:1], uv, occ, np.zeros(1, dtype=int)))
                    continue
                c2 = BRepAdaptor_Curve2d(TopoDS.Edge(edge), face)
                uv = np.array([(q.X(), q.Y()) for q in (c2.Value(t) for t in params)])
                pos = np.arange(len(params))
                if edge.Orientation() == TopAbs_REVERSED:
                    uv, pos = uv[::-1], pos[::-1]
                occurrences.append((e, len(params)))
                raw.append((gids[pos], uv, occ, pos))
            loops.append(raw)
        # Slots: boundary points of this face; consecutive repeats of a point merge.
        slot_gid, slot_uv = [], []
        occ_slots = [np.full(count, -1, dtype=np.int64) for _, count in occurrences]
        rings = []
        for raw in loops:
            ring = []
            for gids, uv, occ, pos in raw:
                xy = dev.forward(uv)
                for g, p, q in zip(gids, xy, pos):
                    if ring and slot_gid[ring[-1]] == g and np.allclose(slot_uv[ring[-1]], p,
                                                                          atol=0.01 * h):
                        occ_slots[occ][q] = ring[-1]
                        continue
                    slot_gid.append(int(g))
                    slot_uv.append(p)
                    ring.append(len(slot_gid) - 1)
                    occ_slots[occ][q] = ring[-1]
            if len(ring) > 1 and slot_gid[ring[0]] == slot_gid[ring[-1]] and \
                    np.allclose(slot_uv[ring[0]], slot_uv[ring[-1]], atol=0.01 * h):
                last = ring.pop()
                for o in occ_slots:
                    o[o == last] = ring[0]
                slot_gid.pop()
                slot_uv.pop()
            if len(ring) >= 3:
                rings.append(ring)
        if not rings:
            raise CadError(f"{self.name}: face {k} has no usable boundary")
        xy_b = np.array(slot_uv, dtype=np.float64)  # development coordinates of the slots
        ring_xy = [xy_b[r] for r in rings]
        signed = [0.5 * np.sum(r[:, 0] * np.roll(r[:, 1], -1) - np.roll(r[:, 0], -1) * r[:, 1]) for r in ring_xy]
        outer = int(np.argmax(np.abs(signed)))
        shell = ring_xy[outer] if signed[outer] > 0 else ring_xy[outer][::-1]
        holes = [r if s < 0 else r[::-1] for i, (r, s) in enumerate(zip(ring_xy, signed)) if i != outer]
        polygon = shapely.Polygon(shell, holes)
        if not polygon.is_valid:
            polygon = shapely.make_valid(polygon)
        # Interior lattice, kept clear of the boundary.
        x0, y0, x1, y1 = polygon.bounds
        dy = h * np.sqrt(3) / 2
        ys = np.arange(y0 + 0.5 * dy, y1, dy)
        pts = []
        for r, yv in enumerate(ys):
            xs = np.arange(x0 + (0.25 if r % 2 else 0.75) * h, x1, h)
            pts.append(np.column_stack([xs, np.full(len(xs), yv)]))
        interior = np.concatenate(pts) if pts else np.zeros((0, 2))
        if len(interior):
            interior = interior[shapely.contains_xy(polygon, interior[:, 0], interior[:, 1])]
        segs_a = np.concatenate([np.asarray(r) for r in rings])
        segs_b = np.concatenate([np.roll(np.asarray(r), -1) for r in rings])
        if len(interior):
            lines = shapely.linestrings(np.stack([xy_b[segs_a], xy_b[segs_b]], axis=1))
            seg_len = np.linalg.norm(xy_b[segs_b] - xy_b[segs_a], axis=1)
            tree = shapely.STRtree(lines)
            (_, near), dist = tree.query_nearest(shapely.points(interior), return_distance=True, all_matches=False)
            interior = interior[dist >= 0.55 * np.maximum(h, seg_len[near])]
        points = np.concatenate([xy_b, interior])
        try:
            tri = Delaunay(points).simplices.astype(np.int64)
        except Exception as exc:  # noqa: BLE001 - qhull errors
            raise CadError(f"{self.name}: face {k} could not be triangulated ({exc})") from None
        p = points[tri]
        area2 = (p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1]) - (p[:, 1, 1] - p[:, 0, 1]) * (p[:, 2, 0] - p[:, 0, 0])
        tri[area2 < 0] = tri[area2 < 0][:, [0, 2, 1]]
        centre = p.mean(axis=1)
        keep = shapely.contains_xy(polygon, centre[:, 0], centre[:, 1]) & (np.abs(area2) > 1e-12 * h * h)
        # A sliver across three boundary points on a straight boundary (a seam
        # line) has its centre on the boundary itself: it is not inside.
        keep &= ~(np.all(tri < len(xy_b), axis=1) & (np.abs(area2) < 1e-6 * h * h))
        tri = tri[keep]
        # Every boundary segment must be an edge of a kept triangle.
        n_pts = len(points)
        have = unique_ints(np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
                           @ np.array([n_pts, 1]))
        need = np.sort(np.stack([segs_a, segs_b], axis=1), axis=1) @ np.array([n_pts, 1])
        missing = ~np.isin(need, have)
        if missing.any():
            refine = set()
            bad = set(np.concatenate([segs_a[missing], segs_b[missing]]).tolist())
            for o, (e, _) in enumerate(occurrences):
                if not self._degenerate[e] and bad & set(occ_slots[o].tolist()):
                    refine.add(e)
            if refine:
                return refine
            raise CadError(f"{self.name}: face {k}: boundary segments lost in the triangulation")
        nb = len(xy_b)
        uv_b = dev.inverse(xy_b)  # only for orientation checks; boundary points stay where they are
        uv_in = dev.inverse(points[nb:])
        xyz_b = np.asarray(self._points)[np.asarray(slot_gid)]
        fixed = np.stack([segs_a, segs_b], axis=1)
        xyz_in = _evaluate(self.surfaces[k], uv_in)
        for _ in range(2):  # alternate Delaunay flips (by 3D angles) and smoothing on the surface
            tri = _flip_to_delaunay(np.concatenate([xyz_b, xyz_in]), np.concatenate([uv_b, uv_in]), tri, fixed)
            uv_in, xyz_in = _relax_on_surface(self.surfaces[k], xyz_b, uv_b, uv_in, tri)
        tri = _flip_to_delaunay(np.concatenate([xyz_b, xyz_in]), np.concatenate([uv_b, uv_in]), tri, fixed)
        if face.Orientation() == TopAbs_REVERSED:
            tri = tri[:, [0, 2, 1]]
        return _FaceMesh(np.asarray(slot_gid, dtype=np.int64), xyz_in, tri, occurrences, occ_slots,
                         np.concatenate([uv_b, uv_in]))

    # -- panels and seams ----------------------------------------------------
    def _assemble(self, groups, meshes):

        points = np.asarray(self._points, dtype=np.float64)
        offsets = np.cumsum([0] + [len(m.slot_gid) + len(m.interior) for m in meshes])
        total = int(offsets[-1])
        panel_of_face = np.empty(len(self.faces), dtype=np.int64)
        for p, (_, members) in enumerate(groups):
            panel_of_face[members] = p
        # Face-vertex coordinates.
        coords = np.concatenate([np.concatenate([points[m.slot_gid], m.interior]) for m in meshes])
        # Occurrences of each edge: (face, face-vertex ids in the edge's order).
        occ_of_edge = [[] for _ in self.edges.items]
        for k, m in enumerate(meshes):
            for (e, _), slots in zip(m.occurrences, m.occ_slots):
                occ_of_edge[e].append((k, offsets[k] + slots))
        # Merge face-vertices along edges shared by two faces of one panel, and
        # along the seam line of a freeform face with itself (OpenCascade's seam
        # of a sphere or a surface of revolution, from the rim to the pole): that
        # line is the parametrisation's, not the part's, and cutting along it
        # would slit a cap to its pole.  A face that closes into a tube is cut
        # open again below, along a path of its own choosing.  Developable faces
        # keep their seam line: their exact development unrolls them from it.
        surfaces = [surface_of(self.surfaces[k], self.faces[k], self.devs[k]) for k in range(len(meshes))]
        freeform = [s is None for s in surfaces]
        rows, cols = [], []
        self_merged = set()
        for e, occ in enumerate(occ_of_edge):
            for (ka, va), (kb, vb) in zip(occ[:-1], occ[1:]):
                if panel_of_face[ka] != panel_of_face[kb] or len(va) != len(vb):
                    continue
                if ka == kb and not freeform[ka]:
                    continue
                if ka == kb:
                    self_merged.add(e)
                rows.append(va)
                cols.append(vb)
        if rows:
            rows, cols = np.concatenate(rows), np.concatenate(cols)
        else:
            rows = cols = np.zeros(0, dtype=np.int64)
        graph = sp.coo_matrix((np.ones(len(rows), dtype=np.int8), (rows, cols)), shape=(total, total))
        _, root = csgraph.connected_components(graph, directed=False)
        panels, local_of, cuts = [], [], []
        for p, (label, members) in enumerate(groups):
            tri = np.concatenate([offsets[k] + meshes[k].triangles for k in members])
            fv = np.concatenate([np.arange(offsets[k], offsets[k + 1]) for k in members])
            roots, first = unique_ints(root[fv], return_index=True)
            order = np.argsort(first)
            index = np.full(root.max() + 1, -1, dtype=np.int64)
            index[roots[order]] = np.arange(len(roots))
            local = np.full(total, -1, dtype=np.int64)
            local[fv] = index[root[fv]]
            vertices = coords[fv[first[order]]]
            faces = local[tri]
            pname = f"{self.name}: panel {label}"
            if len(members) > 1 or any(e in self_merged for e, _ in meshes[members[0]].occurrences):
                # A group, or a freeform face sewn along its own seam line, may
                # close up into a tube or a box: cut it open.
                cut = cut_to_disk(vertices, faces, name=pname)
                vertices, faces = cut.vertices, cut.faces
                cuts.extend((p, path_sides) for path_sides in zip(cut.paths, cut.sides))
            v, f, conn = validate_mesh(vertices, faces, name=pname)
            loops = sorted(conn.loops, key=lambda lp: -np.linalg.norm(
                v[np.roll(lp, -1)] - v[lp], axis=1).sum())
            surface = param = None
            if len(members) == 1:
                k = members[0]
                surface = surfaces[k]
                if surface is not None:
                    param = meshes[k].param[fv[first[order]] - offsets[k]]
            panels.append(Panel(label, v, f, tuple(loops), tuple(members), surface=surface, param=param))
            local_of.append(local)
        seams = []
        for e, occ in enumerate(occ_of_edge):
            if self._degenerate[e] or len(occ) < 2:
                continue
            ka, va = occ[0]
            for kb, vb in occ[1:]:
                pa, pb = int(panel_of_face[ka]), int(panel_of_face[kb])
                if (ka != kb or e in self_merged) and pa == pb:
                    continue  # inside one panel
                params, gids, length = self.edge_data[e]
                seams.append(Seam(id=len(seams), panels=(pa, pb), points=points[gids],
                                  vertices=(local_of[pa][va], local_of[pb][vb]), length=length, cad_edge=e))
        for p, ((path, (left, right))) in cuts:
            pts = panels[p].vertices[left]
            seams.append(Seam(id=len(seams), panels=(p, p), points=pts, vertices=(left, right),
                              length=float(np.linalg.norm(np.diff(pts, axis=0), axis=1).sum())))
        return panels, seams


def surface_of(surface, face, dev=None):
    """The developable surface of a face: a plane, a cylinder, a cone, or any surface
    swept by straight lines from one point (an oblique cone, as in a square-to-round
    transition); else None."""
    from OCP.GeomAbs import GeomAbs_Cone, GeomAbs_Cylinder, GeomAbs_Plane


    kind = surface.GetType()
    if kind not in (GeomAbs_Plane, GeomAbs_Cylinder, GeomAbs_Cone):
        return _general_cone(surface, dev) if dev is not None else None
    if kind == GeomAbs_Plane:
        ax, extra = surface.Plane().Position(), {}
        kind = SurfaceKind.PLANE
    elif kind == GeomAbs_Cylinder:
        cyl = surface.Cylinder()
        ax, extra = cyl.Position(), {"radius": cyl.Radius()}
        kind = SurfaceKind.CYLINDER
    elif kind == GeomAbs_Cone:
        cone = surface.Cone()
        ax, extra = cone.Position(), {"radius": cone.RefRadius(), "semi_angle": cone.SemiAngle()}
        kind = SurfaceKind.CONE
    else:
        return None

    def vec(d):
        return np.array([d.X(), d.Y(), d.Z()])

    return Surface(kind=kind, origin=vec(ax.Location()), x_dir=vec(ax.XDirection()), y_dir=vec(ax.YDirection()),
                   axis=vec(ax.Direction()), **extra)


def _general_cone(surface, dev):
    """A surface made of straight lines through one point (apex), recognised on its
    parameter grid: one side of the grid collapses to a point and every grid line
    from there is straight.  Returns its apex and a dense sample of the opposite
    boundary (the directrix), or None."""

    pts = dev.points  # (nv, nu, 3): rows along u at fixed v
    size = float(np.ptp(pts.reshape(-1, 3), axis=0).max())
    if size <= 0:
        return None
    sides = {"v0": (pts[0], pts), "v1": (pts[-1], pts[::-1]),
             "u0": (pts[:, 0], pts.transpose(1, 0, 2)), "u1": (pts[:, -1], pts.transpose(1, 0, 2)[::-1])}
    for key, (edge, grid) in sides.items():
        if np.ptp(edge, axis=0).max() > 1e-9 * size:
            continue
        apex = edge.mean(axis=0)
        # grid[j] are the points at the j-th line parallel to the apex side; lines
        # from the apex run across j.  Straight: every point on its apex-to-far line.
        far = grid[-1]
        line = far - apex
        length = np.linalg.norm(line, axis=1)
        if np.any(length <= 1e-9 * size):
            return None
        unit = line / length[:, None]
        rel = grid - apex
        off = rel - (rel * unit[None]).sum(axis=2)[..., None] * unit[None]
        if np.abs(off).max() > 1e-7 * size:
            return None
        # The directrix: the far boundary, sampled densely on the surface.
        n = 2001
        if key in ("v0", "v1"):
            u = np.linspace(dev.u[0], dev.u[-1], n)
            v = np.full(n, dev.v[-1] if key == "v0" else dev.v[0])
        else:
            v = np.linspace(dev.v[0], dev.v[-1], n)
            u = np.full(n, dev.u[-1] if key == "u0" else dev.u[0])
        directrix = _evaluate(surface, np.column_stack([u, v]))
        z = np.zeros(3)
        return Surface(kind=SurfaceKind.GENERAL_CONE, origin=apex, x_dir=z, y_dir=z, axis=z, directrix=directrix)
    return None


class _FaceMesh:
    """One face's mesh before assembly: boundary slots (global points) then interior points."""

    def __init__(self, slot_gid, interior, triangles, occurrences, occ_slots, param=None):
        self.slot_gid = slot_gid
        self.param = param  # (slots + interior, 2) surface parameters (boundary ones approximate)
        self.interior = interior
        self.triangles = triangles
        self.occurrences = occurrences
        self.occ_slots = occ_slots


def _evaluate(surface, uv: np.ndarray, derivatives: bool = False):
    """Surface points (k, 3) at parameters (k, 2), and optionally the two tangents (k, 3) each."""
    from OCP.gp import gp_Pnt, gp_Vec

    k = len(uv)
    xyz = np.empty((k, 3))
    if not derivatives:
        for i, (u, v) in enumerate(uv):
            q = surface.Value(u, v)
            xyz[i] = (q.X(), q.Y(), q.Z())
        return xyz
    su, sv = np.empty((k, 3)), np.empty((k, 3))
    p, du, dv = gp_Pnt(), gp_Vec(), gp_Vec()
    for i, (u, v) in enumerate(uv):
        surface.D1(u, v, p, du, dv)
        xyz[i] = (p.X(), p.Y(), p.Z())
        su[i] = (du.X(), du.Y(), du.Z())
        sv[i] = (dv.X(), dv.Y(), dv.Z())
    return xyz, su, sv


def _relax_on_surface(surface, xyz_b, uv_b, uv_in, tri, iterations: int = 3):
    """Tangential Laplacian smoothing of the interior points, on the exact surface.

    Each interior point moves towards the mean of its neighbours in 3D; the
    move is pulled back to the parameters through the surface's tangents and
    the point re-evaluated on the surface.  Moves that would flip a triangle
    in the parameter plane are undone.  Returns the interior points'
    parameters (k, 2) and positions (k, 3).
    """
    nb, ni = len(uv_b), len(uv_in)
    if ni == 0:
        return uv_in, np.zeros((0, 3))
    n = nb + ni
    e = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
    adj = sp.coo_matrix((np.ones(len(e)), (e[:, 0], e[:, 1])), shape=(n, n)).tocsr()
    adj = ((adj + adj.T) > 0).astype(np.float64)
    deg = np.asarray(adj.sum(axis=1)).ravel()[nb:]
    uv = np.concatenate([uv_b, uv_in])

    def orientation(q):
        p = q[tri]
        return np.sign((p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
                       - (p[:, 1, 1] - p[:, 0, 1]) * (p[:, 2, 0] - p[:, 0, 0]))

    sign = orientation(uv)
    xyz_in = None
    for _ in range(iterations):
        xyz_in, su, sv = _evaluate(surface, uv[nb:], derivatives=True)
        xyz = np.concatenate([xyz_b, xyz_in])
        move = (adj @ xyz)[nb:] / deg[:, None] - xyz_in
        # Least-squares parameter step: [su sv] duv = move.
        a11, a12, a22 = (su * su).sum(1), (su * sv).sum(1), (sv * sv).sum(1)
        b1, b2 = (su * move).sum(1), (sv * move).sum(1)
        det = a11 * a22 - a12 * a12
        ok = det > 1e-300
        du = np.where(ok, (a22 * b1 - a12 * b2) / np.where(ok, det, 1), 0.0)
        dv = np.where(ok, (a11 * b2 - a12 * b1) / np.where(ok, det, 1), 0.0)
        step = np.column_stack([du, dv])
        for scale in (1.0, 0.5, 0.25):
            cand = uv.copy()
            cand[nb:] += scale * step
            if np.all(orientation(cand) == sign):
                uv = cand
                break
        else:
            break
    return uv[nb:], _evaluate(surface, uv[nb:])


def _flip_to_delaunay(xyz: np.ndarray, uv: np.ndarray, tri: np.ndarray, fixed: np.ndarray,
                      rounds: int = 30) -> np.ndarray:
    """Flip edges whose two opposite angles (in 3D) sum to more than pi.

    Boundary segments (``fixed``, (b, 2)) never flip; a flip must keep both
    new triangles positively oriented in the parameter plane.  Each round
    flips a set of edges no two of which share a triangle (each triangle
    claims its worst edge; an edge flips when both its triangles claim it).
    """
    tri = tri.copy()
    n = len(xyz)
    fixed_key = unique_ints(np.sort(fixed, axis=1) @ np.array([n, 1]))

    def orient(a, b, c):
        return (uv[b, 0] - uv[a, 0]) * (uv[c, 1] - uv[a, 1]) - (uv[b, 1] - uv[a, 1]) * (uv[c, 0] - uv[a, 0])

    for _ in range(rounds):
        m = len(tri)
        p = xyz[tri]
        angle = np.empty((m, 3))
        for k in range(3):
            a = p[:, (k + 1) % 3] - p[:, k]
            b = p[:, (k + 2) % 3] - p[:, k]
            cos = np.einsum("ij,ij->i", a, b) / (np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1))
            angle[:, k] = np.arccos(np.clip(cos, -1.0, 1.0))
        # Side k of a triangle: corners k+1 -> k+2, opposite corner k.
        side_a = tri[:, [1, 2, 0]].ravel()
        side_b = tri[:, [2, 0, 1]].ravel()
        key = np.minimum(side_a, side_b) * n + np.maximum(side_a, side_b)
        order = np.argsort(key, kind="stable")
        ks = key[order]
        pair = np.flatnonzero(ks[1:] == ks[:-1])
        h1, h2 = order[pair], order[pair + 1]  # the two half-edges of each interior edge
        viol = angle.ravel()[h1] + angle.ravel()[h2] - np.pi
        ok = (viol > 1e-9) & ~np.isin(ks[pair], fixed_key)
        t1, c1 = h1 // 3, h1 % 3
        t2, c2 = h2 // 3, h2 % 3
        a, b = side_a[h1], side_b[h1]  # t1 = (.., a -> b, opposite c)
        c, d = tri[t1, c1], tri[t2, c2]
        ok &= (orient(a, d, c) > 0) & (orient(d, b, c) > 0)
        if not ok.any():
            break
        cand = np.flatnonzero(ok)
        claim = np.full(m, -1.0)
        np.maximum.at(claim, t1[cand], viol[cand])
        np.maximum.at(claim, t2[cand], viol[cand])
        win = cand[(claim[t1[cand]] == viol[cand]) & (claim[t2[cand]] == viol[cand])]
        # Ties could let one triangle win two edges: keep one edge per triangle.
        _, first1 = unique_ints(t1[win], return_index=True)
        win = win[first1]
        _, first2 = unique_ints(t2[win], return_index=True)
        win = win[first2]
        used = np.concatenate([t1[win], t2[win]])
        if len(unique_ints(used)) != len(used):
            win = win[:1]
        tri[t1[win]] = np.stack([a[win], d[win], c[win]], axis=1)
        tri[t2[win]] = np.stack([d[win], b[win], c[win]], axis=1)
    return tri
