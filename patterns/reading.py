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

import contextlib
import os
import re
import sys
import tempfile
from dataclasses import dataclass, fields, replace
from pathlib import Path

import numpy as np

from .cut import chains, components, crease_regions, cut_along, cut_to_disk, is_closed, shared_chains
from .errors import CadError, InputError, MeshTopologyError, MissingFileError
from .files import check_input_file
from .mesh import MAX_TRIANGLES, as_mesh_arrays, check_faces_have_area, drop_unused, polyline_length, unique_ints
from .model import Bookkeeping, Model, Seam, panel_from_mesh
from .options import option
from .tessellate import MeshingOptions, mesh_shape
from .text import printable
from .units import UNIT_NAMES, Unit

__all__ = ["CAD_SUFFIXES", "MAX_FILE_BYTES", "MESH_SUFFIXES", "LoadOptions", "MeshFile", "check_source", "drop_unused",
           "load", "mesh_model", "read_cad", "read_mesh", "weld"]

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


MAX_FILE_BYTES = 1 << 30
"""The largest input file read, bytes (1 GiB: some 4 million triangles as ASCII STL); a 3MF's
members are counted as they would be inflated, before anything is inflated."""


def _existing_file(path, suffixes, kind: str) -> tuple[Path, str]:
    """``(Path, lower-case suffix)`` of a readable regular file of a known type, else the one-line InputError."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in suffixes:
        raise InputError(f"{os.fsdecode(path)}: unknown {kind} file type {suffix or '(none)'!r}; "
                         f"expected one of {', '.join(suffixes)}")
    check_input_file(path, what=f"{kind} file")
    size = path.stat().st_size
    if size > MAX_FILE_BYTES:
        raise InputError(f"{os.fsdecode(path)}: {size / 2**30:.1f} GiB, over the limit of "
                         f"{MAX_FILE_BYTES / 2**30:.0f} GiB for one part")
    return path, suffix


def check_source(path, suffixes=None) -> Path:
    """``path`` as a part file this run can read: a known suffix, a readable regular file, not too large.

    The check :func:`load` makes first, for a caller that plans a run before
    doing any work (the command line).  Raises the same one-line InputError.
    """
    path = Path(path)
    if path.is_dir():
        raise InputError(f"{os.fsdecode(path)}: is a folder; give a CAD or mesh file")
    suffixes = suffixes or CAD_SUFFIXES + MESH_SUFFIXES
    suffix = path.suffix.lower()
    if suffix not in suffixes:
        cad = [s for s in CAD_SUFFIXES if s in suffixes]
        mesh = [s for s in MESH_SUFFIXES if s in suffixes]
        wanted = " or ".join([f"a CAD file ({', '.join(cad)})"] * bool(cad) + [f"a mesh file ({', '.join(mesh)})"] * bool(mesh))
        if suffix in MESH_SUFFIXES and not mesh:  # unfold: a mesh is a part, but not a bent sheet
            raise InputError(f"{os.fsdecode(path)}: is a mesh; unfolding takes {wanted} (a mesh has no exact bends: "
                             f"flatten it instead)")
        raise InputError(f"{os.fsdecode(path)}: unknown file type {suffix or '(none)'!r}; expected {wanted}")
    kind = "CAD" if path.suffix.lower() in CAD_SUFFIXES else "mesh"
    return _existing_file(path, suffixes, kind)[0]


def _check_zip(path: Path, data: bytes) -> None:
    """A 3MF is a zip: refuse it before inflating when its members would exceed MAX_FILE_BYTES."""
    import io
    import zipfile

    try:
        with zipfile.ZipFile(io.BytesIO(data)) as z:
            inflated = sum(info.file_size for info in z.infolist())
    except (zipfile.BadZipFile, OSError, ValueError) as exc:
        raise InputError(f"{os.fsdecode(path)}: cannot read this .3mf file (not a zip archive: {exc})") from None
    if inflated > MAX_FILE_BYTES:
        raise InputError(f"{os.fsdecode(path)}: its members inflate to {inflated / 2**30:.1f} GiB, over the limit "
                         f"of {MAX_FILE_BYTES / 2**30:.0f} GiB for one part ({len(data) / 2**20:.1f} MiB packed)")


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
    import io

    import trimesh  # heavy; only when a file is read

    shown = os.fsdecode(path)
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise InputError(f"{shown}: cannot read the mesh file ({exc.strerror})") from None
    if suffix == ".3mf":
        _check_zip(path, data)
    # From memory, with no resolver: an OBJ's material library (mtllib) is never opened -- it
    # may name anything, a pipe or a device among them -- and materials do not matter here.
    extra = {"skip_materials": True} if suffix == ".obj" else {}
    try:
        loaded = trimesh.load(io.BytesIO(data), file_type=suffix[1:], process=False, force="mesh", **extra)
    except MemoryError:
        raise
    except Exception as exc:  # noqa: BLE001 - trimesh raises many kinds on a broken file
        raise InputError(f"{shown}: cannot read this {suffix} file ({type(exc).__name__}: {exc})") from None
    if isinstance(loaded, trimesh.Scene):  # pragma: no cover - force="mesh" folds scenes
        geometries = list(loaded.geometry.values())
        loaded = trimesh.util.concatenate(geometries) if geometries else None
    if loaded is None or len(getattr(loaded, "faces", ())) == 0:
        raise InputError(f"{shown}: the file holds no triangles")
    if len(loaded.faces) > MAX_TRIANGLES:
        raise InputError(f"{shown}: {len(loaded.faces)} triangles, over the limit of {MAX_TRIANGLES:.0e}; "
                         f"decimate the mesh or split it into parts")
    vertices, faces = as_mesh_arrays(loaded.vertices, loaded.faces, name=shown)
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


_SKIPPED_REPAIRS = ("FixShape.FixSelfIntersectionMode", "FixShape.FixIntersectingWiresMode")
"""OpenCascade's shape-healing steps the readers skip: both test every pair of edges or wires of a face against
each other, over the whole face each time, so a plate with 5,000 holes took 20 minutes to read.  Crossing wires
come only from a broken export: the meshing refuses a face whose boundary crosses itself
(``tessellate.topology._check_wire``, each wire on its own), and unfolded, crossing contours are refused by the
blank's own contour check."""


def _lighter_repairs(reader) -> None:
    """Switch :data:`_SKIPPED_REPAIRS` off on a STEP or IGES reader; every other repair stays as OpenCascade has it."""
    from OCP.TCollection import TCollection_AsciiString

    parameters = reader.GetShapeFixParameters()
    for key in _SKIPPED_REPAIRS:
        parameters.Bind(TCollection_AsciiString(key), TCollection_AsciiString("0"))
    reader.SetShapeFixParameters(parameters)


def read_cad(path):
    """Read a STEP, BREP or IGES file into an OpenCascade shape (millimetres).

    Parameters
    ----------
    path : str or Path
        Any name the file system allows (bytes that are not UTF-8 too).

    Returns
    -------
    OCP.TopoDS.TopoDS_Shape
        STEP and IGES are converted to millimetres by OpenCascade's readers;
        BREP carries no unit and is taken as millimetres.

    Raises
    ------
    InputError
        Missing, unreadable (permission) or special file, or an unknown suffix.
    CadError
        The file is empty, corrupt, or holds no shape; the message carries
        OpenCascade's own first complaint, which is kept off the console.
    """
    path, suffix = _existing_file(path, CAD_SUFFIXES, "CAD")
    shown = os.fsdecode(path)
    if path.stat().st_size == 0:
        raise CadError(f"{shown}: the file is empty")
    from OCP.IFSelect import IFSelect_RetDone

    kind = {".step": "STEP", ".stp": "STEP", ".iges": "IGES", ".igs": "IGES"}.get(suffix, "BREP")
    shape = None
    with _utf8_name(path) as name, _native_stdout() as said:
        try:
            if kind == "BREP":
                from OCP.BRep import BRep_Builder
                from OCP.BRepTools import BRepTools
                from OCP.TopoDS import TopoDS_Shape

                shape = TopoDS_Shape()
                ok = BRepTools.Read_s(shape, name, BRep_Builder())
            else:
                if kind == "STEP":
                    from OCP.STEPControl import STEPControl_Reader as Reader
                else:
                    from OCP.IGESControl import IGESControl_Reader as Reader
                reader = Reader()
                ok = reader.ReadFile(name) == IFSelect_RetDone
                if ok:
                    _lighter_repairs(reader)
                    reader.TransferRoots()
                    shape = reader.OneShape()
        except Exception as exc:  # noqa: BLE001 - OpenCascade raises many kinds
            raise CadError(f"{shown}: cannot read this {kind} file ({type(exc).__name__}: {exc})") from None
    if not ok:
        why = _first_complaint(said)
        raise CadError(f"{shown}: not a readable {kind} file (corrupt, truncated or another format"
                       f"{': ' + why if why else ''})")
    if shape is None or shape.IsNull():
        raise CadError(f"{shown}: the {kind} file holds no shape")
    return shape


@contextlib.contextmanager
def _utf8_name(path: Path):
    """A name OpenCascade takes for ``path``: itself, or (for a name that is not UTF-8, which its
    bindings cannot pass) a link to it with a plain name in a private temporary folder."""
    name = os.fsdecode(path)
    try:
        name.encode("utf-8")
    except UnicodeEncodeError:
        with tempfile.TemporaryDirectory(prefix="patterns-") as tmp:
            link = os.path.join(tmp, "part" + path.suffix.lower())
            os.symlink(os.path.abspath(path), link)
            yield link
        return
    yield name


@contextlib.contextmanager
def _native_stdout():
    """Catch what native code (OpenCascade) prints on file descriptor 1; yields a list that holds it after."""
    import ctypes

    said: list = []
    fd = 1  # where std::cout writes, whatever Python's sys.stdout is now
    with contextlib.suppress(AttributeError, OSError, ValueError):
        sys.stdout.flush()
    saved = os.dup(fd)
    libc = ctypes.CDLL(None)
    with tempfile.TemporaryFile() as tmp:
        os.dup2(tmp.fileno(), fd)
        try:
            yield said
        finally:
            libc.fflush(None)
            os.dup2(saved, fd)
            os.close(saved)
            tmp.seek(0)
            said.append(tmp.read().decode("utf-8", errors="replace"))


def _first_complaint(said: list) -> str:
    """OpenCascade's first message, without its colours and stars."""
    text = re.sub(r"\x1b\[[0-9;]*m", "", "".join(said))
    for line in text.splitlines():
        line = line.strip(" *\t")
        if line:
            return line[:160]
    return ""


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
                              "mm whatever this says; the drawing's unit is --units)",
                        choices=UNIT_NAMES, flag="--input-units")
    crease_angle: float = option(60.0, "mesh files: a closed piece (a box, a can) is split into panels along the "
                                       "edges whose faces meet at more than this angle, degrees; a closed piece "
                                       "with no such edge (a sphere) is refused", low=0, high=180, low_open=True,
                                 metavar="DEG")


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
        shown = os.fsdecode(path)
        if suffix in CAD_SUFFIXES:
            if opts.weld_vertices is not None:
                raise InputError(f"{shown}: weld_vertices applies to mesh files only")
            return mesh_shape(read_cad(path), name=printable(path.name), **meshing)
        if suffix in MESH_SUFFIXES:
            if opts.panels is not None:
                raise InputError(f"{shown}: panels (groups of CAD faces) apply to CAD files only")
            mesh = read_mesh(path, weld_vertices=opts.weld_vertices)
            scale = Unit(opts.units).mm
            model = mesh_model(mesh.vertices * scale if scale != 1.0 else mesh.vertices, mesh.faces,
                               name=printable(path.name), crease_angle=opts.crease_angle)
            return replace(model, bookkeeping=replace(model.bookkeeping, welded=mesh.n_welded,
                                                      unused=mesh.n_unused, units=opts.units))
        if path.is_dir():
            raise InputError(f"{shown}: is a folder; give a CAD or mesh file")
        if not path.exists():
            raise MissingFileError(f"{shown}: no such file")
        raise InputError(f"{shown}: unknown file type {suffix or '(none)'!r}; expected a CAD file "
                         f"({', '.join(CAD_SUFFIXES)}) or a mesh file ({', '.join(MESH_SUFFIXES)})")
    if getattr(source, "wrapped", None) is not None:  # a build123d shape: mesh_shape checks what it wraps
        return mesh_shape(source, name=type(source).__name__, **meshing)
    raise InputError(f"cannot load a {type(source).__name__}: give a file path or a build123d shape")


def mesh_model(vertices, faces, *, name: str = "mesh", crease_angle: float = 60.0, seams=None):
    """A :class:`Model` from a triangle mesh: one panel per connected piece, cut open where needed.

    Parameters
    ----------
    vertices : (n, 3) float, mm
    faces : (m, 3) int
    name : str
    crease_angle : float
        A closed piece (a box, a can: no boundary at all) is split into panels
        along its creases, the edges whose faces meet at more than this many
        degrees; the creases become seams.  A closed piece without such
        creases (a sphere) is refused: one cut cannot lay it flat.
    seams : (k, 2) int, optional
        Edges marked as seams (Blender's ``use_seam``): the mesh is cut open along them first, and each
        chain of marked edges becomes a seam between the panels on its two sides (on one panel where it
        does not part it: a tube cut along one line).  An edge on the mesh's boundary is a seam already.

    Returns
    -------
    Model
        Panels ``piece0``, ``piece1``, ... in order of their first face (a
        closed piece split along its creases: ``piece0.0``, ``piece0.1``,
        ...); seams are the cuts made to open tubes (``cad_edge`` None, both
        sides on one panel) and the creases.

    Raises
    ------
    MeshTopologyError
        A closed piece without creases, or one still closed after splitting;
        a piece with handles; a non-manifold or inconsistently wound piece.
    InputError
        Bad arrays; more than :data:`~patterns.mesh.MAX_TRIANGLES` triangles.
    """

    v, f = as_mesh_arrays(vertices, faces, name=name)
    if len(f) > MAX_TRIANGLES:
        raise InputError(f"{name}: {len(f)} triangles, over the limit of {MAX_TRIANGLES:.0e}; decimate the mesh "
                         f"or split it into parts")
    check_faces_have_area(v, f, name=name)
    marked = _marked_seams(v, f, seams, name)
    if marked:
        opened = cut_along(v, f, marked, name=name)
        v, f = np.asarray(opened.vertices), np.asarray(opened.faces)
        marked = list(zip(marked, opened.sides))
    panels, seams, cuts, split = [], [], 0, 0
    where = np.full((len(v), 2), -1, dtype=np.int64)  # each vertex's (panel, index in it), first copy
    groups = components(f, len(v), name=name)
    for i, group in enumerate(groups):
        pname = name if len(groups) == 1 else f"{name}: piece{i}"
        used = unique_ints(f[group])
        regions = [np.arange(len(group))]
        local = np.searchsorted(used, f[group])  # the piece's faces on its own vertices
        if is_closed(local, len(used), name=pname):
            regions = crease_regions(v[used], local, angle=crease_angle, name=pname)
            if len(regions) == 1:
                cut_to_disk(v[used], local, name=pname)  # a torus: refused for its handles first
                raise MeshTopologyError(
                    f"{pname}: a closed surface with no crease sharper than {crease_angle:g} degrees (a sphere, a "
                    f"blob): no single cut lays it flat without gross distortion; give it seams (split it into "
                    f"panels, e.g. two domes) or a lower crease_angle")
            split += 1
        first = len(panels)
        maps = []
        for r, region in enumerate(regions):
            label = f"piece{i}" if len(regions) == 1 else f"piece{i}.{r}"
            rname = pname if len(regions) == 1 else f"{pname}.{r}"
            rv = unique_ints(local[region])
            rf = np.searchsorted(rv, local[region])
            if len(regions) > 1 and is_closed(rf, len(rv), name=rname):
                raise MeshTopologyError(f"{rname}: still closed after splitting along its creases; give it seams")
            cut = cut_to_disk(v[used][rv], rf, name=rname)
            panels.append(panel_from_mesh(label, cut.vertices, cut.faces, name=rname))
            maps.append(rv)
            where[used[rv]] = np.stack([np.full(len(rv), len(panels) - 1), np.arange(len(rv))], axis=1)
            for path, (left, right) in zip(cut.paths, cut.sides):
                points = v[used][rv][path]
                seams.append(Seam(id=len(seams), panels=(len(panels) - 1,) * 2, points=points,
                                  vertices=(left, right), length=polyline_length(points)))
                cuts += 1
        if len(regions) > 1:
            for a, b, path in shared_chains(local, regions):
                points = v[used][path]
                sides = tuple(np.searchsorted(maps[r], path) for r in (a, b))
                seams.append(Seam(id=len(seams), panels=(first + a, first + b), points=points, vertices=sides,
                                  length=polyline_length(points)))
    for path, (left, right) in marked:  # the marked seams, each between the panels on its two sides
        points = v[left]
        (pl, *_), (pr, *_) = where[left, 0], where[right, 0]
        seams.append(Seam(id=len(seams), panels=(int(pl), int(pr)), points=points,
                          vertices=(where[left, 1], where[right, 1]), length=polyline_length(points)))
    edges = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    longest = float(np.linalg.norm(v[edges[:, 1]] - v[edges[:, 0]], axis=1).max())
    return Model(name=name, panels=tuple(panels), seams=tuple(seams), max_edge=longest,
                 bookkeeping=Bookkeeping(cuts=cuts, split=split))


def _marked_seams(v: np.ndarray, f: np.ndarray, seams, name: str) -> list:
    """The marked seam edges as vertex paths (:func:`patterns.cut.chains`), those on the boundary left out;
    InputError for an edge the mesh has not."""
    if seams is None:
        return []
    try:
        edges = np.asarray(seams, dtype=np.int64).reshape(-1, 2)
    except (TypeError, ValueError):
        raise InputError(f"{name}: seams must be pairs of vertex indices (k x 2)") from None
    if not len(edges):
        return []
    half = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    n = len(v)
    count = np.bincount(np.minimum(half[:, 0], half[:, 1]) * n + np.maximum(half[:, 0], half[:, 1]))
    lo, hi = np.minimum(edges[:, 0], edges[:, 1]), np.maximum(edges[:, 0], edges[:, 1])
    bad = (lo < 0) | (hi >= n) | (lo == hi)
    keys = np.where(bad, 0, lo * n + hi)
    faces_of = np.where(bad | (keys >= len(count)), 0, count[np.minimum(keys, len(count) - 1)])
    missing = np.flatnonzero(bad | (faces_of == 0))
    if len(missing):
        a, b = edges[missing[0]]
        raise InputError(f"{name}: seam edge ({a}, {b}) is no edge of the mesh ({len(missing)} such)")
    inner = np.unique(np.stack([lo, hi], axis=1)[faces_of == 2], axis=0)
    return chains(inner)
