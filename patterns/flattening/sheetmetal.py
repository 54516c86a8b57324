"""Sheet metal: unfold a bent part into one flat blank, as SolidWorks and FreeCAD's SheetMetal do.

A bent sheet-metal part is a solid of constant thickness ``t``: two skins (the
inside and the outside of every bend) joined by narrow rim faces.  One skin,
followed from a fixed face across every bend, is the blank:

1. **Recognise the sheet.**  The thickness is the distance from the largest
   planar face to the nearest opposite, parallel face; the solid's volume must
   be that of a sheet of this thickness over the skin (within 1 %), else the
   part is not a sheet (a machined block).  The skin is every face reached from
   the fixed face across tangent edges (the rims meet it at a corner).
2. **Develop every skin face exactly.**  A plane keeps its own coordinates; a
   cylindrical bend of angle ``a`` and inside radius ``r`` is rolled out to its
   *neutral* width, ``a (r + k t)`` (``k`` the K-factor), or the width a bend
   table gives; a face's own parameters ``(u, v)`` map to the flat linearly
   (``(R_n u, v)`` on a cylinder), so lines stay lines and a hole's circle on a
   plane stays a circle.  A conical bend rolls out to the annular sector of its
   neutral cone (polar about the apex).  No mesh, no relaxation, no strain --
   except on a face that is none of these (a spline bend): it is meshed, moved to
   its neutral surface, flattened by the engine, and reported with its strain.
3. **Join them.**  From the fixed face outwards, each face is turned and moved
   (a rigid motion, never mirrored) so that the edge it shares with a placed
   face lands on that face's copy of it.  Every other shared edge is checked to
   meet as well (a closed tube does not: it needs a cut).
4. **The blank.**  Skin edges that meet a rim are the cut contour, chained by
   their vertices into loops: the longest around is the outline, the others
   holes.  Each bend's centre line is the middle ruling of its developed zone.
   Flanges that land on one another once unfolded are reported.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import shapely

from ..blank import Arc, Bend, Blank, BlankCode, BlankFinding, Line, Loop, Polyline
from ..errors import FlattenError, InputError
from ..options import Options, option

__all__ = ["BendTable", "UnfoldOptions", "read_bend_table", "unfold"]

_TANGENT = 1e-4
"""Two faces are tangent along an edge when their normals there differ by less than this (radians, about)."""
_MEET = 0.01
"""Shared edges must meet on the blank within this, mm."""
_SIDE = 0.4
"""One skin of a sheet is nearly half its surface (0.46-0.50 on the parts measured); below this share, not a sheet."""
_SAMPLE = 0.001
"""Chord error of curved pieces sampled as polylines, mm."""


@dataclass(frozen=True, eq=False)
class BendTable:
    """A bend-deduction table (CSV: ``thickness, radius, angle, deduction``; mm and degrees).

    The deduction ``BD`` of a bend is how much shorter the blank is than its two
    flanges measured to the virtual sharp (the crossing of the outside skins);
    the developed width of the bend zone is then ``2 (r + t) tan(a / 2) - BD``.
    Rows of the same thickness and inside radius are interpolated linearly in
    the angle; a bend outside every row is refused (never extrapolated).

    Attributes
    ----------
    path : str
    rows : (n, 4) float64
        thickness mm, inside radius mm, angle degrees, deduction mm.
    """

    path: str
    rows: np.ndarray

    def allowance(self, thickness: float, radius: float, angle: float) -> float:
        """Developed width of a bend, mm (``angle`` in degrees); InputError when no row covers it."""
        near = self.rows[(np.abs(self.rows[:, 0] - thickness) <= 0.01) & (np.abs(self.rows[:, 1] - radius) <= 0.01)]
        if len(near) == 0 or not near[:, 2].min() - 0.01 <= angle <= near[:, 2].max() + 0.01:
            raise InputError(f"{self.path}: no row for thickness {thickness:g} mm, inside radius {radius:g} mm, "
                             f"angle {angle:.2f} degrees (the table is never extrapolated)")
        order = np.argsort(near[:, 2])
        deduction = float(np.interp(angle, near[order, 2], near[order, 3]))
        return 2 * (radius + thickness) * np.tan(np.radians(angle) / 2) - deduction


def read_bend_table(path) -> BendTable:
    """Read a bend-deduction table (CSV with a header naming ``thickness, radius, angle, deduction``).

    Raises
    ------
    InputError
        Missing file, missing column, or a value that is not a number, naming the file and line.
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: no such bend table")
    try:
        with open(path, newline="", encoding="utf-8") as fh:
            reader = csv.DictReader(fh)
            need = ("thickness", "radius", "angle", "deduction")
            header = [h.strip().lower() for h in (reader.fieldnames or [])]
            missing = [n for n in need if n not in header]
            if missing:
                raise InputError(f"{path}: a bend table needs the columns {', '.join(need)}; "
                                 f"missing {', '.join(missing)}")
            rows = []
            for line, row in enumerate(reader, start=2):
                row = {k.strip().lower(): v for k, v in row.items() if k is not None}
                try:
                    rows.append([float(row[n]) for n in need])
                except (TypeError, ValueError):
                    raise InputError(f"{path}, line {line}: every value must be a number") from None
    except UnicodeDecodeError:
        raise InputError(f"{path}: not a text (CSV) file") from None
    rows = np.array(rows, dtype=np.float64).reshape(-1, 4)
    if len(rows) == 0 or not np.isfinite(rows).all() or (rows[:, :3] <= 0).any():
        raise InputError(f"{path}: the table is empty or holds a non-positive thickness, radius or angle")
    return BendTable(str(path), rows)


def _table(value, option):
    if isinstance(value, BendTable):
        return value
    if isinstance(value, (str, Path)):
        return read_bend_table(value)
    raise InputError(f"{option} must be a CSV file's path or a BendTable, got {type(value).__name__}")


@dataclass(frozen=True, repr=False)
class UnfoldOptions(Options):
    """How a bent sheet-metal part is unfolded (:func:`unfold`, ``patterns unfold``)."""

    k_factor: float = option(0.5, "position of the neutral layer in the bends from the inside, as a fraction of "
                                  "the thickness (SolidWorks' and FreeCAD's K-factor)", low=0, high=1)
    bend_table: object = option(None, "bend-deduction table, CSV with columns thickness, radius, angle, "
                                      "deduction (mm, degrees); it gives every bend instead of the K-factor",
                                optional=True, check=_table, metavar="CSV")
    fixed_face: int | None = option(None, "the CAD face that keeps its place (shape.faces() index; default the "
                                          "largest planar face)", integer=True, low=0, optional=True,
                                    metavar="N")


# --------------------------------------------------------------------------- #
# Faces: kind, normal, the linear map of their parameters to the flat
# --------------------------------------------------------------------------- #


@dataclass
class _Face:
    index: int
    face: object
    kind: str  # "plane", "cylinder", "cone" or "other"
    area: float
    adaptor: object
    origin: np.ndarray = None
    axis: np.ndarray = None
    radius: float = 0.0
    semi_angle: float = 0.0  # cone: OpenCascade's signed half-angle, radians
    scale: np.ndarray = None  # (2,) plane, cylinder: the flat is (scale[0] u, scale[1] v) before placing
    offset: float = 0.0  # cone: the neutral surface lies this far from the skin, towards the convex side, mm
    mirror: float = 1.0  # cone: -1 when the polar development is flipped to keep the skin's orientation
    meshed: object = None  # other: its _Meshed development
    rotation: np.ndarray = None  # (2, 2) placed: rotation @ local + shift
    shift: np.ndarray = None

    def normal(self, u: float, v: float) -> np.ndarray:
        from OCP.BRepGProp import BRepGProp_Face
        from OCP.gp import gp_Pnt, gp_Vec

        p, n = gp_Pnt(), gp_Vec()
        BRepGProp_Face(self.face).Normal(u, v, p, n)
        n = np.array([n.X(), n.Y(), n.Z()])
        return n / np.linalg.norm(n)

    def point(self, u: float, v: float) -> np.ndarray:
        p = self.adaptor.Value(u, v)
        return np.array([p.X(), p.Y(), p.Z()])

    def handedness(self, u: float, v: float) -> float:
        """+1 when ``du x dv`` is the face's outward normal, -1 when it is the inward one."""
        from OCP.gp import gp_Pnt, gp_Vec

        p, du, dv = gp_Pnt(), gp_Vec(), gp_Vec()
        self.adaptor.D1(u, v, p, du, dv)
        cross = np.cross([du.X(), du.Y(), du.Z()], [dv.X(), dv.Y(), dv.Z()])
        return 1.0 if cross @ self.normal(u, v) > 0 else -1.0

    def local(self, uv: np.ndarray) -> np.ndarray:
        """(k, 2) parameters to the face's own flat coordinates, mm: linear on planes and cylinders; on a
        cone, polar about the apex (distance from it along the generator, of the neutral surface; angle
        ``u sin a``)."""
        uv = np.asarray(uv, dtype=np.float64)
        if self.kind == "other":
            return self.meshed.at(np.array([self.point(u, v) for u, v in uv]).reshape(-1, 3))
        if self.kind != "cone":
            return uv * self.scale
        a = abs(self.semi_angle)
        s = np.abs(uv[:, 1] + self.radius / np.sin(self.semi_angle)) + self.offset / np.tan(a)
        phi = uv[:, 0] * np.sin(a)
        return np.column_stack([s * np.cos(phi), self.mirror * s * np.sin(phi)])

    def normal_radius(self, u: float, v: float) -> float:
        """Radius of curvature across the bend, mm: the cylinder's radius, a cone's distance from the
        point to its axis over cos(a) (along the normal)."""
        if self.kind == "cylinder":
            return self.radius
        rel = self.point(u, v) - self.origin
        return float(np.linalg.norm(rel - (rel @ self.axis) * self.axis) / np.cos(self.semi_angle))

    def flat(self, uv: np.ndarray) -> np.ndarray:
        """(k, 2) parameters on the face to (k, 2) positions on the blank, mm."""
        return self.local(uv) @ self.rotation.T + self.shift


@dataclass
class _Meshed:
    """A face no plane, cylinder or cone: its skin meshed, the mesh moved to the neutral surface and
    flattened by the engine (with the strain that costs); points on the face map through the mesh."""

    mesh: object  # trimesh.Trimesh of the skin
    uv: np.ndarray  # (n, 2) its vertices flattened, mm
    flattening: object  # patterns.Flattening
    volume: float  # the sheet behind it, mm³
    gap: float = 0.0  # how far its edges land from its neighbours', mm
    _tree: object = None

    def at(self, points: np.ndarray) -> np.ndarray:
        """(k, 3) points on the face (on its mesh to the tessellation's tolerance) to (k, 2) flat, mm:
        through the nearest triangle (among those with the nearest centroids), barycentrically."""
        from scipy.spatial import cKDTree

        vertices, tris = np.asarray(self.mesh.vertices), np.asarray(self.mesh.faces)
        if self._tree is None:
            self._tree = cKDTree(vertices[tris].mean(axis=1))
        cand = self._tree.query(points, k=min(12, len(tris)))[1].reshape(len(points), -1)
        tri = vertices[tris[cand]]  # (p, k, 3, 3)
        a = tri[..., 0, :]
        e0, e1, e2 = tri[..., 1, :] - a, tri[..., 2, :] - a, points[:, None, :] - a
        d00, d01, d11 = (e0 * e0).sum(-1), (e0 * e1).sum(-1), (e1 * e1).sum(-1)
        d20, d21 = (e2 * e0).sum(-1), (e2 * e1).sum(-1)
        den = d00 * d11 - d01 * d01
        v, w = (d11 * d20 - d01 * d21) / den, (d00 * d21 - d01 * d20) / den
        bary = np.clip(np.stack([1 - v - w, v, w], axis=-1), 0, None)
        bary /= bary.sum(axis=-1, keepdims=True)
        near = np.linalg.norm(np.einsum("pkj,pkjd->pkd", bary, tri) - points[:, None, :], axis=-1).argmin(axis=1)
        rows = np.arange(len(points))
        return np.einsum("pj,pjd->pd", bary[rows, near], self.uv[tris[cand[rows, near]]])


def _mesh_face(f, thickness, k_factor, name) -> _Meshed:
    """Mesh and flatten a face that is not developable as a plane, cylinder or cone."""
    import trimesh

    from ..measure import signed_areas
    from ..tessellate import mesh_shape
    from .engine import flatten_mesh

    # well-shaped triangles, half the thickness across (fewer, larger on a large face: about 2000)
    edge = max(thickness / 2, np.sqrt(f.area / 1000.0))
    (panel,) = mesh_shape(f.face, max_edge=edge, chord_tolerance=0.002, name=f"{name} face {f.index}").panels
    vertices, tris = np.asarray(panel.vertices), np.asarray(panel.faces)
    mesh = trimesh.Trimesh(vertices, tris, process=False)
    u, v = _uv_mid(f.face)
    concave = float(np.mean((vertices - f.point(u, v)) @ f.normal(u, v))) > 0  # curving towards its normal
    into = k_factor * thickness if concave else (1 - k_factor) * thickness  # the neutral surface, into the sheet
    result = flatten_mesh(vertices - into * mesh.vertex_normals, tris, name=f"{name} face {f.index}")
    uv = np.array(result.uv)
    if signed_areas(uv, tris).sum() < 0:
        uv[:, 1] *= -1

    def area(depth):  # of the skin moved ``depth`` into the sheet
        tri = (vertices - depth * mesh.vertex_normals)[tris]
        return 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1).sum()

    volume = thickness * (area(0) + 4 * area(thickness / 2) + area(thickness)) / 6  # Simpson across the sheet
    return _Meshed(mesh, uv, result, float(volume))


def _faces(topology):
    from OCP.BRepAdaptor import BRepAdaptor_Surface
    from OCP.BRepGProp import BRepGProp
    from OCP.GeomAbs import GeomAbs_Cone, GeomAbs_Cylinder, GeomAbs_Plane
    from OCP.GProp import GProp_GProps

    out = []
    for i, face in enumerate(topology.faces):
        adaptor = BRepAdaptor_Surface(face)
        props = GProp_GProps()
        BRepGProp.SurfaceProperties_s(face, props)
        kind = adaptor.GetType()
        named = {GeomAbs_Plane: "plane", GeomAbs_Cylinder: "cylinder", GeomAbs_Cone: "cone"}
        f = _Face(i, face, named.get(kind, "other"), props.Mass(), adaptor)
        if f.kind in ("cylinder", "cone"):
            surface = adaptor.Cylinder() if f.kind == "cylinder" else adaptor.Cone()
            ax = surface.Position()
            loc, d = ax.Location(), ax.Direction()
            f.origin, f.axis = np.array([loc.X(), loc.Y(), loc.Z()]), np.array([d.X(), d.Y(), d.Z()])
            f.radius = surface.Radius() if f.kind == "cylinder" else surface.RefRadius()
            f.semi_angle = 0.0 if f.kind == "cylinder" else surface.SemiAngle()
        out.append(f)
    return out


def _uv_mid(face):
    from OCP.BRepTools import BRepTools

    u0, u1, v0, v1 = BRepTools.UVBounds_s(face)
    return 0.5 * (u0 + u1), 0.5 * (v0 + v1)


def _edge_uv(edge, face, n: int) -> np.ndarray:
    """(n, 2) parameters on ``face`` of ``n`` points along ``edge`` (its own direction)."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve2d

    c2 = BRepAdaptor_Curve2d(edge, face)
    t = np.linspace(c2.FirstParameter(), c2.LastParameter(), n)
    out = np.empty((n, 2))
    for k, tk in enumerate(t):
        p = c2.Value(float(tk))
        out[k] = p.X(), p.Y()
    return out


# --------------------------------------------------------------------------- #
# The sheet: thickness, skin, bends
# --------------------------------------------------------------------------- #


def _volume(shape) -> float:
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props)
    return abs(props.Mass())


def _thickness(faces, fixed, name) -> float:
    """Distance from the fixed planar face to the nearest opposite parallel face behind it, mm."""
    f = faces[fixed]
    u, v = _uv_mid(f.face)
    n, p = f.normal(u, v), f.point(u, v)
    best = None
    for g in faces:
        if g.kind != "plane" or g.index == fixed:
            continue
        gu, gv = _uv_mid(g.face)
        m, q = g.normal(gu, gv), g.point(gu, gv)
        depth = -(q - p) @ n
        if m @ n < -1 + 1e-8 and depth > 1e-6 and (best is None or depth < best):
            best = depth
    if best is None:
        raise InputError(f"{name}: not a sheet: face {fixed} has no parallel face behind it (no constant thickness)")
    return float(best)


def _skin(topology, faces, fixed, name):
    """The faces reached from ``fixed`` across tangent edges, and the shared edges between them."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve

    tangent_edges = {}
    for e, owners in enumerate(topology.edge_faces):
        if topology.degenerate[e]:
            continue
        if len(owners) == 2 and owners[0] == owners[1]:
            tangent_edges[e] = None  # a seam line of a closed face
            continue
        if len(set(owners)) != 2:
            continue
        a, b = owners
        edge = topology.edges[e]
        c = BRepAdaptor_Curve(edge)
        tm = 0.5 * (c.FirstParameter() + c.LastParameter())
        normals = []
        for k in (a, b):
            from OCP.BRepAdaptor import BRepAdaptor_Curve2d

            p = BRepAdaptor_Curve2d(edge, faces[k].face).Value(tm)
            normals.append(faces[k].normal(p.X(), p.Y()))
        if normals[0] @ normals[1] > 1 - _TANGENT:
            tangent_edges[e] = (a, b)
    neighbours = {i: [] for i in range(len(faces))}
    for e, pair in tangent_edges.items():
        if pair is not None:
            a, b = pair
            neighbours[a].append((b, e))
            neighbours[b].append((a, e))
    skin, stack = {fixed}, [fixed]
    while stack:
        i = stack.pop()
        for j, _ in neighbours[i]:
            if j not in skin:
                skin.add(j)
                stack.append(j)
    for e, pair in tangent_edges.items():
        if pair is None and topology.edge_faces[e][0] in skin:
            raise InputError(f"{name}: the sheet closes on itself around face {topology.edge_faces[e][0]} "
                             f"(a tube with no seam): cut it along a line first")
    return skin, neighbours


def _sheet_volume(faces, skin, thickness) -> float:
    """The volume a sheet of this thickness over this skin has, mm³."""
    total = 0.0
    for i in skin:
        f = faces[i]
        if f.kind == "other":
            total += f.meshed.volume
        elif f.kind == "plane":
            total += f.area * thickness
        else:
            r_in = f.inside_radius
            total += f.area / f.bend_radius * ((r_in + thickness) ** 2 - r_in ** 2) / 2
    return total


# --------------------------------------------------------------------------- #
# The unfold
# --------------------------------------------------------------------------- #


def _shape(source, name):
    from ..reading import read_cad

    if isinstance(source, (str, Path)):
        return read_cad(source), name or Path(source).stem
    wrapped = getattr(source, "wrapped", source)
    if not hasattr(wrapped, "ShapeType"):
        raise InputError(f"unfold takes a STEP/BREP/IGES path or a build123d/OCP shape, got {type(source).__name__}")
    return wrapped, name or "part"


def unfold(shape_or_path, options: UnfoldOptions | None = None, *, name: str | None = None, **keywords) -> Blank:
    """Unfold a bent sheet-metal part into its flat blank.

    Parameters
    ----------
    shape_or_path : str, Path, build123d shape or OCP ``TopoDS_Shape``
        The folded solid (STEP, BREP or IGES file, mm).
    options : UnfoldOptions, optional
        The options as a record; keywords (``k_factor``, default 0.5;
        ``bend_table``, a CSV path or :class:`BendTable`; ``fixed_face``) go over it.
    name : str, optional
        For messages and the report (default: the file's stem).

    Returns
    -------
    patterns.Blank
        The outline and holes (exact lines and arcs), the bend lines, the
        thickness read from the model, and findings (flanges that overlap once
        unfolded, a bend with no flat face on one side).

    Raises
    ------
    InputError
        Not a sheet of constant thickness, a closed tube, a bad option, a bend the table does not cover.
    CadError
        The file cannot be read.
    FlattenError
        A face of the sheet that is not a plane or a cylinder.
    """
    from ..tessellate.topology import read_topology

    shape, name = _shape(shape_or_path, name)
    opts = UnfoldOptions.of(options, keywords, name=name)
    topology = read_topology(shape, name=name)
    faces = _faces(topology)
    largest = max(faces, key=lambda f: f.area)
    if largest.kind == "cylinder" and any(owners == (largest.index, largest.index) for owners in topology.edge_faces):
        raise InputError(f"{name}: a closed tube (face {largest.index} goes all the way round, with no seam): "
                         f"cut it along a line of its axis first")
    planes = [f for f in faces if f.kind == "plane"]
    if not planes:
        raise InputError(f"{name}: not a sheet-metal part: it has no planar face")
    if opts.fixed_face is None:
        fixed = max(planes, key=lambda f: f.area).index
    elif opts.fixed_face >= len(faces) or faces[opts.fixed_face].kind != "plane":
        raise InputError(f"{name}: fixed_face {opts.fixed_face} is not a planar face of the part "
                         f"(it has faces 0..{len(faces) - 1})")
    else:
        fixed = opts.fixed_face
    thickness = _thickness(faces, fixed, name)
    skin, neighbours = _skin(topology, faces, fixed, name)
    share = sum(faces[i].area for i in skin) / sum(f.area for f in faces)
    if share < _SIDE:
        raise InputError(f"{name}: not a sheet: face {fixed} and the faces joined to it smoothly are {share:.0%} of "
                         f"the part's surface, one side of a sheet nearly half (a block, a thick plate, the end "
                         f"of a tube)")
    for i in skin:
        f = faces[i]
        u, v = _uv_mid(f.face)
        hand = f.handedness(u, v)
        if f.kind == "plane":
            f.scale = np.array([hand, 1.0])
            continue
        if f.kind == "other":  # its neutral surface at the K-factor's depth, even with a bend table
            f.meshed = _mesh_face(f, thickness, opts.k_factor, name)
            continue
        outward = f.point(u, v) - f.origin
        outward -= (outward @ f.axis) * f.axis
        f.concave = bool(f.normal(u, v) @ outward < 0)
        f.bend_radius = f.normal_radius(u, v)
        f.inside_radius = f.bend_radius if f.concave else f.bend_radius - thickness
        if f.inside_radius < -1e-9:
            raise InputError(f"{name}: face {i} bends tighter than the sheet is thick (radius "
                             f"{f.bend_radius:g} mm, thickness {thickness:g} mm): not a sheet")
        f.inside_radius = max(f.inside_radius, 0.0)
    volume, expected = _volume(shape), _sheet_volume(faces, skin, thickness)
    if abs(volume - expected) > 0.01 * volume:
        raise InputError(f"{name}: not a sheet of constant thickness: the solid holds {volume:.0f} mm³, a "
                         f"{thickness:g} mm sheet over its skin {expected:.0f} mm³ (a machined block or a "
                         f"part of several thicknesses)")
    bends = _bends(topology, faces, skin, neighbours, thickness, opts, name)
    _place(topology, faces, skin, neighbours, fixed, name)
    loops = _loops(topology, faces, skin, name)
    outline = max(loops, key=lambda lp: lp.area)
    holes = tuple(lp for lp in loops if lp is not outline)
    drawn = tuple(_bend_line(faces, group, thickness, info) for group, info in bends)
    findings = list(_overlaps(topology, faces, skin, name))
    findings += [BlankFinding(BlankCode.BEND_WITHOUT_FLANGE, False,
                              f"{name}: bend at faces {', '.join(map(str, b.faces))} has no flat face on one "
                              f"side", b.line.mean(axis=0)) for b, (_, info) in zip(drawn, bends)
                 if not info["flanged"]]
    for i in sorted(skin):
        m = faces[i].meshed
        if m is not None:
            d = m.flattening.distortion
            findings.append(BlankFinding(
                BlankCode.MESHED_FACE, False,
                f"{name}: face {i} is not developable as a plane, cylinder or cone: meshed "
                f"({len(m.mesh.faces)} triangles) and flattened, strain up to {d.strain_max:.3%} (rms "
                f"{d.strain_rms:.3%}); its edges land within {m.gap:.3f} mm of the faces beside it",
                np.asarray(faces[i].flat(np.array([_uv_mid(faces[i].face)])))[0]))
    return Blank(name=name, outline=outline, holes=holes, bends=drawn, thickness=thickness,
                 k_factor=None if opts.bend_table is not None else opts.k_factor, fixed_face=fixed,
                 findings=tuple(findings))


def _bends(topology, faces, skin, neighbours, thickness, opts, name):
    """Group the skin's cylinders and cones into bends (joined faces of one axis, radius and angle); set each
    one's flat map."""
    from OCP.BRepTools import BRepTools

    cylinders = sorted(i for i in skin if faces[i].kind in ("cylinder", "cone"))
    group_of = {}
    groups = []
    for i in cylinders:
        if i in group_of:
            continue
        group, stack = [i], [i]
        group_of[i] = len(groups)
        while stack:
            a = stack.pop()
            for b, _ in neighbours[a]:
                fb, fa = faces[b], faces[a]
                if b in group_of or fb.kind != fa.kind or abs(fb.radius - fa.radius) > 1e-6 or abs(
                        fb.semi_angle - fa.semi_angle) > 1e-9:
                    continue
                if abs(abs(fb.axis @ fa.axis) - 1) > 1e-9 or np.linalg.norm(np.cross(fb.origin - fa.origin,
                                                                                       fa.axis)) > 1e-6:
                    continue
                group_of[b] = len(groups)
                group.append(b)
                stack.append(b)
        groups.append(group)
    out = []
    for group in groups:
        first = faces[group[0]]
        if first.kind == "cone":
            out.append((group, _cone_bend(faces, group, thickness, opts, name)))
        else:
            spans = []
            for i in group:
                u0, u1, _, _ = BRepTools.UVBounds_s(faces[i].face)
                spans.append(u1 - u0)
            angle = float(np.degrees(max(spans)))
            r_in = first.inside_radius
            if opts.bend_table is not None:
                allowance = opts.bend_table.allowance(thickness, r_in, angle)
            else:
                allowance = np.radians(angle) * (r_in + opts.k_factor * thickness)
            neutral = allowance / np.radians(angle)
            for i in group:
                f = faces[i]
                u, v = _uv_mid(f.face)
                f.scale = np.array([f.handedness(u, v) * neutral, 1.0])
            out.append((group, {"angle": angle, "inside_radius": r_in, "allowance": float(allowance)}))
        info = out[-1][1]
        sides = sum(1 for i in group for j, _ in neighbours[i] if faces[j].kind == "plane")
        info.update(direction="up" if first.concave else "down", flanged=sides >= 2)
    return out


def _cone_bend(faces, group, thickness, opts, name) -> dict:
    """A conical bend: its neutral surface developed exactly (polar about the apex); angle, radius and
    allowance as measured across its middle."""
    from OCP.BRepTools import BRepTools

    if opts.bend_table is not None:
        raise InputError(f"{name}: faces {', '.join(map(str, group))} are a conical bend; a bend table gives "
                         f"cylindrical bends only (use the K-factor)")
    for i in group:
        f = faces[i]
        f.offset = opts.k_factor * thickness if f.concave else -(1 - opts.k_factor) * thickness
        u, v = _uv_mid(f.face)
        f.mirror = 1.0
        h = 1e-4 * max(1.0, abs(v))
        jac = np.vstack([f.local(np.array([[u + 1e-6, v]])) - f.local(np.array([[u - 1e-6, v]])),
                         f.local(np.array([[u, v + h]])) - f.local(np.array([[u, v - h]]))])
        f.mirror = f.handedness(u, v) * float(np.sign(np.linalg.det(jac)))
    first = faces[group[0]]
    u0, u1, v0, v1 = BRepTools.UVBounds_s(first.face)
    vm = 0.5 * (v0 + v1)
    angle = float(np.degrees(np.arccos(np.clip(first.normal(u0, vm) @ first.normal(u1, vm), -1.0, 1.0))))
    ends = first.local(np.array([[u0, vm], [u1, vm]]))
    s_mid = float(np.linalg.norm(ends[0]))
    return {"angle": angle, "inside_radius": first.inside_radius,
            "allowance": float(s_mid * abs(u1 - u0) * np.sin(abs(first.semi_angle)))}


def _kabsch(src: np.ndarray, dst: np.ndarray):
    """The rotation R (2, 2) and shift s with ``src @ R.T + s`` closest to ``dst`` (never a mirror)."""
    cs, cd = src.mean(axis=0), dst.mean(axis=0)
    h = (src - cs).T @ (dst - cd)
    angle = np.arctan2(h[0, 1] - h[1, 0], h[0, 0] + h[1, 1])
    rot = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    return rot, cd - cs @ rot.T


def _place(topology, faces, skin, neighbours, fixed, name):
    """Place every skin face on the blank, breadth first from the fixed face; check every shared edge meets."""
    start = faces[fixed]
    start.rotation, start.shift = np.eye(2), np.zeros(2)
    placed, queue = {fixed}, [fixed]
    while queue:
        a = queue.pop(0)
        for b, e in neighbours[a]:
            if b in placed or b not in skin:
                continue
            edge = topology.edges[e]
            dst = faces[a].flat(_edge_uv(edge, faces[a].face, 5))
            src = faces[b].local(_edge_uv(edge, faces[b].face, 5))
            faces[b].rotation, faces[b].shift = _kabsch(src, dst)
            placed.add(b)
            queue.append(b)
    for a in skin:
        for b, e in neighbours[a]:
            if a < b:
                edge = topology.edges[e]
                gap = np.abs(faces[a].flat(_edge_uv(edge, faces[a].face, 5))
                             - faces[b].flat(_edge_uv(edge, faces[b].face, 5))).max()
                meshed = [faces[k].meshed for k in (a, b) if faces[k].meshed is not None]
                for m in meshed:
                    m.gap = max(m.gap, float(gap))
                if gap > _MEET and not meshed:
                    raise InputError(f"{name}: the sheet closes on itself (faces {a} and {b} land {gap:.3f} mm "
                                     f"apart once unfolded, along edge {e}): a tube or a box with no seam; "
                                     f"cut it along a line first")


def _piece(edge, face, flip: bool):
    """One boundary edge of a skin face as an exact piece on the blank, walked as the face's wire walks it."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Curve2d
    from OCP.GCPnts import GCPnts_QuasiUniformDeflection
    from OCP.GeomAbs import GeomAbs_Circle, GeomAbs_Line

    c2 = BRepAdaptor_Curve2d(edge, face.face)
    t0, t1 = c2.FirstParameter(), c2.LastParameter()
    if flip:
        t0, t1 = t1, t0

    def at(ts):
        pts = []
        for t in ts:
            p = c2.Value(float(t))
            pts.append((p.X(), p.Y()))
        return face.flat(np.array(pts))

    kind = c2.GetType()
    straight = kind == GeomAbs_Line and (face.kind in ("plane", "cylinder") or (
        face.kind == "cone" and abs(c2.Line().Direction().X()) < 1e-12))
    if straight:  # a line of the parameters is a line of the flat, but on a cone only along a generator
        a, b = at([t0, t1])
        return Line(a, b)
    if kind == GeomAbs_Circle and face.kind == "plane":
        circ = c2.Circle()
        c = face.flat(np.array([[circ.Location().X(), circ.Location().Y()]]))[0]
        a, q = at([t0, t0 + 0.25 * (t1 - t0)])
        u, w = a - c, q - c
        sweep = abs(t1 - t0) * np.sign(u[0] * w[1] - u[1] * w[0])
        return Arc(c, float(circ.Radius()), float(np.arctan2(*(a - c)[::-1])), float(sweep))
    curve = BRepAdaptor_Curve(edge)
    sampler = GCPnts_QuasiUniformDeflection(curve, _SAMPLE)
    ts = [sampler.Parameter(k) for k in range(1, sampler.NbPoints() + 1)] if sampler.IsDone() else []
    if len(ts) < 2:
        ts = np.linspace(curve.FirstParameter(), curve.LastParameter(), 65)
    ts = np.sort(np.asarray(ts))
    if flip:
        ts = ts[::-1]
    return Polyline(at(ts))


def _loops(topology, faces, skin, name):
    """The cut contour: skin edges that meet a rim, chained into closed loops by their vertices."""
    from OCP.TopAbs import TopAbs_REVERSED
    from OCP.TopExp import TopExp

    from ..tessellate.topology import _Registry

    vertices = _Registry()
    by_start = {}
    for i in sorted(skin):
        for wire in topology.wires[i]:
            for e, edge in wire:
                if topology.degenerate[e] or all(k in skin for k in topology.edge_faces[e]):
                    continue
                flip = edge.Orientation() == TopAbs_REVERSED
                a = vertices.index(TopExp.FirstVertex_s(edge, True))
                b = vertices.index(TopExp.LastVertex_s(edge, True))
                by_start.setdefault(a, []).append((b, _piece(edge, faces[i], flip)))
    loops = []
    while by_start:
        first = next(iter(by_start))
        pieces, at = [], first
        while True:
            nxt = by_start.get(at)
            if not nxt:
                raise FlattenError(f"{name}: the cut contour does not close at a vertex of the model "
                                   f"(after {len(pieces)} edges)")
            to, piece = nxt.pop()
            if not nxt:
                del by_start[at]
            pieces.append(piece)
            at = to
            if at == first:
                break
        loops.append(Loop(tuple(pieces)))
    return loops


def _bend_line(faces, group, thickness, info) -> Bend:
    """The centre line of a bend's developed zone."""
    from OCP.BRepTools import BRepTools

    ends = []
    for i in group:
        u0, u1, v0, v1 = BRepTools.UVBounds_s(faces[i].face)
        um = 0.5 * (u0 + u1)
        ends.append(faces[i].flat(np.array([[um, v0], [um, v1]])))
    ends = np.concatenate(ends)
    d = ends[1] - ends[0]
    d /= np.linalg.norm(d)
    s = (ends - ends[0]) @ d
    line = np.array([ends[np.argmin(s)], ends[np.argmax(s)]])
    return Bend(line=line, angle=info["angle"], inside_radius=info["inside_radius"], direction=info["direction"],
                allowance=info["allowance"], faces=tuple(sorted(group)))


def _overlaps(topology, faces, skin, name):
    """Faces of the blank that land on one another once unfolded (flanges that collide)."""
    from OCP.TopAbs import TopAbs_REVERSED

    polys = {}
    for i in sorted(skin):
        rings = []
        for wire in topology.wires[i]:
            pts = [_piece(edge, faces[i], edge.Orientation() == TopAbs_REVERSED).points(0.01)[:-1]
                   for e, edge in wire if not topology.degenerate[e]]
            if pts:
                rings.append(np.concatenate(pts))
        if rings:
            rings.sort(key=lambda r: -shapely.Polygon(r).area)
            polys[i] = shapely.make_valid(shapely.Polygon(rings[0], rings[1:]))
    keys = sorted(polys)
    tree = shapely.STRtree([polys[k] for k in keys])
    for a, b in zip(*tree.query([polys[k] for k in keys], predicate="intersects")):
        if a >= b:
            continue
        common = polys[keys[a]].intersection(polys[keys[b]])
        # a meshed face meets its neighbours only to within its gap: a sliver that wide along its edge is no overlap
        slack = sum(faces[k].meshed.gap * polys[k].length for k in (keys[a], keys[b]) if faces[k].meshed is not None)
        if common.area > 0.01 + slack:
            point = np.array(common.representative_point().coords[0])
            yield BlankFinding(BlankCode.FLANGES_OVERLAP, True,
                               f"{name}: faces {keys[a]} and {keys[b]} overlap by {common.area:.2f} mm² once "
                               f"unfolded (near x {point[0]:.1f}, y {point[1]:.1f} mm): the blank cannot be cut "
                               f"in one piece", point)
