"""Flattening: 3D triangle meshes to 1:1 flat patterns.

:func:`flatten_mesh` is the one-shot entry point: plain arrays in, a frozen
:class:`Flattening` out.  The growers themselves live in
:mod:`patterns.flatten.grow`.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..check import Overlap, overlap_verdict
from ..errors import FlattenError, InputError
from ..measure import Distortion, distortion, local_coordinates, signed_areas
from ..mesh import _readonly, unique_edges, unique_ints, validate_mesh
from . import grow
from .embed import lscm, tutte_embedding
from .relax import align_to_pins, best_scale, check_pins, relax

__all__ = ["METHODS", "Flattening", "flatten", "flatten_mesh"]

METHODS = ("relaxed", "isometric", "conformal")
"""The flattening methods :func:`flatten_mesh` accepts."""


@dataclass(frozen=True, eq=False)
class Flattening:
    """The result of :func:`flatten_mesh`.

    Attributes
    ----------
    uv : (n, 2) float64
        Flat position of every input vertex, in the input's vertex order and
        unit, at true scale (read-only).
    vertices : (n, 3) float64
        The validated input vertices (read-only).
    faces : (m, 3) int64
        The validated input faces (read-only).
    loops : tuple of (k,) int64
        Boundary loops (vertex indices, surface to their left; longest first).
    method : str
    seed_face : int
        The triangle the greedy grower laid down first, without distortion.
    overlap : Overlap
        The overlap verdict: folded triangles, loop tests, ``one_to_one``.
    start : str
        ``"relaxed"`` only: the layout the relaxation started from --
        ``"greedy"`` (the isometric grower's, when it is one-to-one), else
        ``"lscm"`` (when that is one-to-one), else ``"tutte"``; "" otherwise.
    iterations : int
        ``"relaxed"`` only: relaxation iterations run (0 otherwise).
    converged : bool
        ``"relaxed"``: the stress stopped decreasing (by the tolerance) and the
        pins were reached within ``max_iterations``.  True for the growers.
    """

    uv: np.ndarray
    vertices: np.ndarray
    faces: np.ndarray
    loops: tuple
    method: str
    seed_face: int
    overlap: Overlap
    start: str = ""
    iterations: int = 0
    converged: bool = True

    @property
    def one_to_one(self) -> bool:
        """True when the flat pattern does not overlap itself anywhere."""
        return self.overlap.one_to_one

    @property
    def n_folded(self) -> int:
        """Number of folded (flipped or collapsed) triangles."""
        return self.overlap.n_folded

    @cached_property
    def distortion(self) -> Distortion:
        """Edge strain, principal stretches, areas and boundary lengths."""
        return distortion(self.vertices, self.faces, self.uv, loops=self.loops)


def flatten_mesh(vertices, faces, *, method: str = "relaxed", seed_face: int | None = None,
                 pins=None, max_iterations: int = 500, tolerance: float = 1e-4,
                 min_stretch: float | None = None, progress=None, name: str = "mesh") -> Flattening:
    """Flatten a triangle mesh to the plane at true scale.

    Parameters
    ----------
    vertices : array_like, (n, 3) float
        Coordinates, any unit (mm throughout `patterns`); the flat pattern is in
        the same unit, never rescaled.
    faces : array_like, (m, 3) int
        Consistently wound triangles forming one connected planar domain (a disk,
        or a disk with holes).
    method : {"relaxed", "isometric", "conformal"}
        ``"relaxed"`` (default): the ``"isometric"`` layout -- or, where that
        overlaps itself, a conformal (LSCM) or Tutte layout -- relaxed towards
        true edge lengths (least squared edge strain, with an annealed barrier
        that keeps triangles open on the way) while every triangle keeps its
        orientation and the boundary never crosses itself: the result is
        always one-to-one.  Use it for patterns.  See
        :mod:`patterns.flatten.relax`.

        ``"isometric"``: the greedy grower with length-preserving
        steps, each triangle placed at its true size and rotated by a frame
        carried across the mesh, one vectorised pass per front.  Exact on
        developable meshes, stable under refinement, fast (a million faces in
        about two seconds); it can fold on strongly curved parts, which the
        overlap verdict reports.

        ``"conformal"``: the paper as written (Li & Xue): one vertex at a time,
        shortest front first, each candidate from the Cauchy-Riemann equations of
        its triangle.  Every step scales its triangle by the length error of the
        edge it is built on, and that error compounds ring after ring: scale
        errors of 1e3 at 10k faces, overflow near a million.  Kept as the
        faithful reference for measurements, not for cutting.
    seed_face : int, optional
        The triangle the grower lays down first; default the one farthest from
        the boundary.
    pins : tuple of ((k,) int, (k, 2) float), optional
        ``"relaxed"`` only: vertices held at given flat positions (libigl's
        ``b, bc``), in the mesh unit.  The start is first moved rigidly onto
        them; they are then reached step by step unless that would fold.
    max_iterations : int
        ``"relaxed"`` only: at most this many relaxation iterations (> 0).
        Mildly curved parts converge in 10-25, heads and other strongly
        curved parts that start from LSCM in 70-250.
    tolerance : float
        ``"relaxed"`` only: stop when the summed squared edge strain falls by
        less than this fraction per iteration (averaged over two; >= 0).
    min_stretch : float in (0, 1), optional
        ``"relaxed"`` only: keep every triangle's smallest principal stretch
        near or above this (0.3 keeps each triangle at least about 30 % of its
        size in every direction).  Least squared edge strain alone may press a
        small region of a dome or a cup nearly flat (measured in
        docs/benchmarks.md); this adds a guard that is zero until a triangle is
        squeezed that far.  Parts without such a region come out unchanged; on
        a hemisphere the edge-strain RMS rises by about 2 %.
    progress : callable, optional
        Called as ``progress(n_done, n_total)``: vertices placed by a grower,
        then iterations of the relaxation.
    name : str
        How the mesh is named in error messages.

    Returns
    -------
    Flattening
        ``.uv`` is ``(n, 2) float64``; ``.overlap`` the overlap verdict.

    Raises
    ------
    InputError, MeshTopologyError
        Bad arrays or a mesh that is not one connected planar domain (see
        :func:`patterns.mesh.validate_mesh`); an unknown method or seed.
    FlattenError
        The conformal grower's scale error grew beyond double precision (the
        flat triangle areas overflow).
    """
    if method not in METHODS:
        raise InputError(f"unknown flattening method {method!r}; choose one of {', '.join(METHODS)}")
    # Cheap option checks before the mesh is validated (a second at 1M faces).
    if method != "relaxed" and pins is not None:
        raise InputError(f"{name}: pins apply to method='relaxed' only")
    if min_stretch is not None:
        if method != "relaxed":
            raise InputError(f"{name}: min_stretch applies to method='relaxed' only")
        if isinstance(min_stretch, bool) or not isinstance(min_stretch, (int, float, np.floating)) \
                or not 0 < min_stretch < 1:
            raise InputError(f"{name}: min_stretch must be a number between 0 and 1, got {min_stretch!r}")
    if isinstance(max_iterations, bool) or not isinstance(max_iterations, (int, np.integer)) or max_iterations < 1:
        raise InputError(f"{name}: max_iterations must be a positive integer, got {max_iterations!r}")
    if not (isinstance(tolerance, (int, float, np.floating)) and tolerance >= 0):
        raise InputError(f"{name}: tolerance must be a number >= 0, got {tolerance!r}")
    v, f, conn = validate_mesh(vertices, faces, name=name)
    if seed_face is None:
        seed = grow.seed_face(v, f, conn)
    else:
        if isinstance(seed_face, bool) or not isinstance(seed_face, (int, np.integer)) or not 0 <= seed_face < len(f):
            raise InputError(f"{name}: seed_face must be a face index in [0, {len(f)}), got {seed_face!r}")
        seed = int(seed_face)
    if pins is not None:
        pins = check_pins(pins, len(v), name)
    z = local_coordinates(v, f)
    weights = 0.5 * np.abs((np.conj(z[:, 1]) * z[:, 2]).imag)
    with np.errstate(over="ignore", invalid="ignore"):
        if method == "conformal":
            w = grow.grow_heap(z, f, conn, weights, seed, grow.similarity_step, progress=progress)
        else:
            rotations = grow.transported_rotations(z, f, conn, seed)
            w = grow.grow_fronts(z, f, conn, weights, seed, grow.transported_step,
                                 rotations=rotations, progress=None if method == "relaxed" else progress)
    uv = np.column_stack([w.real, w.imag])
    if method == "relaxed":
        return _relaxed(v, f, conn, uv, seed, z, pins, max_iterations, tolerance, progress, min_stretch)
    # Beyond ~1e154 the flat triangles' areas overflow double precision: such a
    # result cannot even be checked, so it is an error, not an answer.
    with np.errstate(over="ignore", invalid="ignore"):
        overflow = not np.all(np.isfinite(signed_areas(f, uv)))
    if overflow:
        raise FlattenError(
            f"{name}: the {method} grower diverged (flat coordinates beyond double precision); "
            f"use method='isometric'"
        )
    return Flattening(
        uv=_readonly(uv),
        vertices=_readonly(v),
        faces=_readonly(f),
        loops=conn.loops,
        method=method,
        seed_face=seed,
        overlap=overlap_verdict(f, uv, conn.loops),
    )


def _relaxed(v, f, conn, greedy, seed, z, pins, max_iterations, tolerance, progress, min_stretch) -> Flattening:
    """Pick a one-to-one start (greedy, else LSCM, else Tutte) and relax it."""
    start, label, barrier = greedy, "greedy", 1e-3
    if not overlap_verdict(f, start, conn.loops).one_to_one:
        start, label = lscm(v, f, conn, local=z), "lscm"
        if not overlap_verdict(f, start, conn.loops).one_to_one:
            start, label = tutte_embedding(v, f, conn), "tutte"
        # These layouts have no true scale of their own: start from the best one.
        start = start * best_scale(v, conn.edges, start)
        barrier = 0.1  # far from the answer: keep triangles open while it moves
    if pins is not None:
        start = align_to_pins(start, *pins)  # a rigid motion: still one-to-one
    result = relax(v, f, conn, start, pins=pins, barrier=barrier, max_iterations=max_iterations, tolerance=tolerance,
                   progress=progress, local=z, min_stretch=min_stretch)
    uv = np.array(result.uv)
    return Flattening(
        uv=_readonly(uv),
        vertices=_readonly(v),
        faces=_readonly(f),
        loops=conn.loops,
        method="relaxed",
        seed_face=seed,
        overlap=overlap_verdict(f, uv, conn.loops),
        start=label,
        iterations=result.iterations,
        converged=result.converged,
    )


def flatten(model, *, method: str = "relaxed", exact: bool = True, thickness: float = 0.0, k_factor: float = 0.5,
            reference: str = "mid", grain=None, max_strain: float | None = None, max_darts: int = 60,
            max_iterations: int = 500, tolerance: float = 1e-6, min_stretch: float | None = None,
            progress=None):
    """Lay every panel of a model flat at true scale.

    Parameters
    ----------
    model : patterns.Model
        From :func:`patterns.load`.
    method : {"relaxed", "isometric", "conformal"}
        The mesh engine, for freeform panels (see :func:`flatten_mesh`).
    exact : bool
        Unroll planar, cylindrical and conical CAD faces analytically
        (:mod:`patterns.flatten.develop`: exact to round-off, no mesh engine);
        their :attr:`Flattening.method` is ``"exact"``.  False sends them
        through the engine too.
    thickness : float
        Sheet thickness, mm (>= 0).  With a thickness the pattern is the
        development of the neutral surface, ``k_factor * thickness`` from the
        inside skin, so that the blank forms to the modelled size.
    k_factor : float
        Position of the neutral surface in the sheet, from the inside (0..1).
    reference : {"inside", "outside", "mid"}
        Which skin the model shows.  The offset goes towards the convex side of
        cylinders and cones (away from their axis), along the face normal on
        freeform faces.
    grain : (3,) float or mapping of panel name to (3,), optional
        A 3D direction (the fabric's grain, a sheet's rolling direction): each
        flat panel is turned so that this direction, as it lies on the panel,
        points along +Y.  One direction for all panels, or one per panel name
        (panels not named keep their orientation).  Only rotations: nothing
        is scaled.
    max_strain : float, optional
        Largest acceptable triangle strain (0.03 = 3 %).  A freeform panel that
        comes out above it is cut, one dart at a time, from the outline to its
        most strained point by the shortest path along its edges (the paper's
        "segmentation"), and flattened again, until it is within the limit or
        ``max_darts`` cuts are made (``patterns.check`` then reports it).
        Every cut is in :attr:`FlatPanel.darts`.
    max_darts : int
        At most this many darts per panel.
    max_iterations, tolerance
        ``"relaxed"`` only; see :func:`flatten_mesh`.  The tolerance here is
        1e-6 (``flatten_mesh``: 1e-4): a pattern is relaxed to convergence, so
        that the two flat sides of a seam come out as close as the surface
        allows (on the cup sample 0.091-0.096 % apart, against up to 0.13 %
        at 1e-4), for about 1.5 times the iterations.
    min_stretch : float in (0, 1), optional
        ``"relaxed"`` only; see :func:`flatten_mesh`: no triangle pressed below
        this in any direction (a dome relaxed to 1e-6 without it can lose a
        tenth of its area at the pole; see docs/benchmarks.md).
    progress : callable, optional
        ``progress(panels_done, n_panels)`` after each panel.

    Returns
    -------
    patterns.Pattern
        One :class:`~patterns.FlatPanel` per panel (vertex ``i`` of the panel at
        ``uv[i]``), and each seam with its flat length on either side.

    Raises
    ------
    InputError
        Not a model, or bad options.
    FlattenError
        See :func:`flatten_mesh`.
    """
    from ..model import Model
    from ..pattern import FlatPanel, FlatSeam, Pattern
    from .develop import neutral_offset

    if not isinstance(model, Model):
        raise InputError(f"flatten() takes a patterns.Model (from patterns.load), got {type(model).__name__}")
    if method not in METHODS:
        raise InputError(f"unknown flattening method {method!r}; choose one of {', '.join(METHODS)}")
    offset = neutral_offset(thickness, k_factor, reference, name=model.name)
    grains = _grain_table(grain, model)
    if max_strain is not None and (isinstance(max_strain, bool) or not isinstance(max_strain, (int, float))
                                   or not np.isfinite(max_strain) or max_strain <= 0):
        raise InputError(f"{model.name}: max_strain must be a positive number, got {max_strain!r}")
    if isinstance(max_darts, bool) or not isinstance(max_darts, (int, np.integer)) or max_darts < 0:
        raise InputError(f"{model.name}: max_darts must be an integer >= 0, got {max_darts!r}")
    flat = []
    for i, panel in enumerate(model.panels):
        name = f"{model.name}: panel {panel.name}"
        darts = ()
        if exact and panel.surface is not None:
            result = _developed(panel, offset, name)
        else:
            vertices = _offset_along_normals(panel, offset) if offset else panel.vertices
            result = flatten_mesh(vertices, panel.faces, method=method, max_iterations=max_iterations,
                                  tolerance=tolerance, min_stretch=min_stretch, name=name)
            if max_strain is not None:
                result, darts = _with_darts(result, max_strain, max_darts, method, max_iterations, tolerance,
                                            min_stretch, name)
        if panel.name in grains:
            result = _turn_to_grain(result, grains[panel.name])
        flat.append(FlatPanel(panel.name, panel, result, darts=darts))
        if progress is not None:
            progress(i + 1, len(model.panels))
    seams = []
    for seam in model.seams:
        lengths = tuple(
            float(np.linalg.norm(np.diff(flat[p].uv[idx], axis=0), axis=1).sum())
            for p, idx in zip(seam.panels, seam.vertices)
        )
        seams.append(FlatSeam(seam, lengths))
    return Pattern(model=model, panels=tuple(flat), seams=tuple(seams), method=method,
                   thickness=float(thickness), k_factor=float(k_factor), reference=reference)


_DART_SLACK = 1.05  # a dart is kept if the edge-strain RMS after it is at most this times the lowest so far
_DART_REFUSALS = 4  # consecutive refused darts before the loop gives up


def _with_darts(result: Flattening, limit: float, max_darts: int, method, max_iterations, tolerance, min_stretch,
                name):
    """Cut darts into a flattening until its triangle strain is within ``limit``.

    Greedy: each round finds the vertices next to a triangle above the limit,
    takes the one deepest inside (farthest from the outline along the mesh),
    cuts along the shortest path of edges from the outline to it, and flattens
    again.  A dart is kept only if the edge-strain RMS after it (the
    relaxation's objective, which a cut can only lower at the optimum) is at
    most ``_DART_SLACK`` times the lowest so far; otherwise the cut is undone
    and the next deepest vertex is tried (after ``_DART_REFUSALS`` refusals in
    a row the loop stops).  Without that, one cut whose flaps overlap when laid
    flat (LSCM then overlaps, and the relaxation starts from Tutte's layout)
    sent every later round to 50-300 % strain on a hemisphere.  The worst
    triangle strain is not the test: it moves about from cut to cut, and
    darts that raise it for a round are often what brings it down later.
    Returns ``(flattening, darts)``.
    """
    from ..cut import cut_along

    darts = []
    lowest = result.distortion.edge_strain_rms
    refused = set()  # target vertices whose dart made things worse (indices survive later cuts)
    in_a_row = 0
    depths = _strained_depths(result, limit)  # recomputed only when a dart is kept
    while depths is not None and len(darts) < max_darts and in_a_row < _DART_REFUSALS:
        strained, dist, pred = depths
        # The vertex to cut to: among the vertices next to a triangle above the
        # limit, the one deepest inside (farthest from the outline along the
        # mesh), so that one dart relieves the whole strained run.
        open_to = strained.copy()
        open_to[list(refused)] = False
        candidates = np.flatnonzero(open_to)
        if not len(candidates):
            break  # every strained triangle lies on the outline (or was tried): nothing left to cut
        target = int(candidates[np.argmax(dist[candidates])])
        path = [target]
        while pred[path[-1]] >= 0:
            path.append(int(pred[path[-1]]))
        path = np.asarray(path[::-1], dtype=np.int64)  # from the outline inwards
        cut = cut_along(result.vertices, result.faces, path, name=name)
        after = flatten_mesh(cut.vertices, cut.faces, method=method, max_iterations=max_iterations,
                             tolerance=tolerance, min_stretch=min_stretch, name=name)
        rms = after.distortion.edge_strain_rms
        if rms <= _DART_SLACK * lowest:
            darts.append(path)
            result, lowest, in_a_row = after, min(lowest, rms), 0
            depths = _strained_depths(result, limit)
        else:
            refused.add(target)
            in_a_row += 1
    return result, tuple(np.asarray(d) for d in darts)


def _strained_depths(result: Flattening, limit: float):
    """Where a dart could go: ``(strained (n,) bool, dist (n,), pred (n,))``, or None if nothing is above ``limit``.

    ``strained`` marks the inner vertices next to a triangle above the limit
    and reachable from the outline; ``dist`` and ``pred`` are the shortest
    paths along mesh edges (3D lengths) from the outline.
    """
    import scipy.sparse as sp
    from scipy.sparse import csgraph

    from ..measure import triangle_strains

    v, f = result.vertices, result.faces
    above = np.flatnonzero(triangle_strains(v, f, result.uv).magnitude > limit)
    if not len(above):
        return None
    n = len(v)
    edges = unique_edges(f)
    weight = np.linalg.norm(v[edges[:, 1]] - v[edges[:, 0]], axis=1)
    graph = sp.coo_matrix((np.r_[weight, weight], (np.r_[edges[:, 0], edges[:, 1]],
                                                    np.r_[edges[:, 1], edges[:, 0]])), shape=(n, n)).tocsr()
    boundary = unique_ints(np.concatenate(result.loops))
    dist, pred, _ = csgraph.dijkstra(graph, indices=boundary, min_only=True, return_predecessors=True)
    strained = np.zeros(n, dtype=bool)
    strained[f[above].ravel()] = True
    strained[boundary] = False
    return strained & np.isfinite(dist), dist, pred


def _grain_table(grain, model) -> dict:
    """``{panel name: unit (3,) direction}`` from ``flatten(grain=...)``."""
    if grain is None:
        return {}
    names = [p.name for p in model.panels]
    items = grain.items() if hasattr(grain, "items") else [(n, grain) for n in names]
    out = {}
    for name, direction in items:
        if name not in names:
            raise InputError(f"{model.name}: grain names panel {name!r}, which the model does not have")
        try:
            d = np.asarray(direction, dtype=np.float64).reshape(3)
        except (TypeError, ValueError):
            raise InputError(f"{model.name}: a grain is a 3D direction (x, y, z), got {direction!r}") from None
        if not np.all(np.isfinite(d)) or np.linalg.norm(d) == 0:
            raise InputError(f"{model.name}: a grain is a non-zero 3D direction, got {direction!r}")
        out[name] = d / np.linalg.norm(d)
    return out


def flat_direction(vertices, faces, uv, direction) -> np.ndarray:
    """Where a 3D direction points in a flattening: the area-weighted mean of its images, (2,) unit.

    On each triangle the direction is projected onto the triangle's plane and
    carried to the plane by the triangle's own linear map.
    """
    p, q = vertices[faces], uv[faces]
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    f1, f2 = q[:, 1] - q[:, 0], q[:, 2] - q[:, 0]
    # Solve direction ~ a e1 + b e2 (least squares on the triangle's plane): Gram system.
    g11, g12, g22 = (e1 * e1).sum(1), (e1 * e2).sum(1), (e2 * e2).sum(1)
    r1, r2 = e1 @ direction, e2 @ direction
    det = g11 * g22 - g12 * g12
    a = (g22 * r1 - g12 * r2) / det
    b = (g11 * r2 - g12 * r1) / det
    images = a[:, None] * f1 + b[:, None] * f2
    area = 0.5 * np.linalg.norm(np.cross(e1, e2), axis=1)
    total = (images * area[:, None]).sum(axis=0)
    norm = np.linalg.norm(total)
    return total / norm if norm > 0 else np.array([0.0, 1.0])


def _turn_to_grain(result: Flattening, direction) -> Flattening:
    """The flattening turned about its centre so that ``direction`` points along +Y (a rotation)."""
    from dataclasses import replace

    d = flat_direction(result.vertices, result.faces, result.uv, direction)
    angle = np.pi / 2 - np.arctan2(d[1], d[0])
    c, s = np.cos(angle), np.sin(angle)
    centre = result.uv.mean(axis=0)
    uv = (result.uv - centre) @ np.array([[c, s], [-s, c]]) + centre
    return replace(result, uv=_readonly(uv))


def _developed(panel, offset: float, name: str) -> Flattening:
    """The exact development of a planar, cylindrical or conical panel (of its offset by ``offset``)."""
    from .develop import develop, offset_points

    vertices = offset_points(panel.surface, panel.vertices, offset)
    uv = develop(panel.surface, vertices, panel.param, offset=offset)
    if np.sum(signed_areas(panel.faces, uv)) < 0:
        uv[:, 0] = -uv[:, 0]  # the parametrisation runs the other way round: mirror (an isometry)
    if not np.all(np.isfinite(uv)):
        raise FlattenError(f"{name}: the exact development gave non-finite coordinates")
    v, f, conn = validate_mesh(vertices, panel.faces, name=name)
    return Flattening(uv=_readonly(uv), vertices=_readonly(v), faces=_readonly(f), loops=conn.loops,
                      method="exact", seed_face=-1, overlap=overlap_verdict(f, uv, conn.loops), start="analytic")


def _offset_along_normals(panel, offset: float) -> np.ndarray:
    """Panel vertices moved by ``offset`` along their area-weighted normals (freeform sheet thickness)."""
    v, f = panel.vertices, panel.faces
    n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])  # length = 2 x area: area-weighted
    vn = np.zeros_like(v)
    for k in range(3):
        np.add.at(vn, f[:, k], n)
    vn /= np.maximum(np.linalg.norm(vn, axis=1, keepdims=True), 1e-300)
    return v + offset * vn
