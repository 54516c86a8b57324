"""Loading: CAD files, mesh files and build123d objects become a :class:`~patterns.Model`.

:func:`load` is the entry point.  CAD files (STEP, BREP, IGES) and build123d
objects are meshed by :func:`patterns.tessellate.mesh_shape`: one panel per CAD
face (or per named group of faces), seams where two panels share a CAD edge.
Mesh files are split into connected pieces, one panel each; a closed piece or a
tube is cut open (:func:`patterns.cut.cut_to_disk`) and the cut reported as a
seam.


Mesh files (.obj, .stl, .ply, .off) are read by trimesh with ``process=False``:
trimesh never merges or drops anything silently.  Indexed formats (OBJ, PLY,
OFF) keep the connectivity the file gives -- two vertices at the same place are
still two vertices, as where a boundary touches itself -- and only vertices no
face uses are dropped.  STL stores every triangle's corners separately, so its
vertices at exactly the same coordinates are welded here, explicitly, and the
count is reported.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace
from pathlib import Path

import numpy as np

from .cut import cut_to_disk, pieces
from .errors import CadError, InputError
from .mesh import as_mesh_arrays, drop_unused, polyline_length, unique_ints
from .model import Bookkeeping, Model, Seam, panel_from_mesh
from .options import option
from .tessellate import MeshingOptions, mesh_shape
from .units import UNIT_NAMES, Unit

__all__ = ["CAD_SUFFIXES", "LoadOptions", "MESH_SUFFIXES", "MeshFile", "drop_unused", "load", "mesh_model", "read_cad", "read_mesh", "weld"]

MESH_SUFFIXES = (".obj", ".stl", ".ply", ".off", ".3mf")
"""File suffixes :func:`read_mesh` reads."""

CAD_SUFFIXES = (".step", ".stp", ".brep", ".brp", ".iges", ".igs")
"""File suffixes :func:`read_cad` reads."""


@dataclass(frozen=True, eq=False)
class MeshFile:
    """A mesh read from a file.

    Attributes
    ----------
    vertices : (n, 3) float64
        In the file's unit (mesh formats carry none; `patterns` takes mm).
    faces : (m, 3) int64
    path : Path
    n_welded : int
        Vertices merged into another at the same coordinates.
    n_unused : int
        Vertices that no face used, dropped (trimesh's OBJ reader drops these
        itself, so they are not counted for OBJ).
    """

    vertices: np.ndarray
    faces: np.ndarray
    path: Path
    n_welded: int
    n_unused: int


def weld(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray, int, int]:
    """Merge vertices with identical coordinates; drop vertices no face uses.

    Parameters
    ----------
    vertices : (n, 3) float64
    faces : (m, 3) int64

    Returns
    -------
    vertices : (k, 3) float64
        Unique used vertices, in order of first use by ``faces``.
    faces : (m, 3) int64
        Re-indexed.
    n_welded : int
        Used vertices that were duplicates of another.
    n_unused : int
        Vertices that no face used.
    """
    used = unique_ints(faces)
    n_unused = len(vertices) - len(used)
    first, inverse = _unique_rows(vertices[used])
    # Keep the order of first appearance (stable, deterministic output).
    rank = np.empty(len(first), dtype=np.int64)
    rank[np.argsort(first, kind="stable")] = np.arange(len(first))
    remap = np.full(len(vertices), -1, dtype=np.int64)
    remap[used] = rank[inverse.ravel()]
    new_vertices = vertices[used][np.sort(first)]
    return new_vertices, remap[faces], len(used) - len(first), n_unused


def _unique_rows(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Groups of equal rows: ``(first, inverse)`` as ``np.unique(points, axis=0, return_index=True,
    return_inverse=True)`` gives them, several times faster (one lexsort instead of a sort of
    row records)."""
    order = np.lexsort(points.T[::-1])
    ordered = points[order]
    starts = np.ones(len(points), dtype=bool)
    starts[1:] = np.any(ordered[1:] != ordered[:-1], axis=1)
    inverse = np.empty(len(points), dtype=np.int64)
    inverse[order] = np.cumsum(starts) - 1
    return order[starts], inverse  # lexsort is stable: each group's first row is its lowest index


def _existing_file(path, suffixes, kind: str) -> tuple[Path, str]:
    """``(Path, lower-case suffix)`` of an existing file of a known type, else the one-line InputError."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in suffixes:
        raise InputError(f"{path}: unknown {kind} file type {suffix or '(none)'!r}; "
                         f"expected one of {', '.join(suffixes)}")
    if not path.is_file():
        raise InputError(f"{path}: no such file")
    return path, suffix


def read_mesh(path, *, weld_vertices: bool | None = None) -> MeshFile:
    """Read a triangle mesh file.

    Parameters
    ----------
    path : str or Path
        An .obj, .stl, .ply, .off or .3mf file.
    weld_vertices : bool, optional
        Merge vertices at identical coordinates.  Default: only for STL, which
        has no shared vertices, and 3MF (its reader leaves them split).  Unused
        vertices are always dropped.

    Returns
    -------
    MeshFile

    Raises
    ------
    InputError
        Missing or unreadable file, unknown suffix, no triangles, bad values;
        the message names the file.
    """
    path, suffix = _existing_file(path, MESH_SUFFIXES, "mesh")
    import trimesh  # heavy; only when a file is read

    try:
        loaded = trimesh.load(path, file_type=suffix[1:], process=False, force="mesh")
    except Exception as exc:  # noqa: BLE001 - trimesh raises many kinds on a broken file
        raise InputError(f"{path}: cannot read this {suffix} file ({exc})") from None
    if isinstance(loaded, trimesh.Scene):  # pragma: no cover - force="mesh" folds scenes
        geometries = list(loaded.geometry.values())
        loaded = trimesh.util.concatenate(geometries) if geometries else None
    if loaded is None or len(getattr(loaded, "faces", ())) == 0:
        raise InputError(f"{path}: the file holds no triangles")
    vertices, faces = as_mesh_arrays(loaded.vertices, loaded.faces, name=str(path))
    if weld_vertices is None:
        weld_vertices = suffix in (".stl", ".3mf")
    if weld_vertices:
        vertices, faces, n_welded, n_unused = weld(vertices, faces)
    else:
        vertices, faces, n_unused = drop_unused(vertices, faces)
        n_welded = 0
    vertices.setflags(write=False)
    faces.setflags(write=False)
    return MeshFile(vertices, faces, path, n_welded, n_unused)


def read_cad(path):
    """Read a STEP, BREP or IGES file into an OpenCascade shape (millimetres).

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    OCP.TopoDS.TopoDS_Shape
        STEP and IGES are converted to millimetres by OpenCascade's readers;
        BREP carries no unit and is taken as millimetres.

    Raises
    ------
    InputError
        Missing file or unknown suffix.
    CadError
        The file is empty, corrupt, or holds no shape.
    """
    path, suffix = _existing_file(path, CAD_SUFFIXES, "CAD")
    if path.stat().st_size == 0:
        raise CadError(f"{path}: the file is empty")
    from OCP.IFSelect import IFSelect_RetDone

    kind = {".step": "STEP", ".stp": "STEP", ".iges": "IGES", ".igs": "IGES"}.get(suffix, "BREP")
    try:
        if kind == "BREP":
            from OCP.BRep import BRep_Builder
            from OCP.BRepTools import BRepTools
            from OCP.TopoDS import TopoDS_Shape

            shape = TopoDS_Shape()
            ok = BRepTools.Read_s(shape, str(path), BRep_Builder())
        else:
            if kind == "STEP":
                from OCP.STEPControl import STEPControl_Reader as Reader
            else:
                from OCP.IGESControl import IGESControl_Reader as Reader
            reader = Reader()
            ok = reader.ReadFile(str(path)) == IFSelect_RetDone
            if ok:
                reader.TransferRoots()
                shape = reader.OneShape()
    except Exception as exc:  # noqa: BLE001 - OpenCascade raises many kinds
        raise CadError(f"{path}: cannot read this {kind} file ({type(exc).__name__}: {exc})") from None
    if not ok:
        raise CadError(f"{path}: not a readable {kind} file (corrupt, truncated or another format)")
    if shape is None or shape.IsNull():
        raise CadError(f"{path}: the {kind} file holds no shape")
    return shape


def _weld(value, option):
    if value is None or isinstance(value, (bool, np.bool_)):
        return None if value is None else bool(value)
    raise InputError(f"{option} must be True, False or None, got {value!r}")


def _yes_no(text: str) -> bool:
    """``"yes"``/``"no"`` (command line) as a bool."""
    if text not in ("yes", "no"):
        raise ValueError(f"expected yes or no, got {text!r}")
    return text == "yes"


@dataclass(frozen=True, repr=False)
class LoadOptions(MeshingOptions):
    """How a part is read (:func:`load`; ``patterns flatten``, ``check``, ``info``, ``batch``)."""

    weld_vertices: bool | None = option(None, "mesh files: weld vertices at exactly the same coordinates (default: "
                                              "STL files only, whose triangles store their corners apart; the "
                                              "count is in Model.bookkeeping)", check=_weld, parse=_yes_no,
                                        metavar="yes|no", optional=True)
    units: str = option("mm", "mesh files: the unit of the coordinates, converted to mm (CAD files are read in "
                              "mm whatever this says); on the command line also the unit of the DXF",
                        choices=UNIT_NAMES)


def load(source, options: LoadOptions | None = None, **keywords):
    """Load a part as panels joined by seams.

    Parameters
    ----------
    source : str, Path or build123d shape
        A CAD file (.step/.stp, .brep, .iges/.igs), a mesh file (.stl, .obj,
        .ply, .off, .3mf), or a build123d ``Face``, ``Shell``, ``Solid``,
        ``Compound`` or ``Part``.
    options : LoadOptions, optional
        The options as a record; keywords (any field of :class:`LoadOptions`)
        go over it.  CAD: ``max_edge`` (mm), ``chord_tolerance`` (mm),
        ``angular_tolerance`` (radians), ``panels`` (groups of CAD faces cut as
        one panel each, ``{"front": [0, 1]}``), ``sew``; see
        :func:`patterns.tessellate.mesh_shape`.  Mesh files:
        ``weld_vertices`` (see :func:`read_mesh`) and ``units`` (the unit of
        the file's coordinates; the model is in mm).

    Returns
    -------
    Model
        In mm; :attr:`Model.bookkeeping` says what loading did (vertices
        welded, unused vertices dropped, cuts made to open tubes).

    Raises
    ------
    InputError
        Missing file, unknown suffix, bad values in a mesh, bad options.
    CadError
        Empty, corrupt or face-less CAD file; a face that cannot be meshed.
    MeshTopologyError
        A mesh piece that is non-manifold, inconsistently wound, or has handles.
    """
    name = str(source) if isinstance(source, (str, Path)) else type(source).__name__
    opts = LoadOptions.of(options, keywords, name=name)
    meshing = {f.name: getattr(opts, f.name) for f in fields(MeshingOptions)}
    if isinstance(source, (str, Path)):
        path = Path(source)
        suffix = path.suffix.lower()
        if suffix in CAD_SUFFIXES:
            if opts.weld_vertices is not None:
                raise InputError(f"{path}: weld_vertices applies to mesh files only")
            return mesh_shape(read_cad(path), name=path.name, **meshing)
        if suffix in MESH_SUFFIXES:
            if opts.panels is not None:
                raise InputError(f"{path}: panels (groups of CAD faces) apply to CAD files only")
            mesh = read_mesh(path, weld_vertices=opts.weld_vertices)
            scale = Unit(opts.units).mm
            model = mesh_model(mesh.vertices * scale if scale != 1.0 else mesh.vertices, mesh.faces, name=path.name)
            return replace(model, bookkeeping=replace(model.bookkeeping, welded=mesh.n_welded,
                                                      unused=mesh.n_unused))
        if not path.exists():
            raise InputError(f"{path}: no such file")
        raise InputError(f"{path}: unknown file type {suffix or '(none)'!r}; expected a CAD file "
                         f"({', '.join(CAD_SUFFIXES)}) or a mesh file ({', '.join(MESH_SUFFIXES)})")
    if hasattr(source, "wrapped"):
        return mesh_shape(source, name=type(source).__name__, **meshing)
    raise InputError(f"cannot load a {type(source).__name__}: give a file path or a build123d shape")


def mesh_model(vertices, faces, *, name: str = "mesh"):
    """A :class:`Model` from a triangle mesh: one panel per connected piece, cut open where needed.

    Parameters
    ----------
    vertices : (n, 3) float, mm
    faces : (m, 3) int
    name : str

    Returns
    -------
    Model
        Panels ``piece0``, ``piece1``, ... in order of their first face;
        seams are the cuts (``cad_edge`` None, both sides on one panel).
    """

    v, f = as_mesh_arrays(vertices, faces, name=name)
    panels, seams = [], []
    groups = pieces(f, len(v), name=name)
    for i, group in enumerate(groups):
        label = f"piece{i}"
        pname = name if len(groups) == 1 else f"{name}: {label}"
        pv, pf, _ = drop_unused(v, f[group])
        cut = cut_to_disk(pv, pf, name=pname)
        panels.append(panel_from_mesh(label, cut.vertices, cut.faces, name=pname))
        for path, (left, right) in zip(cut.paths, cut.sides):
            points = pv[path]
            seams.append(Seam(id=len(seams), panels=(i, i), points=points, vertices=(left, right),
                              length=polyline_length(points)))
    edges = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    longest = float(np.linalg.norm(v[edges[:, 1]] - v[edges[:, 0]], axis=1).max())
    return Model(name=name, panels=tuple(panels), seams=tuple(seams), max_edge=longest,
                 bookkeeping=Bookkeeping(cuts=len(seams)))
