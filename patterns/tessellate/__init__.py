"""CAD shapes to panels and seams: the mesher, as a pipeline of stages over frozen records.

:func:`mesh_shape` runs, in order:

1. **topology** (:mod:`~patterns.tessellate.topology`): faces, edges and wires
   numbered once (:class:`~patterns.tessellate.topology.Topology`); loose faces
   sewn; the panel groups checked;
2. **sizes** (:mod:`~patterns.tessellate.sizes`): each face's development table
   and target edge length (:class:`~patterns.tessellate.sizes.Sizes`);
3. **edge division** (:mod:`~patterns.tessellate.edges`): every CAD edge
   divided once, its points shared by both faces
   (:class:`~patterns.tessellate.edges.EdgeDivision`);
4. **face meshing** (:mod:`~patterns.tessellate.faces`): a lattice per face,
   triangulated; a face that loses a boundary segment answers
   :class:`~patterns.tessellate.faces.RefineEdges` and those edges are divided
   finer (``divide_finer``) before it is tried again;
5. **remeshing** (:mod:`~patterns.tessellate.remesh`): flips and smoothing on
   the exact surface;
6. **surface recognition** (:mod:`~patterns.tessellate.recognise`): planes,
   cylinders, cones and general cones, for exact development;
7. **assembly** (:mod:`~patterns.tessellate.assemble`): panels and seams, a
   :class:`patterns.Model`.

build123d / OpenCascade is imported only when a CAD object is meshed.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..errors import CadError, InputError
from ..mesh import drop_unused, face_areas
from ..model import Model
from ..options import Options, option
from .assemble import assemble
from .edges import divide_edges, divide_finer
from .faces import RefineEdges, mesh_face
from .sizes import DEFAULT_TRIANGLES, MAX_TRIANGLES, MIN_FACE_TRIANGLES, face_sizes
from .topology import panel_groups, read_topology, sewn

__all__ = ["DEFAULT_TRIANGLES", "MAX_TRIANGLES", "MIN_FACE_TRIANGLES", "MeshingOptions", "mesh_shape", "parse_panel",
           "tessellate_face"]

_ROUNDS = 8  # times a face may ask for finer edges before the shape is refused


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


def _panel_groups(value, option):
    """``{name: [CAD face index, ...]}``, checked (indices against the shape later); the CLI gives pairs."""
    if not isinstance(value, Mapping):
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
                                    low=0, low_open=True, optional=True, unit="mm")
    chord_tolerance: float = option(0.05, "CAD: largest distance from a triangle or segment to the true surface "
                                          "or edge, mm; curved faces get shorter edges to meet it; also the "
                                          "sewing tolerance", low=0, low_open=True, unit="mm")
    angular_tolerance: float = option(0.2, "CAD: largest angle between the normals at the two ends of a "
                                           "triangle edge, radians", low=0, low_open=True, metavar="RAD")
    panels: dict | None = option(None, "CAD: groups of CAD faces, by their index in shape.faces() order, cut as one "
                                  "panel each: NAME=0,1, repeatable (API: a mapping of names to face indices)",
                            check=_panel_groups, parse=parse_panel, repeat=True, flag="--panel", metavar="NAME=FACES")
    sew: bool = option(True, "CAD: sew faces that meet along an edge without sharing it (a file of loose "
                             "faces), so that the edge becomes a seam; --no-sew leaves them apart",
                             off="CAD: leave faces that meet along an edge without sharing it apart (no seam there)")


def mesh_shape(shape, options: MeshingOptions | None = None, *, name: str = "shape", **keywords) -> Model:
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
    wrapped = getattr(shape, "wrapped", shape)  # a build123d shape wraps its OCP one
    if not isinstance(wrapped, TopoDS_Shape) or wrapped.IsNull():
        raise InputError(f"{name}: expected a build123d shape or an OCP TopoDS_Shape, got {type(shape).__name__}")
    if opts.sew:
        wrapped = sewn(wrapped, opts.chord_tolerance)
    topology = read_topology(wrapped, name=name)
    groups = panel_groups(topology, opts.panels)
    sizes = face_sizes(topology, max_edge=opts.max_edge, chord_tolerance=opts.chord_tolerance,
                       angular_tolerance=opts.angular_tolerance)
    division = divide_edges(topology, sizes, chord_tolerance=opts.chord_tolerance,
                            angular_tolerance=opts.angular_tolerance)
    meshes, division = _mesh_faces(topology, sizes, division)
    return assemble(topology, sizes, division, meshes, groups)


def _mesh_faces(topology, sizes, division):
    """Every face meshed, edges divided finer where a face asks: ``(meshes, the final division)``."""
    meshes = [None] * len(topology.faces)
    todo = set(range(len(topology.faces)))
    for _ in range(_ROUNDS):
        refine = set()
        for k in sorted(todo):
            result = mesh_face(topology, sizes, division, k)
            if isinstance(result, RefineEdges):
                refine |= result.edges
            else:
                meshes[k] = result
        if not refine:
            return tuple(meshes), division
        division = divide_finer(topology, division, refine)
        todo = {k for e in refine for k in topology.edge_faces[e]}
    raise CadError(f"{topology.name}: faces {sorted(todo)} could not be meshed with their edges kept "
                   f"(a very thin or self-touching face?)")
