"""Reading meshes from files.

Mesh files (.obj, .stl, .ply, .off) are read by trimesh with ``process=False``:
trimesh never merges or drops anything silently.  Indexed formats (OBJ, PLY,
OFF) keep the connectivity the file gives -- two vertices at the same place are
still two vertices, as where a boundary touches itself -- and only vertices no
face uses are dropped.  STL stores every triangle's corners separately, so its
vertices at exactly the same coordinates are welded here, explicitly, and the
count is reported.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .errors import InputError
from .mesh import as_mesh_arrays

__all__ = ["MESH_SUFFIXES", "MeshFile", "drop_unused", "read_mesh", "weld"]

MESH_SUFFIXES = (".obj", ".stl", ".ply", ".off")
"""File suffixes :func:`read_mesh` reads."""


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
    used = np.unique(faces.ravel())
    n_unused = len(vertices) - len(used)
    _, first, inverse = np.unique(vertices[used], axis=0, return_index=True, return_inverse=True)
    # Keep the order of first appearance (stable, deterministic output).
    rank = np.empty(len(first), dtype=np.int64)
    rank[np.argsort(first, kind="stable")] = np.arange(len(first))
    remap = np.full(len(vertices), -1, dtype=np.int64)
    remap[used] = rank[inverse.ravel()]
    new_vertices = vertices[used][np.sort(first)]
    return new_vertices, remap[faces], len(used) - len(first), n_unused


def drop_unused(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray, int]:
    """Remove vertices that no face uses, keeping the order of the others.

    Returns
    -------
    vertices : (k, 3) float64
    faces : (m, 3) int64
        Re-indexed.
    n_unused : int
    """
    used = np.zeros(len(vertices), dtype=bool)
    used[faces.ravel()] = True
    remap = np.cumsum(used) - 1
    return vertices[used], remap[faces], int((~used).sum())


def read_mesh(path, *, weld_vertices: bool | None = None) -> MeshFile:
    """Read a triangle mesh file.

    Parameters
    ----------
    path : str or Path
        An .obj, .stl, .ply or .off file.
    weld_vertices : bool, optional
        Merge vertices at identical coordinates.  Default: only for STL, which
        has no shared vertices.  Unused vertices are always dropped.

    Returns
    -------
    MeshFile

    Raises
    ------
    InputError
        Missing or unreadable file, unknown suffix, no triangles, bad values;
        the message names the file.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in MESH_SUFFIXES:
        raise InputError(f"{path}: unknown mesh file type {suffix or '(none)'!r}; "
                         f"expected one of {', '.join(MESH_SUFFIXES)}")
    if not path.is_file():
        raise InputError(f"{path}: no such file")
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
        weld_vertices = suffix == ".stl"
    if weld_vertices:
        vertices, faces, n_welded, n_unused = weld(vertices, faces)
    else:
        vertices, faces, n_unused = drop_unused(vertices, faces)
        n_welded = 0
    vertices.setflags(write=False)
    faces.setflags(write=False)
    return MeshFile(vertices, faces, path, n_welded, n_unused)
