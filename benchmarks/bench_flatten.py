"""Time and quality of `patterns` flattening against libigl's LSCM, ARAP and SLIM.

Run from the repository root::

    python benchmarks/bench_flatten.py                 # everything
    python benchmarks/bench_flatten.py --sizes 1k,10k --no-corpus
    python benchmarks/bench_flatten.py --markdown > tables.md

Meshes
------
* every ``*.obj`` / ``*.off`` in ``../shared/corpus/`` relative to the repository
  root, loaded with ``trimesh.load(path, process=False)`` (skipped, with the
  reason printed, when the folder is absent or ``--no-corpus`` is given);
* generated surfaces at about 1k, 10k, 100k and 1M faces (``--sizes``): a 60
  degree spherical cap (``cap60``), a paraboloid dish, a saddle and a half
  cylinder; and at about 10k and 100k faces only (``--extra-sizes``): a
  hemisphere, an ellipsoid cup and a torus patch.

Methods
-------
* ``relaxed``, ``isometric``, ``conformal``: :func:`patterns.flatten_mesh` with default
  options; the time covers the whole call (input validation, the grower, for
  ``relaxed`` the relaxation, and the overlap verdict).  The note of a ``relaxed``
  row gives its start layout and iteration count.
* ``relaxed-tight``: ``relaxed`` with ``max_iterations=5000, tolerance=1e-9`` (timed
  once, up to ``--max-faces-tight`` faces): the least edge strain the method reaches
  when time does not matter.  Not judged; it shows where a criterion is out of reach.
* ``arap+relaxed``: the same tight relaxation started from libigl ARAP's layout
  (where that is one-to-one, up to ``--max-faces-tight`` faces; the time is the
  relaxation's alone).  Not judged; it shows whether the least-squares optimum
  depends on the start.
* ``lscm``: ``igl.lscm`` with the two farthest-apart boundary vertices pinned at
  their 3D distance apart.  LSCM has no scale of its own, so before measuring its
  uv is multiplied by the single factor that makes the total flat area equal to
  the total 3D area.  Nothing else is ever rescaled.
* ``arap``: as in libigl's tutorial: boundary to a circle
  (``igl.map_vertices_to_circle``), harmonic initialisation (``igl.harmonic``),
  then ``igl.arap_precomputation`` (2D) and ``igl.arap_solve`` with the default
  ``igl.ARAPData`` (10 iterations).  One vertex is held at its initial position:
  that only fixes the translation, which the ARAP energy does not see (with no
  fixed vertex ``arap_precomputation`` fails on some meshes).  The time includes the
  harmonic initialisation, which is also given on its own in the note column.
* ``slim``: ``igl.slim_precompute`` / ``igl.slim_solve`` with the symmetric
  Dirichlet energy from the same harmonic initialisation, no constraints, a fixed
  number of iterations; only up to ``--max-faces-slim`` faces.

Every row is measured by the same code, :func:`patterns.distortion` (edge strain
RMS and max, folded triangles) and :func:`patterns.overlap_verdict` (one-to-one),
outside the timed region.  Times are the best of 3 runs up to
``REPEAT_LIMIT`` faces and of 1 run above, all methods in the same process.

Acceptance summary
------------------
After the tables the script prints, for every mesh, ``relaxed`` against libigl
ARAP and SLIM with a PASS/FAIL per criterion of the issue:

* edge-strain RMS <= 0.95 x ARAP's where ARAP has no folded triangle; where ARAP
  folds, RMS lower than SLIM's;
* at about 100k faces (``ACCEPT_100K``): time <= ARAP's, and SLIM's time >= 3 x ours;
* at about 1M faces (``ACCEPT_1M``): time (the table's row) under 30 s and peak
  memory under 4 GB.  The memory is the peak resident set size (``VmHWM``) of a
  separate child process that imports ``patterns``, loads the mesh from ``.npy``
  files and runs ``flatten_mesh(V, F)`` once (so it includes the interpreter, the
  imports and the input arrays).
"""

from __future__ import annotations

import argparse
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

REPO = Path(__file__).resolve().parent.parent
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

import igl
import trimesh

import patterns
from patterns import surfaces
from patterns.measure import folded_faces

CORPUS = REPO.parent / "shared" / "corpus"
"""The shared corpus of real disk-topology meshes."""

SIZES = {"1k": 1_000, "10k": 10_000, "100k": 100_000, "1M": 1_000_000}
"""Face counts of the generated surfaces, by the label used on the command line."""

ALL_METHODS = ("relaxed", "relaxed-tight", "arap+relaxed", "isometric", "conformal", "lscm", "arap", "slim")
"""Every method the benchmark knows, in the order the rows are printed."""

TIGHT = {"max_iterations": 5000, "tolerance": 1e-9}
"""Options of the ``relaxed-tight`` rows: ``relaxed`` run (nearly) to its optimum, to show
how low the least-squares edge strain can go on a mesh, whatever the time."""

REPEAT_LIMIT = 200_000
"""Meshes with at most this many faces are timed best of 3, larger ones once."""

SLIM_ITERATIONS = 20
"""Iterations of ``igl.slim_solve``."""

ACCEPT_STRAIN_RATIO = 0.95
"""Acceptance: ``relaxed`` RMS strain at most this times ARAP's (where ARAP does not fold)."""

ACCEPT_100K = (80_000, 200_000)
"""Acceptance: meshes with a face count in this range are judged on the 100k time criteria."""

ACCEPT_SLIM_SPEEDUP = 3.0
"""Acceptance at 100k: SLIM's time at least this many times ``relaxed``'s."""

ACCEPT_1M = 500_000
"""Acceptance: meshes with at least this many faces are judged on the 1M time and memory criteria."""

ACCEPT_1M_SECONDS = 30.0
ACCEPT_1M_BYTES = 4e9
"""Acceptance at 1M: time under 30 s, peak resident memory under 4 GB (4e9 bytes)."""


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
        Edge strain ``|l_flat / l_3d - 1|``: RMS and maximum over all edges.
    folds : int or None
        Triangles with flat signed area <= 0.
    one_to_one : bool or None
        The overlap verdict; None when it could not be computed.
    note : str
        Errors, skips, rescale factors, sub-timings.
    """

    mesh: str
    faces: int
    method: str
    seconds: float | None = None
    rms: float | None = None
    max: float | None = None
    folds: int | None = None
    one_to_one: bool | None = None
    note: str = ""


COLUMNS = ("mesh", "faces", "method", "seconds", "/ LSCM", "strain RMS %", "strain max %",
           "folds", "one-to-one", "note")
"""Table header."""


def _percent(x: float | None) -> str:
    if x is None:
        return ""
    if not np.isfinite(x):
        return str(x)
    p = 100.0 * x
    return f"{p:.3g}" if p < 1e4 else f"{p:.2e}"


def _cells(row: Row, lscm_seconds: float | None) -> list[str]:
    """Format one row as table cells (the ratio is to the LSCM time on the same mesh)."""
    if row.seconds is not None and lscm_seconds:
        ratio = f"{row.seconds / lscm_seconds:.2f}"
    else:
        ratio = ""
    verdict = {True: "yes", False: "no", None: ""}[row.one_to_one]
    return [
        row.mesh,
        str(row.faces),
        row.method,
        "" if row.seconds is None else f"{row.seconds:.3f}",
        ratio,
        _percent(row.rms),
        _percent(row.max),
        "" if row.folds is None else str(row.folds),
        verdict,
        row.note,
    ]


WIDTHS = (18, 8, 13, 9, 7, 13, 13, 7, 10, 0)
"""Column widths of the plain-text table."""


def plain_line(cells) -> str:
    """One fixed-width plain-text table line."""
    parts = []
    for cell, width in zip(cells, WIDTHS, strict=True):
        parts.append(f"{cell:<{width}}" if width else cell)
    return " ".join(parts).rstrip()


def markdown_table(groups: list[list[Row]]) -> str:
    """Markdown table of several meshes' rows (each group is one mesh)."""
    lines = ["| " + " | ".join(COLUMNS) + " |", "|" + "---|" * len(COLUMNS)]
    for rows in groups:
        lscm = next((r.seconds for r in rows if r.method == "lscm"), None)
        for row in rows:
            cells = [c.replace("|", "/") for c in _cells(row, lscm)]
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


def corpus_meshes(folder: Path):
    """Yield ``(name, vertices, faces)`` for every ``*.obj`` and ``*.off`` in ``folder``.

    Loaded with ``trimesh.load(path, process=False)``: vertices are neither merged
    nor reordered.
    """
    paths = sorted(p for p in folder.iterdir() if p.suffix.lower() in (".obj", ".off"))
    for path in paths:
        mesh = trimesh.load(path, process=False)
        vertices = np.ascontiguousarray(mesh.vertices, dtype=np.float64)
        faces = np.ascontiguousarray(mesh.faces, dtype=np.int64)
        yield path.name, vertices, faces


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


def measure(row: Row, vertices, faces, uv, loops) -> Row:
    """Fill ``row`` with the strain, folds and overlap verdict of ``uv``.

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
    with np.errstate(over="ignore", invalid="ignore"):
        d = patterns.distortion(vertices, faces, uv, loops=loops)
    row.rms, row.max, row.folds = d.edge_strain_rms, d.edge_strain_max, d.n_folded
    if loops is not None:
        row.one_to_one = patterns.overlap_verdict(faces, uv, loops).one_to_one
    return row


# --------------------------------------------------------------------------- #
# patterns
# --------------------------------------------------------------------------- #


def run_patterns(name: str, vertices, faces, method: str, repeats: int,
                 max_faces_conformal: int, max_faces_tight: int = 0) -> Row:
    """Time :func:`patterns.flatten_mesh` and measure its result.

    Parameters
    ----------
    name : str
    vertices : (n, 3) float64
    faces : (m, 3) int64
    method : {"relaxed", "relaxed-tight", "isometric", "conformal"}
        ``relaxed-tight`` is ``relaxed`` with the options :data:`TIGHT`.
    repeats : int
        Best of this many runs.
    max_faces_conformal : int
        Above this face count the conformal method is not run.
    max_faces_tight : int
        Above this face count ``relaxed-tight`` is not run.

    Returns
    -------
    Row
        Strain from ``result.distortion``, folds and verdict from ``result``
        (the same functions that measure the libigl rows).  A
        :class:`patterns.PatternsError` is reported in the note ("diverged" for
        a :class:`patterns.FlattenError`).
    """
    row = Row(name, len(faces), method)
    if method == "conformal" and len(faces) > max_faces_conformal:
        row.note = "skipped (pure-Python reference)"
        return row
    if method == "relaxed-tight" and len(faces) > max_faces_tight:
        row.note = f"skipped (> {max_faces_tight} faces)"
        return row
    options = TIGHT if method == "relaxed-tight" else {}
    try:
        seconds, result = best_of(
            lambda: patterns.flatten_mesh(vertices, faces, method=method.removesuffix("-tight"), name=name,
                                          **options),
            1 if options else repeats)
    except patterns.FlattenError as exc:
        row.note = f"diverged: {exc}"
        return row
    except patterns.PatternsError as exc:
        row.note = f"{type(exc).__name__}: {exc}"
        return row
    row.seconds = seconds
    with np.errstate(over="ignore", invalid="ignore"):  # a diverged conformal layout overflows here
        d = result.distortion
    row.rms, row.max = d.edge_strain_rms, d.edge_strain_max
    row.folds, row.one_to_one = result.n_folded, result.one_to_one
    if result.method == "relaxed":
        row.note = f"start={result.start}, {result.iterations} iterations"
        if not result.converged:
            row.note += ", not converged"
    return row


def run_relaxed_from_arap(name: str, vertices, faces, max_faces: int) -> Row:
    """The relaxation with the :data:`TIGHT` options, started from libigl ARAP's layout.

    Shows whether the least-squares edge strain ``relaxed`` reaches is a
    property of the mesh or of the start: from ARAP's (one-to-one) layout the
    same relaxation should end at the same RMS as ``relaxed-tight``.  Uses the
    relaxation's own function (``patterns.flatten.relax.relax``), as
    ``flatten_mesh`` takes no start layout.  Not judged; the time is the
    relaxation's alone (ARAP's is in its own row).

    Returns
    -------
    Row
    """
    from patterns.flatten.relax import relax

    row = Row(name, len(faces), "arap+relaxed")
    if len(faces) > max_faces:
        row.note = f"skipped (> {max_faces} faces)"
        return row
    v, f, conn = patterns.validate_mesh(vertices, faces, name=name)
    start = _mirror_if_reversed(f, np.asarray(igl_arap(v, f)[0], dtype=np.float64), row)
    if not patterns.overlap_verdict(f, start, conn.loops).one_to_one:
        row.note = "skipped (ARAP's layout is not one-to-one)"
        return row
    t0 = time.perf_counter()
    result = relax(v, f, conn, start, barrier=1e-3, **TIGHT)
    row.seconds = time.perf_counter() - t0
    row = measure(row, v, f, np.asarray(result.uv), conn.loops)
    row.note = (row.note + "; " if row.note else "") + f"start=arap, {result.iterations} iterations" + (
        "" if result.converged else ", not converged")
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


def igl_arap(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, float]:
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


def igl_slim(vertices: np.ndarray, faces: np.ndarray, iterations: int) -> tuple[np.ndarray, float]:
    """libigl SLIM (symmetric Dirichlet, no constraints) from the harmonic initialisation.

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


def _init_note(faces: np.ndarray, init: np.ndarray, init_seconds: float) -> str:
    """Note on the harmonic initialisation: its time and, if any, its folded triangles."""
    folded = len(folded_faces(faces, init))
    return f"harmonic init {init_seconds:.3f} s" + (f" ({folded} folded)" if folded else "")


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
            row.note = _init_note(faces, init, init_seconds) + f"; {SLIM_ITERATIONS} iterations"
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
# Acceptance summary
# --------------------------------------------------------------------------- #

RSS_CHILD = """\
import json, resource, sys, time
import numpy as np
import patterns

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


ACCEPT_COLUMNS = ("mesh", "faces", "relaxed one-to-one", "relaxed RMS %", "RMS / ARAP", "ARAP folds",
                  "RMS / SLIM", "strain", "time / ARAP", "time / SLIM", "100k: <= ARAP time",
                  "100k: >= 3x faster than SLIM", "1M: < 30 s", "1M: peak RSS GB", "1M: < 4 GB")
"""Header of the acceptance table."""

ACCEPT_WIDTHS = (18, 8, 8, 8, 8, 10, 8, 26, 8, 8, 6, 6, 6, 8, 0)
"""Column widths of the plain-text acceptance table."""

ACCEPT_PLAIN_HEADER = ("mesh", "faces", "rel 1:1", "rel RMS%", "/ARAP", "ARAP folds", "/SLIM", "strain",
                       "t/ARAP", "t/SLIM", "<=ARAP", ">=3xSL", "<30s", "RSS GB", "<4GB")
"""Shorter header for the plain-text acceptance table."""


def _ratio(a: float | None, b: float | None) -> float | None:
    if a is None or b is None or not np.isfinite(a) or not np.isfinite(b) or b == 0:
        return None
    return a / b


def _verdict(ok: bool | None) -> str:
    return {True: "PASS", False: "FAIL", None: "n/a"}[ok]


def acceptance(rows: list[Row], memory: Memory | None) -> tuple[list[str], dict[str, bool | None]] | None:
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
    verdicts : dict
        Criterion name to True (PASS), False (FAIL) or None (not measurable);
        criteria that do not apply to this mesh's size are absent.
    """
    by = {r.method: r for r in rows}
    rel = by.get("relaxed")
    if rel is None:
        return None
    arap, slim = by.get("arap"), by.get("slim")
    faces = rel.faces
    verdicts: dict[str, bool | None] = {}

    rms_arap = _ratio(rel.rms, arap.rms if arap else None)
    rms_slim = _ratio(rel.rms, slim.rms if slim else None)
    arap_folds = arap.folds if arap else None
    if rel.rms is None or not np.isfinite(rel.rms):
        strain, verdicts["strain"] = "FAIL (no relaxed result)", False
    elif arap_folds is None:
        strain, verdicts["strain"] = "n/a (no ARAP result)", None
    elif arap_folds == 0:
        ok = rms_arap is not None and rms_arap <= ACCEPT_STRAIN_RATIO
        strain = f"{_verdict(ok)} ({'<=' if ok else '>'} {ACCEPT_STRAIN_RATIO} x ARAP)"
        verdicts["strain"] = ok
    elif rms_slim is None:
        strain, verdicts["strain"] = "n/a (ARAP folds, no SLIM)", None
    else:
        ok = rms_slim < 1.0
        strain = f"{_verdict(ok)} ({'<' if ok else '>='} SLIM; ARAP folds)"
        verdicts["strain"] = ok

    t_arap = _ratio(rel.seconds, arap.seconds if arap else None)
    t_slim = _ratio(rel.seconds, slim.seconds if slim else None)
    le_arap = faster_slim = under_30 = rss = under_4 = "-"
    if ACCEPT_100K[0] <= faces <= ACCEPT_100K[1]:
        ok = None if t_arap is None else t_arap <= 1.0
        le_arap, verdicts["100k time <= ARAP"] = _verdict(ok), ok
        ok = None if t_slim is None else t_slim <= 1.0 / ACCEPT_SLIM_SPEEDUP
        faster_slim, verdicts["100k >= 3x faster than SLIM"] = _verdict(ok), ok
    if faces >= ACCEPT_1M:
        ok = None if rel.seconds is None else rel.seconds < ACCEPT_1M_SECONDS
        under_30, verdicts["1M < 30 s"] = _verdict(ok), ok
        peak = memory.peak_bytes if memory else None
        rss = "" if peak is None else f"{peak / 1e9:.2f}"
        ok = None if peak is None else peak < ACCEPT_1M_BYTES
        under_4, verdicts["1M < 4 GB"] = _verdict(ok), ok

    def num(x, fmt=".3f"):
        return "" if x is None else format(x, fmt)

    folds_cell = "" if arap_folds is None else ("no" if arap_folds == 0 else f"yes ({arap_folds})")
    cells = [rel.mesh, str(faces), {True: "yes", False: "no", None: ""}[rel.one_to_one], _percent(rel.rms),
             num(rms_arap, ".3g"), folds_cell, num(rms_slim, ".3g"), strain, num(t_arap, ".2f"), num(t_slim, ".3f"),
             le_arap, faster_slim, under_30, rss, under_4]
    return cells, verdicts


def acceptance_tables(groups: list[list[Row]], memories: dict[str, Memory]):
    """Acceptance cells of every mesh with a ``relaxed`` row, and PASS/FAIL counts per criterion.

    Returns
    -------
    lines : list of list of str
    counts : dict
        Criterion to ``(n_pass, n_fail, n_not_measurable)``.
    """
    lines, counts = [], {}
    for rows in groups:
        out = acceptance(rows, memories.get(rows[0].mesh) if rows else None)
        if out is None:
            continue
        cells, verdicts = out
        lines.append(cells)
        for key, ok in verdicts.items():
            c = counts.setdefault(key, [0, 0, 0])
            c[0 if ok is True else 1 if ok is False else 2] += 1
    return lines, {k: tuple(v) for k, v in counts.items()}


def acceptance_text(groups: list[list[Row]], memories: dict[str, Memory], markdown: bool) -> str:
    """The acceptance block: legend, table (markdown or plain), counts and memory notes."""
    lines, counts = acceptance_tables(groups, memories)
    if not lines:
        return "acceptance: no relaxed rows"
    out = [
        "relaxed against libigl, per mesh.  RMS / ARAP, RMS / SLIM: relaxed's edge-strain RMS divided",
        "by theirs; time / ARAP, time / SLIM: relaxed's seconds divided by theirs.",
        (f"strain: PASS if RMS <= {ACCEPT_STRAIN_RATIO} x ARAP's where ARAP has no folded triangle, "
         "else if RMS < SLIM's."),
        (f"100k criteria judged on meshes with {ACCEPT_100K[0]}-{ACCEPT_100K[1]} faces, 1M criteria on "
         f"meshes with >= {ACCEPT_1M} faces ('-' elsewhere)."),
        "1M: time from the table; peak RSS (VmHWM) of a child process that imports patterns,",
        "loads the mesh and runs flatten_mesh(V, F) once.",
        "",
    ]
    if markdown:
        out.append("| " + " | ".join(ACCEPT_COLUMNS) + " |")
        out.append("|" + "---|" * len(ACCEPT_COLUMNS))
        out += ["| " + " | ".join(c.replace("|", "/") for c in cells) + " |" for cells in lines]
    else:
        def line(cells):
            return " ".join(f"{c:<{w}}" if w else c
                            for c, w in zip(cells, ACCEPT_WIDTHS, strict=True)).rstrip()
        out.append(line(ACCEPT_PLAIN_HEADER))
        out += [line(cells) for cells in lines]
    out.append("")
    for key, (n_pass, n_fail, n_na) in counts.items():
        out.append(f"{'* ' if markdown else ''}{key}: PASS on {n_pass}, FAIL on {n_fail}"
                   + (f", not measurable on {n_na}" if n_na else "")
                   + f" of {n_pass + n_fail + n_na} meshes")
    for name, mem in memories.items():
        if mem.peak_bytes is None:
            out.append(f"{'* ' if markdown else ''}memory {name}: {mem.note}")
        else:
            out.append(f"{'* ' if markdown else ''}memory {name}: child peak RSS {mem.peak_bytes / 1e9:.2f} GB "
                       f"({mem.before_bytes / 1e9:.2f} GB after imports and loading the mesh); "
                       f"child flatten_mesh {mem.seconds:.2f} s (one cold run)"
                       + (f"; {mem.note}" if mem.note else ""))
    return "\n".join(out)


# --------------------------------------------------------------------------- #
# Driver
# --------------------------------------------------------------------------- #


def bench_mesh(name: str, vertices, faces, methods, args, on_row) -> list[Row]:
    """Run every selected method on one mesh; return its rows in print order.

    LSCM runs first so the other rows can be given as a ratio of its time.
    ``on_row(row, lscm_seconds)`` is called as each row is finished.
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
    order = ["lscm"] + [m for m in ALL_METHODS if m != "lscm"]
    for method in order:
        if method not in methods:
            continue
        print(f"  {name}: {method} ...", file=sys.stderr, flush=True)
        if method.removesuffix("-tight") in patterns.METHODS:
            rows[method] = run_patterns(name, vertices, faces, method, repeats, args.max_faces_conformal,
                                        args.max_faces_tight)
        elif method == "arap+relaxed":
            rows[method] = run_relaxed_from_arap(name, vertices, faces, args.max_faces_tight)
        else:
            rows[method] = run_libigl(name, vertices, faces, method, repeats, loops, args.max_faces_slim)
            if loops is None and not rows[method].note.startswith("skipped"):
                rows[method].note = "; ".join(x for x in (rows[method].note, loops_note) if x)
    out = [rows[m] for m in ALL_METHODS if m in rows]
    lscm = rows["lscm"].seconds if "lscm" in rows else None
    for row in out:
        on_row(row, lscm)
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
        if method.removesuffix("-tight") in patterns.METHODS:
            run_patterns("warm-up", vertices, faces, method, 1, len(faces), len(faces))
        elif method == "arap+relaxed":
            run_relaxed_from_arap("warm-up", vertices, faces, len(faces))
        else:
            run_libigl("warm-up", vertices, faces, method, 1, loops, len(faces))


HEADER = """\
Edge strain = |flat edge length / 3D edge length - 1| over all edges (RMS and max, in %).
Times: best of 3 runs up to {limit} faces, 1 run above; '/ LSCM' = seconds / LSCM seconds on the same mesh.
relaxed, isometric, conformal: patterns.flatten_mesh, default options (validation + grower
  [+ relaxation] + overlap verdict), uv never rescaled; relaxed note: start layout, iterations.
relaxed-tight: relaxed with max_iterations=5000, tolerance=1e-9 (one run): how low the stress goes.
arap+relaxed: the same relaxation (tight options) started from libigl ARAP's layout instead (time:
  the relaxation alone): whether the lowest stress depends on the start.
lscm: igl.lscm, two farthest boundary vertices pinned; its uv is RESCALED by one factor so that
  total flat area = total 3D area before the strain is measured (LSCM has no scale of its own).
arap: igl harmonic init (boundary on a circle) + arap_precomputation/arap_solve, 2D, default 10 iterations,
  one vertex held (translation only); time includes the harmonic init.
slim: igl.slim_solve, symmetric Dirichlet, {slim} iterations, same harmonic init, included in the time.
All rows measured by patterns.distortion and patterns.overlap_verdict (outside the timed region)."""


def main(argv=None) -> int:
    """Command-line entry point; see ``--help``."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", default="1k,10k,100k,1M",
                        help=f"sizes of the generated {', '.join(SHAPES)}, comma-separated from "
                             "1k,10k,100k,1M (default all; '' for none)")
    parser.add_argument("--extra-sizes", default="10k,100k",
                        help=f"sizes of the generated {', '.join(EXTRA_SHAPES)} "
                             "(default 10k,100k; '' for none)")
    parser.add_argument("--no-memory", action="store_true",
                        help=f"skip the child-process peak-memory run of relaxed on meshes with "
                             f">= {ACCEPT_1M} faces")
    parser.add_argument("--no-corpus", action="store_true", help="skip the shared corpus meshes")
    parser.add_argument("--methods", default=",".join(ALL_METHODS),
                        help=f"comma-separated subset of {','.join(ALL_METHODS)} (default all)")
    parser.add_argument("--markdown", action="store_true",
                        help="print the tables as markdown (for docs/benchmarks.md) at the end")
    parser.add_argument("--max-faces-conformal", type=int, default=200_000,
                        help="skip the conformal method above this many faces (default 200000)")
    parser.add_argument("--max-faces-tight", type=int, default=40_000,
                        help="skip relaxed-tight (relaxed to tolerance 1e-9, up to 5000 iterations) "
                             "above this many faces (default 40000)")
    parser.add_argument("--max-faces-slim", type=int, default=120_000,
                        help="skip libigl SLIM above this many faces (default 120000)")
    args = parser.parse_args(argv)

    methods = [m.strip() for m in args.methods.split(",") if m.strip()]
    unknown = [m for m in methods if m not in ALL_METHODS]
    if unknown:
        parser.error(f"unknown methods {unknown}; choose from {', '.join(ALL_METHODS)}")
    sizes = parse_sizes(args.sizes)
    extra_sizes = parse_sizes(args.extra_sizes)

    print(HEADER.format(limit=REPEAT_LIMIT, slim=SLIM_ITERATIONS))
    print(machine_summary())
    print()

    def on_row(row, lscm):
        # With --markdown the tables come at the end; the rows go to stderr as progress.
        print(plain_line(_cells(row, lscm)), file=sys.stderr if args.markdown else sys.stdout, flush=True)

    sections = []
    if args.no_corpus:
        print("corpus: skipped (--no-corpus)")
    elif not CORPUS.is_dir():
        print(f"corpus: skipped ({CORPUS} does not exist)")
    else:
        sections.append(("Corpus (../shared/corpus/)", corpus_meshes(CORPUS)))
    if sizes or extra_sizes:
        sections.append(("Generated surfaces", generated_meshes(sizes, extra_sizes)))

    warm_up(methods)
    tables = []
    memories: dict[str, Memory] = {}
    for title, meshes in sections:
        if not args.markdown:
            print(f"\n== {title} ==")
            print(plain_line(COLUMNS))
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
