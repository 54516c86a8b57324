"""Flattening: 3D triangle meshes to 1:1 flat patterns.

:func:`flatten_mesh` is the one-shot entry point: plain arrays in, a frozen
:class:`Flattening` out.  The growers themselves live in
:mod:`patterns.flatten.grow`.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from threadpoolctl import threadpool_limits

from ..errors import FlattenError, InputError, PatternsError
from ..measure import Distortion, distortion, flat_direction, local_coordinates, signed_areas
from ..mesh import _readonly, as_mesh_arrays, unique_edges, unique_ints, validate_mesh
from ..options import check_number, is_number
from ..predicates import Overlap, overlap_verdict
from . import grow
from .embed import lscm, tutte_embedding
from .energy import ENERGIES
from .numbering import dissection_order, renumber, renumber_connectivity, spatial_order
from .relax import align_to_pins, best_scale, check_lengths, check_pins, is_isometric, relax

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
        ``"relaxed"``: the energy stopped decreasing (by the tolerance), the
        pins were reached and the held lengths kept, within ``max_iterations``.
        True for the growers.
    energy : str
        ``"relaxed"`` only: the energy minimised (``"arap"``, ``"hybrid"`` or
        ``"symmetric-dirichlet"``; what ``"auto"`` chose); "" otherwise.
    length_error : float
        ``"relaxed"`` with ``lengths``: the largest ``|l_flat / l_held - 1|`` over
        the held edges; 0 otherwise.
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
    energy: str = ""
    length_error: float = 0.0

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
        """Principal strains, edge strain, areas and boundary lengths."""
        return distortion(self.vertices, self.faces, self.uv, loops=self.loops)


def flatten_mesh(vertices, faces, *, method: str = "relaxed", seed_face: int | None = None,
                 pins=None, max_iterations: int = 500, tolerance: float = 1e-5,
                 min_stretch: float | None = None, energy: str = "auto", lengths=None, progress=None,
                 name: str = "mesh") -> Flattening:
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
        overlaps itself, a conformal (LSCM) or Tutte layout -- relaxed to the
        least area-weighted distortion (``energy``) while every triangle keeps
        its orientation and the boundary never crosses itself: the result is
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
        Mildly curved parts converge in 6-15, heads and other strongly
        curved parts that start from LSCM in 50-250.
    tolerance : float
        ``"relaxed"`` only: stop when the energy falls by less than this
        fraction per iteration (averaged over two; >= 0).
    min_stretch : float in (0, 1), optional
        ``"relaxed"`` only: keep every triangle's smallest principal stretch
        near or above this (0.3 keeps each triangle at least about 30 % of its
        size in every direction): a guard that is zero until a triangle is
        squeezed that far.
    energy : {"auto", "arap", "hybrid", "symmetric-dirichlet"}
        ``"relaxed"`` only: the distortion minimised, each summed over the
        triangles weighted by their 3D area (:mod:`patterns.flatten.energy`).
        ``"arap"``: the squared principal strains, the material's strain
        (libigl ARAP's energy).  ``"symmetric-dirichlet"``: SLIM's energy,
        which never lets a triangle collapse.  ``"hybrid"``: half of each.
        ``"auto"`` (default): ARAP, unless its fold-free minimum presses a
        triangle flat (to below 1/1000 of its size: where the least-strain
        layout would fold, as on a scanned head), then the hybrid from there.
    lengths : tuple of ((k, 2) int, (k,) float[, (k,) int]), optional
        ``"relaxed"`` only: edges of the mesh (vertex pairs) held at these
        flat lengths, in the mesh unit -- the seams of a pattern
        (:func:`patterns.flatten` holds every seam edge at its 3D length).
        With a third array of group numbers, the edges of a group are held
        in total instead of one by one.  ``Flattening.length_error`` says how
        close they came.
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
        min_stretch = check_number(min_stretch, "min_stretch", low=0, high=1, low_open=True, high_open=True,
                                   name=name)
    max_iterations = check_number(max_iterations, "max_iterations", low=0, low_open=True, integer=True, name=name)
    tolerance = check_number(tolerance, "tolerance", low=0, name=name)
    if energy not in ENERGIES:
        raise InputError(f"{name}: unknown energy {energy!r}; choose one of {', '.join(ENERGIES)}")
    if method != "relaxed" and (lengths is not None or energy != "auto"):
        raise InputError(f"{name}: {'lengths' if lengths is not None else 'energy'} applies to method='relaxed' only")
    v, f, num, conn = _working_mesh(vertices, faces, name)
    if seed_face is not None and not (is_number(seed_face, integer=True) and 0 <= seed_face < len(f)):
        raise InputError(f"{name}: seed_face must be a face index in [0, {len(f)}), got {seed_face!r}")
    # The engine works in the working numbering: options that name vertices or faces follow it.
    inv = None if num is None else num.vertex_inverse
    if lengths is not None:
        lengths = check_lengths(lengths, conn, name, numbering=inv)
    if pins is not None:
        pins = check_pins(pins, len(v), name)
        pins = pins if num is None else (inv[pins[0]], pins[1])
    wv, wf = (v, f) if num is None else (v[num.vertex], num.faces)
    seed = grow.seed_face(wv, wf, conn) if seed_face is None else int(seed_face if num is None
                                                                         else num.face_inverse[seed_face])
    with threadpool_limits(limits=1, user_api="blas"):
        # One BLAS thread: a sum split between threads rounds differently, and the
        # pattern must not depend on the machine's thread count.
        uv, extras = _engine(wv, wf, conn, seed, method, pins, lengths, progress, name, max_iterations=max_iterations,
                             tolerance=tolerance, min_stretch=min_stretch, energy=energy)
    loops = conn.loops
    if num is not None:  # back to the input's numbering
        uv, seed = np.ascontiguousarray(uv[num.vertex_inverse]), int(num.face[seed])
        loops = tuple(_readonly(num.vertex[loop]) for loop in loops)
    return Flattening(uv=_readonly(uv), vertices=_readonly(v), faces=_readonly(f), loops=loops, method=method,
                      seed_face=seed, overlap=overlap_verdict(f, uv, loops), **extras)


_SCATTERED = 0.25  # share of edges joining vertices more than n / 16 apart in the input's order
_RENUMBER_FROM = 50_000  # vertices: smaller meshes fit in cache whatever their order


def _working_mesh(vertices, faces, name):
    """``(v, f, numbering or None, connectivity)``: the validated input and the numbering the engine works in.

    A mesh whose edges mostly join vertices far apart in its own numbering
    (numbered at random, say: 88 % of its edges span more than a sixteenth of
    it, against none for a mesh numbered row by row or along its surface) is
    renumbered along a space-filling curve before anything else, so that
    validation, the growers and the relaxation read memory in order: their time
    then hardly depends on how the input was numbered.  Other meshes are used
    as they come, and so is any mesh under 50 000 vertices (it fits in cache in
    any order).  Refusals name the input's own vertices and faces.
    """
    v, f = as_mesh_arrays(vertices, faces, name=name)
    n = len(v)
    span = np.abs(f[:, [0, 1, 2]] - f[:, [1, 2, 0]])
    if n < _RENUMBER_FROM or np.mean(span > n // 16) <= _SCATTERED:
        _, _, conn = validate_mesh(v, f, name=name)
        return v, f, None, conn
    num = renumber(spatial_order(v), f)
    try:
        _, _, conn = validate_mesh(v[num.vertex], num.faces, name=name)
    except PatternsError:
        validate_mesh(v, f, name=name)  # the same refusal, naming the input's vertices and faces
        raise
    return v, f, num, conn


def _engine(v, f, conn, seed, method, pins, lengths, progress, name, **relax_options):
    """Flatten the canonically numbered mesh: ``(uv (n, 2), extra Flattening fields)``."""
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
        return _relaxed(v, f, conn, uv, z, pins, lengths, progress, **relax_options)
    # Beyond ~1e154 the flat triangles' areas overflow double precision: such a
    # result cannot even be checked, so it is an error, not an answer.
    with np.errstate(over="ignore", invalid="ignore"):
        overflow = not np.all(np.isfinite(signed_areas(f, uv)))
    if overflow:
        raise FlattenError(
            f"{name}: the {method} grower diverged (flat coordinates beyond double precision); "
            f"use method='isometric'"
        )
    return uv, {}


def _relaxed(v, f, conn, greedy, z, pins, lengths, progress, **options):
    """Pick a one-to-one start (greedy, else LSCM, else Tutte) and relax it: ``(uv, extra Flattening fields)``.

    The relaxation runs on the mesh renumbered in a nested-dissection order of
    the start (:mod:`patterns.flatten.numbering`): its time does not depend
    on the input's numbering, nor on the part's placement in space.
    """
    start, label, barrier = greedy, "greedy", 0.0
    if not overlap_verdict(f, start, conn.loops).one_to_one:
        start, label = lscm(v, f, conn, local=z), "lscm"
        if not overlap_verdict(f, start, conn.loops).one_to_one:
            start, label = tutte_embedding(v, f, conn), "tutte"
        # These layouts have no true scale of their own: start from the best one.
        start = start * best_scale(v, conn.edges, start)
        barrier = 0.1  # far from the answer: keep triangles open while it moves
    if pins is not None:
        start = align_to_pins(start, *pins)  # a rigid motion: still one-to-one
    elif lengths is None and label == "greedy" and is_isometric(v, f, start, local=z):
        # Already exact (a developable part): nothing to relax, renumber or factorise.
        return start, dict(start=label, iterations=0, converged=True,
                           energy="arap" if options["energy"] == "auto" else options["energy"])
    num = renumber(dissection_order(start, conn.edges), f)
    inv = num.vertex_inverse
    if pins is not None:
        pins = (inv[pins[0]], pins[1])
    if lengths is not None:
        lengths = (inv[lengths[0]], *lengths[1:])
    result = relax(v[num.vertex], num.faces, renumber_connectivity(conn, num), start[num.vertex], pins=pins,
                   lengths=lengths, barrier=barrier, progress=progress, local=z[num.face], **options)
    return np.array(result.uv[inv]), dict(start=label, iterations=result.iterations, converged=result.converged,
                                          energy=result.energy, length_error=result.length_error)


def flatten(model, *, method: str = "relaxed", exact: bool = True, thickness: float = 0.0, k_factor: float = 0.5,
            reference: str = "mid", grain=None, seams: str = "true", ease=None, max_strain: float | None = None,
            max_darts: int = 60, max_iterations: int = 500, tolerance: float = 1e-6, min_stretch: float | None = None,
            energy: str = "auto", progress=None):
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
    seams : {"true", "total", "free"}
        ``"true"`` (default): every seam edge of a freeform panel is held flat
        at its 3D length (``method="relaxed"``; :mod:`patterns.flatten.seams`),
        so that each seam is as long flat as in 3D and its two sides match
        point by point, also against an exactly developed neighbour.
        ``"total"``: only each seam side's total length is held (less strain;
        points along the seam may drift a few mm from their mate's).
        ``"free"``: the boundary takes the least-strain lengths (seams come
        out longer or shorter, and the two sides of a seam differ).
    ease : Ease or sequence of Ease, optional
        Deliberate extra (or less) length on one side of a seam
        (:class:`~patterns.flatten.seams.Ease`): that side is held at its 3D
        length times ``1 + ratio``, plus ``mm``.  An eased side of a planar,
        cylindrical or conical panel sends that panel through the engine.
    max_strain : float, optional
        Largest acceptable triangle strain (0.03 = 3 %).  A freeform panel that
        comes out above it is cut, one dart at a time, from the outline to its
        most strained point by the shortest path along its edges (the paper's
        "segmentation"), and flattened again, until it is within the limit or
        ``max_darts`` cuts are made (``patterns.check`` then reports it).
        Every cut is in :attr:`FlatPanel.darts`.
    max_darts : int
        At most this many darts per panel.
    max_iterations, tolerance, min_stretch, energy
        ``"relaxed"`` only; see :func:`flatten_mesh`.  The tolerance here is
        1e-6 (``flatten_mesh``: 1e-5): a pattern is relaxed to convergence.
    progress : callable, optional
        ``progress(panels_done, n_panels)`` after each panel.

    Returns
    -------
    patterns.Pattern
        One :class:`~patterns.FlatPanel` per panel (vertex ``i`` of the panel at
        ``uv[i]``), and each seam with its flat length on either side and the
        length it was held at.

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
    from .seams import SeamLengths, held_lengths, seam_mode, validate_ease

    if not isinstance(model, Model):
        raise InputError(f"flatten() takes a patterns.Model (from patterns.load), got {type(model).__name__}")
    if method not in METHODS:
        raise InputError(f"unknown flattening method {method!r}; choose one of {', '.join(METHODS)}")
    offset = neutral_offset(thickness, k_factor, reference, name=model.name)
    grains = _grain_table(grain, model)
    mode = seam_mode(seams)
    eased = validate_ease(ease, model)
    if eased and (mode is SeamLengths.FREE or method != "relaxed"):
        raise InputError(f"{model.name}: ease needs seams='true' or 'total' and method='relaxed'")
    if max_strain is not None:
        max_strain = check_number(max_strain, "max_strain", low=0, low_open=True, name=model.name)
    max_darts = check_number(max_darts, "max_darts", low=0, integer=True, name=model.name)
    eased_panels = {model.seams[s].panels[side] for s, side in eased}
    flat, targets = [], {}
    for i, panel in enumerate(model.panels):
        name = f"{model.name}: panel {panel.name}"
        darts = ()
        if exact and panel.surface is not None and i not in eased_panels:
            result = _developed(panel, offset, name)
        else:
            vertices = _offset_along_normals(panel, offset) if offset else panel.vertices
            held = None
            if method == "relaxed":
                held = held_lengths(model, i, vertices, eased, mode, mesh_edges=unique_edges(panel.faces))
            options = dict(method=method, max_iterations=max_iterations, tolerance=tolerance,
                           min_stretch=min_stretch, energy=energy, name=name)
            result = flatten_mesh(vertices, panel.faces, lengths=held, **options)
            if max_strain is not None:
                result, darts = _with_darts(result, max_strain, max_darts, held, options)
        targets.update(_side_targets(model, i, result, eased, mode))
        if panel.name in grains:
            result = _turn_to_grain(result, grains[panel.name])
        flat.append(FlatPanel(panel.name, panel, result, darts=darts))
        if progress is not None:
            progress(i + 1, len(model.panels))
    seams_out = []
    edges = [unique_edges(fp.faces) for fp in flat]  # once per panel, not per seam side
    for seam in model.seams:
        lengths = tuple(_flat_length(flat[p].flattening, edges[p], idx) for p, idx in zip(seam.panels, seam.vertices))
        held_at = tuple(targets.get((seam.id, side)) for side in range(2))
        seams_out.append(FlatSeam(seam, lengths, None if None in held_at else held_at))
    return Pattern(model=model, panels=tuple(flat), seams=tuple(seams_out), method=method,
                   thickness=float(thickness), k_factor=float(k_factor), reference=reference)


def _flat_length(result: Flattening, edges: np.ndarray, idx) -> float:
    """Flat length of a seam side given by its vertices, segment by segment along the mesh's ``edges``."""
    from .seams import seam_edges

    idx = np.asarray(idx, dtype=np.int64)
    pairs = seam_edges(result.vertices, edges, np.column_stack([idx[:-1], idx[1:]]))
    return float(np.linalg.norm(result.uv[pairs[:, 1]] - result.uv[pairs[:, 0]], axis=1).sum())


def _side_targets(model, panel: int, result: Flattening, eased: dict, mode) -> dict:
    """``{(seam id, side): flat length the side should have}`` for the seams of one flattened panel.

    The 3D length of the side's polyline (on the surface that was flattened)
    times its ease, where the length was held (seams "true") or kept by an
    exact development; nothing for a free seam.
    """
    from .seams import SeamLengths

    if mode is SeamLengths.FREE or result.method not in ("relaxed", "exact"):
        return {}
    out = {}
    for seam in model.seams_of(panel):
        for side, p in enumerate(seam.panels):
            if p == panel:
                pts = result.vertices[np.asarray(seam.vertices[side])]
                # 3D: the copies of a point coincide, so the polyline is measured as it is.
                length = float(np.linalg.norm(np.diff(pts, axis=0), axis=1).sum())
                out[(seam.id, side)] = length * eased.get((seam.id, side), 1.0)
    return out


_DART_SLACK = 1.05  # a dart is kept if the strain RMS after it is at most this times the lowest so far
_DART_REFUSALS = 4  # consecutive refused darts before the loop gives up


def _with_darts(result: Flattening, limit: float, max_darts: int, held, options: dict):
    """Cut darts into a flattening until its triangle strain is within ``limit``.

    Greedy: each round finds the vertices next to a triangle above the limit,
    takes the one deepest inside (farthest from the outline along the mesh),
    cuts along the shortest path of edges from the outline to it, and flattens
    again (``options``: those of :func:`flatten_mesh`; ``held``: the seam
    lengths, remapped onto each cut mesh).  A dart is kept only if the
    strain RMS after it (the relaxation's objective, which a cut can only
    lower at the optimum) is at most ``_DART_SLACK`` times the lowest so far;
    otherwise the cut is undone and the next deepest vertex is tried (after
    ``_DART_REFUSALS`` refusals in a row the loop stops).  Without that, one
    cut whose flaps overlap when laid flat (LSCM then overlaps, and the
    relaxation starts from Tutte's layout) sent every later round to
    50-300 % strain on a hemisphere.  The worst triangle strain is not the
    test: it moves about from cut to cut, and darts that raise it for a round
    are often what brings it down later.  Returns ``(flattening, darts)``.
    """
    from ..cut import cut_along
    from .seams import seam_edges

    darts = []
    lowest = _strain_rms(result)
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
        cut = cut_along(result.vertices, result.faces, path, name=options["name"])
        cut_held = None if held is None else (seam_edges(cut.vertices, unique_edges(cut.faces), held[0]), *held[1:])
        after = flatten_mesh(cut.vertices, cut.faces, lengths=cut_held, **options)
        rms = _strain_rms(after)
        if rms <= _DART_SLACK * lowest:
            darts.append(path)
            result, lowest, in_a_row, held = after, min(lowest, rms), 0, cut_held
            depths = _strained_depths(result, limit)
        else:
            refused.add(target)
            in_a_row += 1
    return result, tuple(np.asarray(d) for d in darts)


def _strain_rms(result: Flattening) -> float:
    """The area-weighted RMS of the principal strains of a flattening."""
    from ..measure import strain_rms

    return strain_rms(result.vertices, result.faces, result.uv)


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
