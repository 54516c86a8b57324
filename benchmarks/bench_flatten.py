"""Time and quality of `patterns` flattening against libigl's LSCM, ARAP and SLIM (issue 16's criteria).

Run from the repository root::

    python benchmarks/bench_flatten.py                 # everything (about 25 minutes on 2 idle cores)
    python benchmarks/bench_flatten.py --quick         # 1k surfaces, corpus meshes up to 10k faces
    python benchmarks/bench_flatten.py --sizes 1k,10k --no-corpus
    python benchmarks/bench_flatten.py --markdown > tables.md
    python benchmarks/bench_flatten.py --folder DIR --sizes "" --extra-sizes ""   # the meshes of DIR only

Meshes
------
* every ``*.obj`` / ``*.off`` in ``../shared/corpus/`` relative to the repository
  root (up to ``--max-corpus-faces`` faces), loaded with
  ``trimesh.load(path, process=False)`` (skipped, with the reason printed, when
  the folder is absent or ``--no-corpus`` is given);
* the same of ``benchmarks/data/limbs/`` (:data:`LIMBS`, issue 37; ``*.obj.gz``, bundled):
  OptCuts' benchmark inputs with long thin limbs (two hands, an armadillo, a dinosaur, a torso
  with arms), their provenance and licence in that folder's README.md;
* generated surfaces at about 1k, 10k, 100k and 1M faces (``--sizes``): a 60
  degree spherical cap (``cap60``: radius 100 mm, polar half-angle 30 degrees), a
  paraboloid dish, a saddle and a half cylinder (exactly developable); and at
  about 10k and 100k faces only (``--extra-sizes``): a hemisphere, an ellipsoid
  cup and a torus patch.

Methods (``--methods``; default all but ``conformal``)
------------------------------------------------------
* ``relaxed``: :func:`patterns.flatten_mesh` with default options (method
  ``"relaxed"``, energy ``"auto"``); the time covers the whole call (input
  validation, the grower, the relaxation, the overlap verdict).  The note gives
  the start layout, the energy that ran, the iterations (and "not converged").
* ``relaxed-shuffled``: the same call on the same mesh with its vertices AND its
  faces renumbered by one fixed random permutation (seed :data:`SHUFFLE_SEED`,
  drawn outside the timed region); the layout is mapped back to the original
  numbering and measured on the original mesh.
* ``isometric``: :func:`patterns.flatten_mesh` with ``method="isometric"``.
* ``conformal`` (only when named in ``--methods``): the pure-Python reference
  grower, up to ``--max-faces-conformal`` faces.
* ``lscm``: ``igl.lscm`` with the two farthest-apart boundary vertices pinned at
  their 3D distance apart; its uv is then multiplied by the single factor that
  makes the total flat area the 3D area (LSCM has no scale of its own).
* ``arap``: as in libigl's tutorial: boundary to a circle
  (``igl.map_vertices_to_circle``), harmonic initialisation (``igl.harmonic``),
  then ``igl.arap_precomputation`` (2D) and ``igl.arap_solve`` with the default
  ``igl.ARAPData`` (10 iterations), one vertex held at its initial position (the
  translation only).  The time includes the harmonic initialisation.
* ``slim``: ``igl.slim_precompute`` / ``igl.slim_solve``, symmetric Dirichlet,
  no constraints, :data:`SLIM_ITERATIONS` iterations, from Tutte's embedding
  (uniform weights, the boundary on the circle: one-to-one, as SLIM needs; the
  harmonic map folds the OptCuts armadillo and dinosaur), included in the time;
  up to ``--max-faces-slim`` faces.  (Until issue 37 SLIM started from the
  harmonic map; the tables of docs/benchmarks.md say which.)

Every row is measured by the same code outside the timed region:
:func:`patterns.distortion` (area-weighted principal-strain RMS and max,
symmetric Dirichlet energy, ``stretch_p1``, folded triangles, edge strain) and
:func:`patterns.overlap_verdict` (one-to-one).  Times are the best of 3 runs up
to :data:`REPEAT_LIMIT` faces and of 1 run above, all methods in one process.
The edge-strain RMS is a column only: it counts edges, so it depends on the
triangulation; the principal-strain RMS is the judge.

Acceptance summary
------------------
After the tables, ``relaxed`` against libigl ARAP and SLIM per mesh, PASS/FAIL
with the numbers, and a count of PASS/FAIL per criterion:

* (0) every mesh: 0 folded triangles and one-to-one;
* (a) where ARAP has no folded triangle: strain RMS <= 1.0 x ARAP's (a FAIL by
  less than 1e-4, relative, is marked "(tie)" and counted apart: both at the
  same minimum);
* (b) where ARAP folds: 0 folds, one-to-one, strain RMS < SLIM's, ``stretch_p1``
  >= 0.1, symmetric Dirichlet <= 1.2 x SLIM's, time <= 2 x SLIM's;
* (c) meshes of 80k-200k faces: time <= ARAP's;
* (d) meshes of >= 500k faces: time (the table's row) <= 10 s and peak memory
  < 4 GB.  The memory is the peak resident set size (``VmHWM``) of a separate
  child process that imports ``patterns``, loads the mesh from ``.npy`` files
  and runs ``flatten_mesh(V, F)`` once (so it includes the interpreter, the
  imports and the input arrays);
* (e) every mesh: ``relaxed-shuffled``'s time <= 1.5 x ``relaxed``'s and its
  strain RMS within 0.5 % (relative) of ``relaxed``'s (or within 1e-9 absolute:
  the round-off of an exactly developable mesh's zero strain);
* (f) exactly developable meshes (the ``cylinder`` surfaces): edge strain max
  < 1e-9.
"""

from __future__ import annotations

import argparse
import gzip
import json
import os
import platform
import subprocess
import sys
import time
from dataclasses import dataclass
from importlib import metadata
from pathlib import Path

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

REPO = Path(__file__).resolve().parent.parent
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

import igl
import trimesh

import patterns
from patterns import surfaces
from patterns.launch import one_run_allocator
from patterns.measure import folded_faces

CORPUS = REPO.parent / "shared" / "corpus"
"""The shared corpus of real disk-topology meshes."""

LIMBS = REPO / "benchmarks" / "data" / "limbs"
"""OptCuts' benchmark inputs with long thin limbs (two hands, an armadillo, a dinosaur, a torso), disks,
bundled gzip-compressed with their provenance and licence (its README.md) (issue 37)."""

SIZES = {"1k": 1_000, "10k": 10_000, "100k": 100_000, "1M": 1_000_000}
"""Face counts of the generated surfaces, by the label used on the command line."""

ALL_METHODS = ("relaxed", "relaxed-shuffled", "isometric", "conformal", "lscm", "arap", "slim")
"""Every method the benchmark knows, in the order the rows are printed."""

DEFAULT_METHODS = tuple(m for m in ALL_METHODS if m != "conformal")
"""Methods run when ``--methods`` is not given (``conformal`` only on request)."""

SHUFFLE_SEED = 16
"""Seed of the fixed random renumbering of the ``relaxed-shuffled`` rows."""

REPEAT_LIMIT = 200_000
"""Meshes with at most this many faces are timed best of 3, larger ones once."""

SLIM_ITERATIONS = 20
"""Iterations of ``igl.slim_solve``."""

ACCEPT_ARAP_RATIO = 1.0
"""(a) Where ARAP does not fold: ``relaxed`` strain RMS at most this times ARAP's."""

ACCEPT_ARAP_TIE = 1e-4
"""(a) Not a criterion: a FAIL by less than this (relative) is marked "(tie)" and counted apart --
both at the same minimum, relaxed above ARAP by round-off or the last iterations."""

ACCEPT_P1 = 0.1
"""(b) Where ARAP folds: ``stretch_p1`` at least this (no crushed triangle)."""

ACCEPT_SD_RATIO = 1.2
"""(b) Where ARAP folds: symmetric Dirichlet energy at most this times SLIM's."""

ACCEPT_SLIM_TIME = 2.0
"""(b) Where ARAP folds: time at most this times SLIM's."""

ACCEPT_100K = (80_000, 200_000)
"""(c) Meshes with a face count in this range: time at most ARAP's."""

ACCEPT_1M = 500_000
"""(d) Meshes with at least this many faces are judged on time and memory."""

ACCEPT_1M_SECONDS = 10.0
ACCEPT_1M_BYTES = 4e9
"""(d) Time at most 10 s, peak resident memory under 4 GB (4e9 bytes)."""

ACCEPT_SHUFFLED_TIME = 1.5
ACCEPT_SHUFFLED_RMS = 0.005
ACCEPT_SHUFFLED_FLOOR = 1e-9
"""(e) Renumbered at random: time within 1.5 x, strain RMS within 0.5 % (relative) -- or within 1e-9
absolute, the round-off of an exactly developable mesh's zero strain."""

ACCEPT_DEVELOPABLE = 1e-9
"""(f) Exactly developable meshes: edge strain max below this."""

DEVELOPABLE = ("cylinder",)
"""Generated shapes that are exactly developable (judged on (f))."""


# --------------------------------------------------------------------------- #
# Rows and formatting
# --------------------------------------------------------------------------- #


@dataclass
class Row:
    """One line of the result table: one method on one mesh.

    Attributes
    ----------
    mesh : str
    faces : int
    method : str
    seconds : float or None
        Best wall-clock time, or None when the method did not run.
    rms, max : float or None
        Area-weighted RMS of both principal strains, and the largest principal
        strain magnitude (``Distortion.strain_rms``, ``strain_max``).
    sd : float or None
        Area-weighted symmetric Dirichlet energy (4 for an isometry, inf if folded).
    p1 : float or None
        1st percentile (by area) of the smallest principal stretch.
    folds : int or None
        Triangles with flat signed area <= 0.
    one_to_one : bool or None
        The overlap verdict; None when it could not be computed.
    edge_rms, edge_max : float or None
        Edge strain ``|l_flat / l_3d - 1|``: RMS and maximum over the edges
        (mesh-dependent; a column only).
    note : str
        Errors, skips, rescale factors, sub-timings, start/energy/iterations.
    """

    mesh: str
    faces: int
    method: str
    seconds: float | None = None
    rms: float | None = None
    max: float | None = None
    sd: float | None = None
    p1: float | None = None
    folds: int | None = None
    one_to_one: bool | None = None
    edge_rms: float | None = None
    edge_max: float | None = None
    note: str = ""


COLUMNS = ("mesh", "faces", "method", "seconds", "/ ARAP", "/ SLIM", "strain RMS %", "strain max %",
           "sym. Dirichlet", "stretch p1", "folds", "one-to-one", "edge-strain RMS % (mesh-dep.)", "note")
"""Table header."""

WIDTHS = (18, 7, 16, 8, 6, 6, 8, 8, 9, 7, 6, 4, 8, 0)
"""Column widths of the plain-text table."""

PLAIN_COLUMNS = ("mesh", "faces", "method", "seconds", "/ARAP", "/SLIM", "RMS %", "max %", "sym.Dir.",
                 "p1", "folds", "1:1", "edgeRMS%", "note")
"""Shorter header of the plain-text table."""


def _percent(x: float | None) -> str:
    if x is None:
        return ""
    if not np.isfinite(x):
        return str(x)
    p = 100.0 * x
    return f"{p:.3g}" if p < 1e4 else f"{p:.2e}"


def _number(x: float | None, fmt: str = ".4g") -> str:
    if x is None:
        return ""
    if not np.isfinite(x):
        return str(x)
    return format(x, fmt)


def _cells(row: Row, arap_seconds: float | None, slim_seconds: float | None) -> list[str]:
    """Format one row as table cells (the ratios are to ARAP's and SLIM's time on the same mesh)."""
    ratios = []
    for ref in (arap_seconds, slim_seconds):
        ratios.append(f"{row.seconds / ref:.2f}" if row.seconds is not None and ref else "")
    return [
        row.mesh,
        str(row.faces),
        row.method,
        "" if row.seconds is None else f"{row.seconds:.3f}",
        *ratios,
        _percent(row.rms),
        _percent(row.max),
        _number(row.sd),
        _number(row.p1, ".3f"),
        "" if row.folds is None else str(row.folds),
        {True: "yes", False: "no", None: ""}[row.one_to_one],
        _percent(row.edge_rms),
        row.note,
    ]


def _reference_seconds(rows: list[Row]) -> tuple[float | None, float | None]:
    """ARAP's and SLIM's time among one mesh's rows."""
    by = {r.method: r.seconds for r in rows}
    return by.get("arap"), by.get("slim")


def plain_line(cells, widths=WIDTHS) -> str:
    """One fixed-width plain-text table line."""
    parts = []
    for cell, width in zip(cells, widths, strict=True):
        parts.append(f"{cell:<{width}}" if width else cell)
    return " ".join(parts).rstrip()


def format_table(header, rows, markdown: bool) -> str:
    """A table of strings: markdown, or plain text with columns as wide as their widest cell."""
    rows = [[str(c) for c in row] for row in rows]
    if markdown:
        lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
        return "\n".join(lines + ["| " + " | ".join(c.replace("|", "/") for c in row) + " |" for row in rows])
    widths = [max(len(str(h)), *(len(row[k]) for row in rows)) if rows else len(str(h))
              for k, h in enumerate(header)]
    return "\n".join("  ".join(f"{c:<{w}}" for c, w in zip(row, widths, strict=True)).rstrip()
                     for row in [list(header), *rows])


def markdown_table(groups: list[list[Row]]) -> str:
    """Markdown table of several meshes' rows (each group is one mesh)."""
    lines = ["| " + " | ".join(COLUMNS) + " |", "|" + "---|" * len(COLUMNS)]
    for rows in groups:
        arap, slim = _reference_seconds(rows)
        for row in rows:
            cells = [c.replace("|", "/") for c in _cells(row, arap, slim)]
            lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


# --------------------------------------------------------------------------- #
# Meshes
# --------------------------------------------------------------------------- #


def parse_sizes(text: str) -> list[tuple[str, int]]:
    """Parse ``"1k,10k,100k,1M"`` into ``[(label, n_faces), ...]``.

    Raises
    ------
    SystemExit
        On an unknown label.
    """
    out = []
    for label in (s.strip() for s in text.split(",") if s.strip()):
        key = next((k for k in SIZES if k.lower() == label.lower()), None)
        if key is None:
            raise SystemExit(f"unknown size {label!r}; choose from {', '.join(SIZES)}")
        out.append((key, SIZES[key]))
    return out


def cylinder_cells(n_faces: int, radius: float = 200.0, height: float = 300.0,
                   angle: float = 180.0) -> tuple[int, int]:
    """Cells ``(n_around, n_along)`` with ``2 * n_around * n_along ~ n_faces``, near square.

    The arc is ``radius * radians(angle)`` long, the height ``height``; the cell
    counts are chosen in that ratio.
    """
    aspect = radius * np.radians(angle) / height
    n_along = max(1, round(float(np.sqrt(n_faces / (2.0 * aspect)))))
    n_around = max(1, round(n_faces / (2.0 * n_along)))
    return n_around, n_along


SHAPES = ("cap60", "dish", "saddle", "cylinder")
"""Generated surfaces run at every ``--sizes`` size."""

EXTRA_SHAPES = ("hemisphere", "cup", "torus")
"""Generated surfaces run only at the ``--extra-sizes`` sizes (default 10k, 100k)."""


def make_surface(shape: str, n_faces: int) -> tuple[np.ndarray, np.ndarray]:
    """The generated surface ``shape`` with about ``n_faces`` faces, as ``(vertices, faces)``."""
    if shape == "cap60":
        return surfaces.spherical_cap(radius=100.0, half_angle=30.0, n_faces=n_faces)
    if shape == "dish":
        return surfaces.paraboloid_dish(diameter=600.0, sag=54.0, n_faces=n_faces)
    if shape == "saddle":
        return surfaces.saddle(diameter=400.0, height=40.0, n_faces=n_faces)
    if shape == "cylinder":
        a, b = cylinder_cells(n_faces)
        return surfaces.cylinder_patch(radius=200.0, height=300.0, angle=180.0, n_around=a, n_along=b)
    if shape == "hemisphere":
        return surfaces.spherical_cap(radius=100.0, half_angle=90.0, n_faces=n_faces)
    if shape == "cup":
        return surfaces.ellipsoid_cup(n_faces=n_faces)
    if shape == "torus":
        return surfaces.torus_patch(n_faces=n_faces)
    raise ValueError(f"unknown shape {shape!r}")


def generated_meshes(sizes: list[tuple[str, int]], extra_sizes: list[tuple[str, int]]):
    """Yield ``(name, vertices, faces)`` for every generated surface and size.

    :data:`SHAPES` at every size of ``sizes``, :data:`EXTRA_SHAPES` at every size
    of ``extra_sizes``; by increasing size.  Generated lazily so that only one
    1M-face mesh is in memory at a time.
    """
    for n in sorted({n for _, n in sizes} | {n for _, n in extra_sizes}):
        label = next(k for k, v in SIZES.items() if v == n)
        shapes = (SHAPES if any(m == n for _, m in sizes) else ()) + \
                 (EXTRA_SHAPES if any(m == n for _, m in extra_sizes) else ())
        for shape in shapes:
            yield f"{shape} {label}", *make_surface(shape, n)


def corpus_meshes(folder: Path, max_faces: int | None = None):
    """Yield ``(name, vertices, faces)`` for every ``*.obj``, ``*.off`` and ``*.obj.gz`` in ``folder``.

    Loaded with ``trimesh.load(path, process=False)`` (a ``.gz`` through
    :func:`gzip.open`): vertices are neither merged nor reordered.  Meshes with
    more than ``max_faces`` faces are left out (and named on stderr).
    """
    paths = sorted(p for p in folder.iterdir() if p.name.lower().endswith((".obj", ".off", ".obj.gz")))
    for path in paths:
        mesh = load_mesh(path)
        if max_faces is not None and len(mesh.faces) > max_faces:
            print(f"  {path.name}: left out ({len(mesh.faces)} > {max_faces} faces)", file=sys.stderr)
            continue
        vertices = np.ascontiguousarray(mesh.vertices, dtype=np.float64)
        faces = np.ascontiguousarray(mesh.faces, dtype=np.int64)
        yield path.name.removesuffix(".gz"), vertices, faces


def load_mesh(path: Path) -> trimesh.Trimesh:
    """``trimesh.load(path, process=False)``, or of the decompressed OBJ where ``path`` ends in ``.gz``."""
    if path.name.lower().endswith(".gz"):
        with gzip.open(path) as stream:
            return trimesh.load(stream, file_type="obj", process=False)
    return trimesh.load(path, process=False)


def shuffle_mesh(vertices: np.ndarray, faces: np.ndarray, seed: int = SHUFFLE_SEED):
    """The same mesh with its vertices and faces renumbered by a fixed random permutation.

    Returns
    -------
    vertices : (n, 3) float64
        ``vertices[order]``: new vertex ``k`` is old vertex ``order[k]``.
    faces : (m, 3) int64
        The faces in a random order, in the new vertex numbers (each keeps its
        corner order, so its winding).
    order : (n,) int64
        The vertex permutation; a layout ``uv_new`` of the new numbering is
        ``uv[order] = uv_new`` in the old.
    """
    rng = np.random.default_rng(seed)
    order = rng.permutation(len(vertices))
    inverse = np.empty_like(order)
    inverse[order] = np.arange(len(order))
    new_faces = inverse[faces[rng.permutation(len(faces))]]
    return np.ascontiguousarray(vertices[order]), np.ascontiguousarray(new_faces), order


# --------------------------------------------------------------------------- #
# Timing and measuring
# --------------------------------------------------------------------------- #


def best_of(fn, repeats: int):
    """Call ``fn()`` ``repeats`` times; return ``(best seconds, result of the best run)``."""
    best, result = np.inf, None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        dt = time.perf_counter() - t0
        if dt < best:
            best, result = dt, out
    return best, result


def fill(row: Row, d) -> Row:
    """Copy the measures of a :class:`patterns.Distortion` ``d`` into ``row``."""
    row.rms, row.max, row.sd, row.p1 = d.strain_rms, d.strain_max, d.symmetric_dirichlet, d.stretch_p1
    row.folds, row.edge_rms, row.edge_max = d.n_folded, d.edge_strain_rms, d.edge_strain_max
    return row


def measure(row: Row, vertices, faces, uv, loops) -> Row:
    """Fill ``row`` with the distortion, folds and overlap verdict of ``uv``.

    Parameters
    ----------
    row : Row
    vertices : (n, 3) float64
    faces : (m, 3) int64
    uv : (n, 2) float64
    loops : tuple of (k,) int64 or None
        Boundary loops from :func:`patterns.validate_mesh`; without them the
        one-to-one verdict is left empty.
    """
    if not np.all(np.isfinite(uv)):
        row.note = (row.note + "; " if row.note else "") + "non-finite uv"
        return row
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        fill(row, patterns.distortion(vertices, faces, uv, loops=loops))
    if loops is not None:
        row.one_to_one = patterns.overlap_verdict(uv, faces, loops).one_to_one
    return row


# --------------------------------------------------------------------------- #
# patterns
# --------------------------------------------------------------------------- #


def relaxed_note(result) -> str:
    """``start=..., energy=..., N iterations`` of a ``relaxed`` result."""
    note = f"start={result.start}, energy={result.energy}, {result.iterations} iterations"
    return note + ("" if result.converged else ", not converged")


def run_patterns(name: str, vertices, faces, method: str, repeats: int, max_faces_conformal: int,
                 loops=None) -> Row:
    """Time :func:`patterns.flatten_mesh` and measure its result.

    Parameters
    ----------
    name : str
    vertices : (n, 3) float64
    faces : (m, 3) int64
    method : {"relaxed", "relaxed-shuffled", "isometric", "conformal"}
        ``relaxed-shuffled`` runs ``relaxed`` on the mesh renumbered by
        :func:`shuffle_mesh` and maps the layout back.
    repeats : int
        Best of this many runs.
    max_faces_conformal : int
        Above this face count the conformal method is not run.
    loops : tuple of (k,) int64, optional
        The original mesh's boundary loops (``relaxed-shuffled`` only, for its
        overlap verdict in the original numbering).

    Returns
    -------
    Row
        A :class:`patterns.PatternsError` is reported in the note ("diverged"
        for a :class:`patterns.FlattenError`).
    """
    row = Row(name, len(faces), method)
    if method == "conformal" and len(faces) > max_faces_conformal:
        row.note = "skipped (pure-Python reference)"
        return row
    order = None
    v, f = vertices, faces
    if method == "relaxed-shuffled":
        v, f, order = shuffle_mesh(vertices, faces)
    engine = "relaxed" if method == "relaxed-shuffled" else method
    try:
        seconds, result = best_of(lambda: patterns.flatten_mesh(v, f, method=engine, name=name), repeats)
    except patterns.FlattenError as exc:
        row.note = f"diverged: {exc}"
        return row
    except patterns.PatternsError as exc:
        row.note = f"{type(exc).__name__}: {exc}"
        return row
    row.seconds = seconds
    if order is not None:
        uv = np.empty_like(result.uv)
        uv[order] = result.uv
        measure(row, vertices, faces, uv, loops)
    else:
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            fill(row, result.distortion)  # a diverged conformal layout overflows here
        row.folds, row.one_to_one = result.n_folded, result.one_to_one
    if result.method == "relaxed":
        row.note = relaxed_note(result)
    return row


# --------------------------------------------------------------------------- #
# libigl
# --------------------------------------------------------------------------- #


def farthest_boundary_pair(vertices: np.ndarray, boundary: np.ndarray) -> tuple[int, int]:
    """The two boundary vertices farthest apart in 3D (exact, by blocks)."""
    p = vertices[boundary]
    best, pair = -1.0, (0, 1)
    block = 1024
    for start in range(0, len(p), block):
        q = p[start:start + block]
        d2 = (q * q).sum(1)[:, None] + (p * p).sum(1)[None, :] - 2.0 * q @ p.T
        i, j = np.unravel_index(int(np.argmax(d2)), d2.shape)
        if d2[i, j] > best:
            best, pair = float(d2[i, j]), (start + int(i), int(j))
    return int(boundary[pair[0]]), int(boundary[pair[1]])


def igl_lscm(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """libigl LSCM with two boundary vertices pinned.

    The two farthest-apart vertices of ``igl.boundary_loop`` are pinned at
    ``(0, 0)`` and ``(d, 0)``, ``d`` their 3D distance.

    Returns
    -------
    (n, 2) float64
        The uv as libigl returns it (not yet area-normalised).
    """
    boundary = igl.boundary_loop(faces)
    i, j = farthest_boundary_pair(vertices, boundary)
    pins = np.array([i, j], dtype=np.int64)
    pin_uv = np.array([[0.0, 0.0], [np.linalg.norm(vertices[j] - vertices[i]), 0.0]])
    uv, _ = igl.lscm(vertices, faces, pins, pin_uv)
    return uv


def area_normalise(vertices: np.ndarray, faces: np.ndarray, uv: np.ndarray) -> tuple[np.ndarray, float]:
    """Scale ``uv`` by the one factor that makes its total area the 3D area.

    The flat area is the sum of the unsigned triangle areas.

    Returns
    -------
    uv : (n, 2) float64
    factor : float
    """
    area_3d = patterns.distortion(vertices, faces, uv).area_3d
    p = uv[faces]
    a = p[:, 1] - p[:, 0]
    b = p[:, 2] - p[:, 0]
    area_flat = 0.5 * np.abs(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]).sum()
    factor = float(np.sqrt(area_3d / area_flat))
    return uv * factor, factor


def igl_harmonic_init(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Harmonic map to the unit disk (boundary by arc length on the circle), as in libigl's tutorial."""
    boundary = igl.boundary_loop(faces)
    circle = igl.map_vertices_to_circle(vertices, boundary.astype(np.int32))
    return igl.harmonic(vertices, faces, boundary, circle, 1)


def tutte_init(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Tutte's embedding: the boundary on the unit circle by arc length, every other vertex the mean of its
    neighbours (uniform weights, one sparse solve): one-to-one on a disk, where the harmonic map of
    :func:`igl_harmonic_init` (cotangent weights) can fold (the OptCuts armadillo: 11 triangles, the dinosaur 785)."""
    boundary = igl.boundary_loop(faces)
    circle = igl.map_vertices_to_circle(vertices, boundary.astype(np.int32))
    adjacency = igl.adjacency_matrix(faces).astype(np.float64).tocsr()
    laplacian = (sp.diags(np.asarray(adjacency.sum(axis=1)).ravel()) - adjacency).tocsr()
    inner = np.setdiff1d(np.arange(len(vertices)), boundary)
    uv = np.zeros((len(vertices), 2))
    uv[boundary] = circle
    solve = spla.factorized(laplacian[inner][:, inner].tocsc())
    rhs = -(laplacian[inner][:, boundary] @ circle)
    uv[inner] = np.column_stack([solve(np.ascontiguousarray(rhs[:, k])) for k in range(2)])
    return uv


def igl_arap(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """libigl ARAP parametrisation from the harmonic initialisation.

    ``igl.arap_precomputation`` in 2D with the default ``igl.ARAPData``
    (``max_iter`` 10, no dynamics) and one vertex (``faces[0, 0]``) held at its
    initial position, then ``igl.arap_solve`` with the harmonic map as initial
    guess.

    Returns
    -------
    uv : (n, 2) float64
    init : (n, 2) float64
        The harmonic initialisation.
    init_seconds : float
        Time of the harmonic initialisation alone.
    """
    t0 = time.perf_counter()
    init = igl_harmonic_init(vertices, faces)
    init_seconds = time.perf_counter() - t0
    # One vertex held where the initialisation put it.  The ARAP energy does not
    # depend on translation, so this only removes the translation null space;
    # with no fixed vertex at all, arap_precomputation fails on some meshes
    # (the global step's matrix is then singular).
    fixed = np.array([faces[0, 0]], dtype=np.int32)
    data = igl.ARAPData()
    igl.arap_precomputation(vertices, faces, 2, fixed, data)
    uv = igl.arap_solve(init[fixed], data, init)
    return uv, init, init_seconds


def igl_slim(vertices: np.ndarray, faces: np.ndarray, iterations: int) -> tuple[np.ndarray, np.ndarray, float]:
    """libigl SLIM (symmetric Dirichlet, no constraints) from Tutte's embedding (:func:`tutte_init`), as SLIM's
    paper starts it and issue 37 measures it (before issue 37: from the harmonic map, which can fold, and SLIM
    keeps a folded start's folds).

    Returns
    -------
    uv : (n, 2) float64
    init : (n, 2) float64
        The Tutte initialisation.
    init_seconds : float
        Time of the initialisation alone.
    """
    t0 = time.perf_counter()
    init = tutte_init(vertices, faces)
    init_seconds = time.perf_counter() - t0
    data = igl.slim_precompute(
        np.asfortranarray(vertices),
        np.asfortranarray(faces, dtype=np.int32),
        np.asfortranarray(init),
        igl.MappingEnergyType.SYMMETRIC_DIRICHLET,
        np.zeros(0, dtype=np.int32),
        np.zeros((0, 2), order="F"),
        0.0,
    )
    uv = igl.slim_solve(data, iterations)
    return np.ascontiguousarray(uv), init, init_seconds


def _mirror_if_reversed(faces: np.ndarray, uv: np.ndarray, row: Row) -> np.ndarray:
    """Mirror a libigl uv whose total signed area is negative (a reflected layout), and say so."""
    p = uv[faces]
    a = p[:, 1] - p[:, 0]
    b = p[:, 2] - p[:, 0]
    if np.sum(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]) < 0:
        row.note = (row.note + "; " if row.note else "") + "mirrored (libigl output was reflected)"
        return uv * np.array([-1.0, 1.0])
    return uv


def _init_note(faces: np.ndarray, init: np.ndarray, init_seconds: float, label: str = "harmonic") -> str:
    """Note on the initialisation: its time and, if any, its folded triangles."""
    folded = len(folded_faces(init, faces))
    return f"{label} init {init_seconds:.3f} s" + (f" ({folded} folded)" if folded else "")


def run_libigl(name: str, vertices, faces, method: str, repeats: int, loops, max_faces_slim: int) -> Row:
    """Time one libigl method and measure its (for LSCM: area-normalised) result.

    Parameters
    ----------
    name : str
    vertices : (n, 3) float64
    faces : (m, 3) int64
    method : {"lscm", "arap", "slim"}
    repeats : int
    loops : tuple of (k,) int64 or None
        Boundary loops for the overlap verdict.
    max_faces_slim : int
        Above this face count SLIM is not run.

    Returns
    -------
    Row
    """
    row = Row(name, len(faces), method)
    if method == "slim" and len(faces) > max_faces_slim:
        row.note = f"skipped (> {max_faces_slim} faces)"
        return row
    try:
        if method == "lscm":
            seconds, uv = best_of(lambda: igl_lscm(vertices, faces), repeats)
        elif method == "arap":
            seconds, (uv, init, init_seconds) = best_of(lambda: igl_arap(vertices, faces), repeats)
            row.note = _init_note(faces, init, init_seconds)
        elif method == "slim":
            seconds, (uv, init, init_seconds) = best_of(
                lambda: igl_slim(vertices, faces, SLIM_ITERATIONS), repeats)
            row.note = _init_note(faces, init, init_seconds, "Tutte") + f"; {SLIM_ITERATIONS} iterations"
        else:
            raise ValueError(method)
    except (RuntimeError, ValueError, TypeError, MemoryError) as exc:  # reported in the row
        row.note = f"failed: {type(exc).__name__}: {exc}"
        return row
    row.seconds = seconds
    uv = np.asarray(uv, dtype=np.float64)
    if np.all(np.isfinite(uv)):
        uv = _mirror_if_reversed(faces, uv, row)
        if method == "lscm":
            uv, factor = area_normalise(vertices, faces, uv)
            row.note = (row.note + "; " if row.note else "") + f"uv x {factor:.4g} (area-normalised)"
    return measure(row, vertices, faces, uv, loops)


# --------------------------------------------------------------------------- #
# Peak memory (child process)
# --------------------------------------------------------------------------- #

RSS_CHILD = """\
import json, os, resource, sys, time
import numpy as np
import patterns
from patterns.launch import one_run_allocator
if os.environ.get("BENCH_ALLOCATOR") == "command":
    one_run_allocator()

def high_water_kib():
    # VmHWM belongs to the memory map made by exec, so unlike ru_maxrss (which on
    # Linux keeps the parent's high-water mark across fork + exec) it is this
    # process's own peak.
    try:
        with open("/proc/self/status") as status:
            for line in status:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]), "VmHWM"
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss, "ru_maxrss"

vertices = np.load(sys.argv[1])
faces = np.load(sys.argv[2])
before, source = high_water_kib()
t0 = time.perf_counter()
result = patterns.flatten_mesh(vertices, faces)
seconds = time.perf_counter() - t0
peak, source = high_water_kib()
print(json.dumps({"seconds": seconds, "before_kib": before, "peak_kib": peak, "source": source,
                  "one_to_one": bool(result.one_to_one)}))
"""
"""Child process for the memory measurement: load the mesh, flatten with defaults, report its peak RSS."""


@dataclass
class Memory:
    """Peak resident memory of one ``flatten_mesh(V, F)`` (default method) in a child process.

    Attributes
    ----------
    peak_bytes : float or None
        Peak resident set size of the child at the end (interpreter, imports,
        input arrays and the flattening): ``VmHWM`` of ``/proc/self/status``;
        None when the child failed.
    before_bytes : float or None
        The same after the imports and loading the arrays, before ``flatten_mesh``.
    seconds : float or None
        The child's (single, cold) ``flatten_mesh`` time.
    note : str
    """

    peak_bytes: float | None = None
    before_bytes: float | None = None
    seconds: float | None = None
    note: str = ""


def measure_memory(vertices: np.ndarray, faces: np.ndarray) -> Memory:
    """Run ``patterns.flatten_mesh(vertices, faces)`` in a child process and read its peak RSS.

    The arrays go to the child as ``.npy`` files in a temporary folder; the child
    imports only numpy and ``patterns`` (not libigl).  The peak is the child's
    ``VmHWM`` (KiB), not ``ru_maxrss``: on Linux a child's ``ru_maxrss``, and the
    parent's ``RUSAGE_CHILDREN`` one, start from the parent's high-water mark at
    the fork, which here is the benchmark process holding the 1M-face mesh and
    every earlier result.  Without ``/proc`` the child falls back to ``ru_maxrss``
    and the note says so.
    """
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        v_path, f_path = Path(tmp) / "v.npy", Path(tmp) / "f.npy"
        np.save(v_path, vertices)
        np.save(f_path, faces)
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(
            x for x in (str(REPO), os.environ.get("PYTHONPATH", "")) if x))
        proc = subprocess.run([sys.executable, "-c", RSS_CHILD, str(v_path), str(f_path)],
                              check=False, capture_output=True, text=True, env=env, cwd=tmp)
    if proc.returncode != 0:
        tail = (proc.stderr.strip().splitlines() or ["?"])[-1]
        return Memory(note=f"child failed (exit {proc.returncode}): {tail}")
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    notes = [] if out["one_to_one"] else ["child result not one-to-one"]
    if out["source"] != "VmHWM":
        notes.append(f"peak from {out['source']} (includes the parent's high-water mark)")
    return Memory(peak_bytes=out["peak_kib"] * 1024.0, before_bytes=out["before_kib"] * 1024.0,
                  seconds=out["seconds"], note="; ".join(notes))


# --------------------------------------------------------------------------- #
# Acceptance summary
# --------------------------------------------------------------------------- #

ACCEPT_COLUMNS = ("mesh", "faces", "ARAP folds", "relaxed RMS %", "(0) 0 folds, 1:1", "(a) RMS / ARAP <= 1",
                  "(b) ARAP folds: against SLIM", "(c) 100k: time / ARAP <= 1", "(d) 1M: <= 10 s, < 4 GB",
                  "(e) shuffled: time ratio <= 1.5, RMS change <= 0.5 %", "(f) developable: edge max < 1e-9")
"""Header of the acceptance table (markdown)."""

CRITERIA = {
    "(0)": "every mesh: 0 folds and one-to-one",
    "(a)": (f"ARAP does not fold: strain RMS <= {ACCEPT_ARAP_RATIO} x ARAP's (a FAIL by less than "
            f"{ACCEPT_ARAP_TIE:g}, relative, is marked (tie))"),
    "(b)": (f"ARAP folds: 0 folds, one-to-one, RMS < SLIM's, stretch_p1 >= {ACCEPT_P1}, "
            f"sym. Dirichlet <= {ACCEPT_SD_RATIO} x SLIM's, time <= {ACCEPT_SLIM_TIME} x SLIM's"),
    "(c)": f"{ACCEPT_100K[0]}-{ACCEPT_100K[1]} faces: time <= ARAP's",
    "(d)": f">= {ACCEPT_1M} faces: time <= {ACCEPT_1M_SECONDS:g} s and child peak RSS < {ACCEPT_1M_BYTES / 1e9:g} GB",
    "(e)": (f"every mesh: relaxed-shuffled time <= {ACCEPT_SHUFFLED_TIME} x relaxed's, strain RMS within "
            f"{100 * ACCEPT_SHUFFLED_RMS:g} % of relaxed's (or {ACCEPT_SHUFFLED_FLOOR:g} absolute)"),
    "(f)": f"exactly developable ({', '.join(DEVELOPABLE)}): edge strain max < {ACCEPT_DEVELOPABLE:g}",
}
"""The criteria, as printed in the legend."""


def _ratio(a: float | None, b: float | None) -> float | None:
    if a is None or b is None or not np.isfinite(a) or not np.isfinite(b) or b == 0:
        return None
    return a / b


def _verdict(ok: bool | None) -> str:
    return {True: "PASS", False: "FAIL", None: "n/a"}[ok]


def _near_one(r: float | None) -> str:
    """A ratio; within 1e-4 of 1 as ``1+2.4e-10`` so that a tie is seen as one."""
    if r is None:
        return "?"
    return f"1{r - 1.0:+.1e}" if abs(r - 1.0) < 1e-4 else f"{r:.5f}"


def _part(label: str, value, ok: bool | None, fmt: str = ".3g") -> str:
    """``label value`` of one part of a compound criterion; a failing part is marked ``*``."""
    text = value if isinstance(value, str) else ("?" if value is None else format(value, fmt))
    return f"{label} {text}" + ("*" if ok is False else "")


def _all(parts: list[bool | None]) -> bool | None:
    """False if any part fails, None if none fails but one is not measurable, else True."""
    if any(p is False for p in parts):
        return False
    return None if any(p is None for p in parts) else True


def judge_folding(rel: Row, arap: Row | None, slim: Row | None, verdicts: dict) -> tuple[str, str, str]:
    """Cells and verdicts of (0), (a) and (b) for one mesh."""
    fold_free = None if rel.folds is None else rel.folds == 0 and rel.one_to_one is True
    verdicts["(0)"] = fold_free
    zero = f"{_verdict(fold_free)} ({rel.folds} folds, {'1:1' if rel.one_to_one else 'not 1:1'})"
    a_cell, b_cell = "-", "-"
    if arap is None or arap.folds is None:
        a_cell = "n/a (no ARAP result)"
        verdicts["(a)"] = None
    elif arap.folds == 0:
        r = _ratio(rel.rms, arap.rms)
        ok = None if r is None else r <= ACCEPT_ARAP_RATIO
        verdicts["(a)"] = ok
        a_cell = f"{_verdict(ok)} {_near_one(r)}"
        if ok is False and r - 1.0 <= ACCEPT_ARAP_TIE:
            a_cell += " (tie)"
            verdicts["(a) tie"] = True
    else:
        sd_ratio = _ratio(rel.sd, slim.sd) if slim else None
        t_ratio = _ratio(rel.seconds, slim.seconds) if slim else None
        rms_ratio = _ratio(rel.rms, slim.rms) if slim else None
        checks = {
            "(b) 0 folds, 1:1": fold_free,
            "(b) RMS < SLIM": None if rms_ratio is None else rms_ratio < 1.0,
            f"(b) p1 >= {ACCEPT_P1}": None if rel.p1 is None else rel.p1 >= ACCEPT_P1,
            f"(b) SD <= {ACCEPT_SD_RATIO} x SLIM": None if sd_ratio is None else sd_ratio <= ACCEPT_SD_RATIO,
            f"(b) time <= {ACCEPT_SLIM_TIME} x SLIM": None if t_ratio is None else t_ratio <= ACCEPT_SLIM_TIME,
        }
        ok = _all(list(checks.values()))
        verdicts["(b)"] = ok
        verdicts.update(checks)
        values = list(checks.values())
        b_cell = ", ".join([
            f"{_verdict(ok)}:" + (" no SLIM result;" if slim is None or slim.rms is None else ""),
            _part("folds", str(rel.folds), values[0]),
            _part("RMS/SLIM", rms_ratio, values[1]),
            _part("p1", rel.p1, values[2]),
            _part("SD/SLIM", sd_ratio, values[3]),
            _part("t/SLIM", t_ratio, values[4], ".2f"),
        ]).replace(":,", ":")
    return zero, a_cell, b_cell


def judge_speed(rel: Row, arap: Row | None, memory, verdicts: dict) -> tuple[str, str]:
    """Cells and verdicts of (c) and (d) for one mesh (``-`` where the size does not apply)."""
    c_cell = d_cell = "-"
    if ACCEPT_100K[0] <= rel.faces <= ACCEPT_100K[1]:
        r = _ratio(rel.seconds, arap.seconds if arap else None)
        ok = None if r is None else r <= 1.0
        verdicts["(c)"] = ok
        c_cell = f"{_verdict(ok)} {_number(r, '.2f')}"
    if rel.faces >= ACCEPT_1M:
        t_ok = None if rel.seconds is None else rel.seconds <= ACCEPT_1M_SECONDS
        peak = memory.peak_bytes if memory else None
        m_ok = None if peak is None else peak < ACCEPT_1M_BYTES
        verdicts["(d) time"], verdicts["(d) memory"] = t_ok, m_ok
        verdicts["(d)"] = _all([t_ok, m_ok])
        d_cell = (f"{_verdict(verdicts['(d)'])}: " + _part("s", rel.seconds, t_ok, ".2f") + ", "
                  + _part("GB", None if peak is None else peak / 1e9, m_ok, ".2f"))
    return c_cell, d_cell


def judge_numbering(rel: Row, shuffled: Row | None, verdicts: dict) -> tuple[str, str]:
    """Cells and verdicts of (e) and (f) for one mesh."""
    e_cell = f_cell = "-"
    if shuffled is not None:
        t = _ratio(shuffled.seconds, rel.seconds)
        r = _ratio(shuffled.rms, rel.rms)
        change = None if r is None else abs(r - 1.0)
        t_ok = None if t is None else t <= ACCEPT_SHUFFLED_TIME
        r_ok = None if change is None else (change <= ACCEPT_SHUFFLED_RMS
                                            or abs(shuffled.rms - rel.rms) <= ACCEPT_SHUFFLED_FLOOR)
        verdicts["(e)"] = _all([t_ok, r_ok])
        verdicts["(e) time"], verdicts["(e) strain"] = t_ok, r_ok
        if change is not None and change > ACCEPT_SHUFFLED_RMS and r_ok:
            strain = f"RMS differs by {abs(shuffled.rms - rel.rms):.1e} (round-off)"
        else:
            strain = _part("RMS change %", None if change is None else 100 * change, r_ok, ".2g")
        e_cell = f"{_verdict(verdicts['(e)'])}: " + _part("time x", t, t_ok, ".2f") + ", " + strain
    if rel.mesh.split()[0] in DEVELOPABLE:
        ok = None if rel.edge_max is None else rel.edge_max < ACCEPT_DEVELOPABLE
        verdicts["(f)"] = ok
        f_cell = f"{_verdict(ok)} {_number(rel.edge_max, '.2g')}"
    return e_cell, f_cell


def acceptance(rows: list[Row], memory) -> tuple[list[str], dict[str, bool | None]] | None:
    """The acceptance cells of one mesh, and the verdict of each criterion judged on it.

    Parameters
    ----------
    rows : list of Row
        The mesh's rows; None is returned without a ``relaxed`` row.
    memory : Memory or None
        The child-process measurement (meshes with at least ``ACCEPT_1M`` faces).

    Returns
    -------
    cells : list of str
        One per :data:`ACCEPT_COLUMNS`; ``-`` where a criterion does not apply.
    verdicts : dict
        Criterion (and sub-criterion) to True (PASS), False (FAIL) or None (not
        measurable); criteria that do not apply to this mesh are absent.
    """
    by = {r.method: r for r in rows}
    rel = by.get("relaxed")
    if rel is None:
        return None
    arap, slim = by.get("arap"), by.get("slim")
    if slim is not None and slim.rms is None:
        slim = None
    verdicts: dict[str, bool | None] = {}
    if rel.rms is None:
        verdicts["(0)"] = False
        return [rel.mesh, str(rel.faces), "", "", f"FAIL ({rel.note})"] + ["-"] * 6, verdicts
    zero, a_cell, b_cell = judge_folding(rel, arap, slim, verdicts)
    c_cell, d_cell = judge_speed(rel, arap, memory, verdicts)
    e_cell, f_cell = judge_numbering(rel, by.get("relaxed-shuffled"), verdicts)
    arap_folds = "" if arap is None or arap.folds is None else str(arap.folds)
    return ([rel.mesh, str(rel.faces), arap_folds, _percent(rel.rms), zero, a_cell, b_cell, c_cell, d_cell,
             e_cell, f_cell], verdicts)


def acceptance_tables(groups: list[list[Row]], memories: dict):
    """Acceptance cells of every mesh with a ``relaxed`` row, and PASS/FAIL counts per criterion.

    Returns
    -------
    lines : list of list of str
    counts : dict
        Criterion to ``[n_pass, n_fail, n_not_measurable]``, main criteria in
        the order of :data:`CRITERIA`, then the parts.
    """
    keys = list(CRITERIA)
    keys.insert(keys.index("(a)") + 1, "(a) tie")  # printed only when there is one
    lines, counts = [], {key: [0, 0, 0] for key in keys}
    for rows in groups:
        out = acceptance(rows, memories.get(rows[0].mesh) if rows else None)
        if out is None:
            continue
        cells, verdicts = out
        lines.append(cells)
        for key, ok in verdicts.items():
            c = counts.setdefault(key, [0, 0, 0])
            c[0 if ok is True else 1 if ok is False else 2] += 1
    return lines, counts


def _plain_acceptance(cells: list[str]) -> str:
    """One mesh's acceptance as one plain-text line (criteria that apply only)."""
    head = f"{cells[0]:<18} {cells[1]:>7}  ARAP folds {cells[2] or '?':<5} RMS {cells[3]:<6}"
    parts = [f"{col.split(')')[0]}) {cell}" for col, cell in zip(ACCEPT_COLUMNS[4:], cells[4:], strict=True)
             if cell != "-"]
    return head + "  " + "  ".join(parts)


def _memory_lines(memories: dict, bullet: str) -> list[str]:
    """One line per child-process memory measurement."""
    out = []
    for name, mem in memories.items():
        if mem.peak_bytes is None:
            out.append(f"{bullet}memory {name}: {mem.note}")
        else:
            out.append(f"{bullet}memory {name}: child peak RSS {mem.peak_bytes / 1e9:.2f} GB "
                       f"({mem.before_bytes / 1e9:.2f} GB after imports and loading the mesh); "
                       f"child flatten_mesh {mem.seconds:.2f} s (one cold run)"
                       + (f"; {mem.note}" if mem.note else ""))
    return out


def acceptance_text(groups: list[list[Row]], memories: dict, markdown: bool) -> str:
    """The acceptance block: legend, table (markdown or plain), counts and memory notes."""
    lines, counts = acceptance_tables(groups, memories)
    if not lines:
        return "acceptance: no relaxed rows"
    bullet = "* " if markdown else "  "
    out = ["relaxed against libigl ARAP and SLIM, per mesh (PASS/FAIL with the numbers; '-': does not apply;",
           "a failing part of a compound criterion is marked *; ratios are relaxed's value / theirs):"]
    out += [f"{bullet}{key} {text}" for key, text in CRITERIA.items()]
    out.append("")
    if markdown:
        out.append("| " + " | ".join(ACCEPT_COLUMNS) + " |")
        out.append("|" + "---|" * len(ACCEPT_COLUMNS))
        out += ["| " + " | ".join(c.replace("|", "/") for c in cells) + " |" for cells in lines]
    else:
        out += [_plain_acceptance(cells) for cells in lines]
    out += ["", "PASS/FAIL per criterion:" if not markdown else "PASS/FAIL per criterion:\n"]
    for key, (n_pass, n_fail, n_na) in counts.items():
        if key == "(a) tie":
            if n_pass:
                out.append(f"{bullet}(a): of the FAILs, {n_pass} {'is a tie' if n_pass == 1 else 'are ties'} "
                           f"(relaxed above ARAP by less than "
                           f"{ACCEPT_ARAP_TIE:g}, relative)")
            continue
        n = n_pass + n_fail + n_na
        text = (f"PASS on {n_pass}, FAIL on {n_fail}" + (f", not measurable on {n_na}" if n_na else "")
                + f" of {n} meshes") if n else "no mesh of this kind in this run"
        out.append(f"{bullet}{key}: {text}")
    out += _memory_lines(memories, bullet)
    return "\n".join(out)


# --------------------------------------------------------------------------- #
# Driver
# --------------------------------------------------------------------------- #


def bench_mesh(name: str, vertices, faces, methods, args, on_row) -> list[Row]:
    """Run every selected method on one mesh; return its rows in print order.

    libigl runs first so that every row can be given as a ratio of ARAP's and
    SLIM's time; ``on_row(row, arap_seconds, slim_seconds)`` is called for each
    row once the mesh is done.
    """
    n_faces = len(faces)
    repeats = 3 if n_faces <= REPEAT_LIMIT else 1
    try:
        loops = patterns.validate_mesh(vertices, faces, name=name)[2].loops
        loops_note = ""
    except patterns.PatternsError as exc:
        loops = None
        loops_note = f"validate_mesh: {type(exc).__name__}: {exc}"
    rows = {}
    order = ["lscm", "arap", "slim"] + [m for m in ALL_METHODS if m not in ("lscm", "arap", "slim")]
    for method in order:
        if method not in methods:
            continue
        print(f"  {name}: {method} ...", file=sys.stderr, flush=True)
        if method in ("lscm", "arap", "slim"):
            rows[method] = run_libigl(name, vertices, faces, method, repeats, loops, args.max_faces_slim)
            if loops is None and not rows[method].note.startswith("skipped"):
                rows[method].note = "; ".join(x for x in (rows[method].note, loops_note) if x)
        else:
            rows[method] = run_patterns(name, vertices, faces, method, repeats, args.max_faces_conformal, loops)
    out = [rows[m] for m in ALL_METHODS if m in rows]
    arap, slim = _reference_seconds(out)
    for row in out:
        on_row(row, arap, slim)
    return out


def _load() -> str:
    try:
        return " ".join(f"{x:.2f}" for x in os.getloadavg())
    except OSError:
        return "n/a"


def machine_summary() -> str:
    """One line on the machine: cores, Python and library versions, current load."""
    versions = []
    for dist in ("numpy", "scipy", "libigl", "trimesh", "shapely"):
        try:
            versions.append(f"{dist} {metadata.version(dist)}")
        except metadata.PackageNotFoundError:
            versions.append(f"{dist} ?")
    return (f"machine: {os.cpu_count()} cores ({platform.machine()}), Python {platform.python_version()}, "
            f"patterns {patterns.__version__} ({_git_state()}), {', '.join(versions)}; "
            f"load average at the start: {_load()}")


def _git_state() -> str:
    """The repository's commit, and whether ``patterns/`` differs from it."""
    try:
        head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=REPO, capture_output=True,
                              text=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--", "patterns"], cwd=REPO,
                               capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "commit unknown"
    return f"commit {head}" + (", patterns/ modified" if dirty else "")


def warm_up(methods) -> None:
    """Run every selected method once on a small disk, untimed (imports, first-call set-up)."""
    vertices, faces = surfaces.spherical_cap(radius=100.0, half_angle=30.0, n_faces=600)
    loops = patterns.validate_mesh(vertices, faces)[2].loops
    for method in methods:
        if method in ("lscm", "arap", "slim"):
            run_libigl("warm-up", vertices, faces, method, 1, loops, len(faces))
        else:
            run_patterns("warm-up", vertices, faces, method, 1, len(faces), loops)


HEADER = """\
Principal strains: the singular values s1 >= s2 of each triangle's 3D -> flat map; strain RMS = area-weighted
  RMS of |s1 - 1| and |s2 - 1| (the judge); strain max = the largest of them; sym. Dirichlet = area-weighted mean
  of s1^2 + s2^2 + 1/s1^2 + 1/s2^2 (4 = isometry, inf if folded); stretch p1 = 1st percentile by area of s2
  (< 0.1: crushed triangles).  Edge-strain RMS = RMS of |flat edge / 3D edge - 1| over the edges: it counts edges,
  so it depends on the triangulation -- a column only, not judged.
Times: best of 3 runs up to {limit} faces, 1 run above; '/ ARAP', '/ SLIM' = seconds / their seconds on the mesh.
relaxed, isometric: patterns.flatten_mesh, default options (validation + grower [+ relaxation] + overlap
  verdict), uv never rescaled; relaxed note: start layout, energy that ran, iterations.
relaxed-shuffled: relaxed on the mesh with vertices and faces renumbered by a fixed random permutation
  (seed {seed}), layout mapped back and measured on the original mesh.
lscm: igl.lscm, two farthest boundary vertices pinned; its uv is RESCALED by one factor so that
  total flat area = total 3D area before it is measured (LSCM has no scale of its own).
arap: igl harmonic init (boundary on a circle) + arap_precomputation/arap_solve, 2D, default 10 iterations,
  one vertex held (translation only); time includes the harmonic init.
slim: igl.slim_solve, symmetric Dirichlet, {slim} iterations, from Tutte's embedding (uniform weights), included in the time.
All rows measured by patterns.distortion and patterns.overlap_verdict (outside the timed region).
Allocator: {allocator}."""


def parse_args(argv=None) -> argparse.Namespace:
    """The command line; ``--quick`` fills in the sizes not given explicitly."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true",
                        help="a short run: --sizes 1k --extra-sizes 10k --max-corpus-faces 10000 "
                             "(unless given), about a minute")
    parser.add_argument("--sizes", default=None,
                        help=f"sizes of the generated {', '.join(SHAPES)}, comma-separated from "
                             "1k,10k,100k,1M (default all; '' for none)")
    parser.add_argument("--extra-sizes", default=None,
                        help=f"sizes of the generated {', '.join(EXTRA_SHAPES)} (default 10k,100k; '' for none)")
    parser.add_argument("--no-memory", action="store_true",
                        help=f"skip the child-process peak-memory run of relaxed on meshes with >= {ACCEPT_1M} faces")
    parser.add_argument("--no-corpus", action="store_true", help="skip the shared corpus meshes")
    parser.add_argument("--folder", action="append", type=Path, default=[],
                        help="flatten the *.obj, *.off, *.obj.gz of this folder instead of the corpus and the "
                             "thin limbs (repeatable; e.g. OptCuts' input/benchmark disks)")
    parser.add_argument("--max-corpus-faces", type=int, default=None,
                        help="leave out corpus meshes with more faces than this (default none left out)")
    parser.add_argument("--methods", default=",".join(DEFAULT_METHODS),
                        help=f"comma-separated subset of {','.join(ALL_METHODS)} "
                             f"(default {','.join(DEFAULT_METHODS)})")
    parser.add_argument("--allocator", choices=("command", "default"), default="command",
                        help="command (default): this whole process, every method's runs and the memory child, "
                             "with the C allocator set as the patterns command sets it for itself "
                             "(patterns.launch.one_run_allocator); default: as Python leaves it")
    parser.add_argument("--markdown", action="store_true",
                        help="print the tables as markdown (for docs/benchmarks.md) at the end")
    parser.add_argument("--max-faces-conformal", type=int, default=200_000,
                        help="skip the conformal method (when asked for) above this many faces (default 200000)")
    parser.add_argument("--max-faces-slim", type=int, default=120_000,
                        help="skip libigl SLIM above this many faces (default 120000)")
    args = parser.parse_args(argv)
    quick = {"sizes": "1k", "extra_sizes": "10k", "max_corpus_faces": 10_000}
    full = {"sizes": "1k,10k,100k,1M", "extra_sizes": "10k,100k", "max_corpus_faces": None}
    for key in quick:
        if getattr(args, key) is None:
            setattr(args, key, (quick if args.quick else full)[key])
    args.methods = [m.strip() for m in args.methods.split(",") if m.strip()]
    unknown = [m for m in args.methods if m not in ALL_METHODS]
    if unknown:
        parser.error(f"unknown methods {unknown}; choose from {', '.join(ALL_METHODS)}")
    return args


def mesh_sections(args) -> list:
    """``(title, iterator of (name, vertices, faces))`` of the corpus and the generated surfaces."""
    sections = []
    for folder in args.folder:
        if not folder.is_dir():
            raise SystemExit(f"bench_flatten.py: --folder {folder}: not a folder")
        sections.append((f"{folder.name} ({folder})", corpus_meshes(folder, args.max_corpus_faces)))
    if args.folder:
        pass
    elif args.no_corpus:
        print("corpus: skipped (--no-corpus)")
    elif not CORPUS.is_dir():
        print(f"corpus: skipped ({CORPUS} does not exist)")
    else:
        sections.append(("Corpus (../shared/corpus/)", corpus_meshes(CORPUS, args.max_corpus_faces)))
    if args.no_corpus or args.folder:
        pass
    elif not LIMBS.is_dir():
        print(f"thin limbs: skipped ({LIMBS} does not exist)")
    else:
        sections.append(("Thin limbs (benchmarks/data/limbs/)", corpus_meshes(LIMBS, args.max_corpus_faces)))
    sizes, extra_sizes = parse_sizes(args.sizes), parse_sizes(args.extra_sizes)
    if sizes or extra_sizes:
        sections.append(("Generated surfaces", generated_meshes(sizes, extra_sizes)))
    return sections


def main(argv=None) -> int:
    """Command-line entry point; see ``--help``."""
    args = parse_args(argv)
    methods = args.methods
    os.environ["BENCH_ALLOCATOR"] = args.allocator  # the memory child's too
    if args.allocator == "command":
        took = one_run_allocator()
        allocator = ("as the patterns command sets it (patterns.launch.one_run_allocator: freed blocks up to 32 MB "
                     "kept for the next, the heap never trimmed), for every method alike" if took else
                     "Python's default (this C library takes no mallopt settings)")
    else:
        allocator = "Python's default (--allocator default)"
    print(HEADER.format(limit=REPEAT_LIMIT, slim=SLIM_ITERATIONS, seed=SHUFFLE_SEED, allocator=allocator))
    print(machine_summary())
    print()

    def on_row(row, arap, slim):
        # With --markdown the tables come at the end; the rows go to stderr as progress.
        print(plain_line(_cells(row, arap, slim)), file=sys.stderr if args.markdown else sys.stdout, flush=True)

    sections = mesh_sections(args)
    warm_up(methods)
    tables = []
    memories: dict[str, Memory] = {}
    for title, meshes in sections:
        if not args.markdown:
            print(f"\n== {title} ==")
            print(plain_line(PLAIN_COLUMNS))
        groups = []
        for name, vertices, faces in meshes:
            groups.append(bench_mesh(name, vertices, faces, methods, args, on_row))
            if "relaxed" in methods and len(faces) >= ACCEPT_1M and not args.no_memory:
                print(f"  {name}: relaxed peak memory (child process) ...", file=sys.stderr, flush=True)
                memories[name] = measure_memory(vertices, faces)
        tables.append((title, groups))

    all_groups = [g for _, groups in tables for g in groups]
    if args.markdown:
        for title, groups in tables:
            print(f"\n### {title}\n")
            print(markdown_table(groups))
        print("\n### Acceptance: relaxed against libigl ARAP and SLIM\n")
    else:
        print("\n== Acceptance: relaxed against libigl ARAP and SLIM ==")
    print(acceptance_text(all_groups, memories, args.markdown))
    print(f"\nload average at the end: {_load()}; patterns at the end: {_git_state()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
