"""The mesh engine: :func:`flatten_mesh`, one triangle mesh to the plane at true scale.

The one-shot entry point: plain arrays in, a frozen :class:`Flattening` out.
The growers live in :mod:`patterns.flattening.grow`, the relaxation in
:mod:`patterns.flattening.relax`; this module picks the start and the
numbering the engine works in.
"""

from __future__ import annotations

import numpy as np
from threadpoolctl import threadpool_limits

from ..errors import FlattenError, InputError, PatternsError
from ..measure import local_coordinates, signed_areas
from ..mesh import _readonly, as_mesh_arrays, validate_mesh
from ..options import is_number
from ..pattern import Flattening
from ..predicates import overlap_verdict
from . import grow
from .embed import lscm, tutte_embedding
from .moves import align_to_pins, best_scale, check_lengths, check_pins
from .numbering import dissection_order, renumber, renumber_connectivity, spatial_order
from .relax import is_isometric, relax
from .settings import FlattenOptions

__all__ = ["flatten_mesh"]

def flatten_mesh(vertices, faces, *, method: str = "relaxed", seed_face: int | None = None,
                 pins=None, max_iterations: int = 500, energy_tolerance: float = 1e-5,
                 min_stretch: float | None = None, energy: str = "auto", lengths=None, start=None,
                 progress=None, name: str = "mesh") -> Flattening:
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
        :mod:`patterns.flattening.relax`.

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
    energy_tolerance : float
        ``"relaxed"`` only: stop when the energy falls by less than this
        fraction per iteration (averaged over two; >= 0).
    min_stretch : float in (0, 1), optional
        ``"relaxed"`` only: keep every triangle's smallest principal stretch
        near or above this (0.3 keeps each triangle at least about 30 % of its
        size in every direction): a guard that is zero until a triangle is
        squeezed that far.
    energy : {"auto", "arap", "hybrid", "symmetric-dirichlet"}
        ``"relaxed"`` only: the distortion minimised, each summed over the
        triangles weighted by their 3D area (:mod:`patterns.flattening.energy`).
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
    start : (n, 2) float, optional
        ``"relaxed"`` only: a one-to-one layout of this mesh to relax from
        instead of the grower's (the same panel's layout before a constraint
        was added: :mod:`patterns.flattening.darts` sews a dart's legs from
        the layout they fell into when cut).
    progress : callable, optional
        Called as ``progress(n_done, n_total)``: first ``progress(0, 1)`` as
        the flattening starts, then vertices placed by a grower (``n_done``
        at least 1), then iterations of the relaxation (from 1).
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
    # Cheap option checks, by the declarations patterns.flatten uses, before the
    # mesh is validated (a second at 1M faces).
    method = FlattenOptions.checked("method", method, where=name)
    if method != "relaxed":
        for option, value in (("pins", pins), ("min_stretch", min_stretch), ("lengths", lengths), ("start", start)):
            if value is not None:
                raise InputError(f"{name}: {option} applies to method='relaxed' only")
        if energy != "auto":
            raise InputError(f"{name}: energy applies to method='relaxed' only")
    min_stretch = FlattenOptions.checked("min_stretch", min_stretch, where=name)
    max_iterations = FlattenOptions.checked("max_iterations", max_iterations, where=name)
    energy_tolerance = FlattenOptions.checked("energy_tolerance", energy_tolerance, where=name)
    energy = FlattenOptions.checked("energy", energy, where=name)
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
    if start is not None:
        start = _check_start(start, v, f, conn, name)
        start = start if num is None else start[num.vertex]
    wv, wf = (v, f) if num is None else (v[num.vertex], num.faces)
    seed = grow.seed_face(wv, wf, conn) if seed_face is None else int(seed_face if num is None
                                                                         else num.face_inverse[seed_face])
    if progress is not None:
        progress(0, 1)  # a flattening starts (patterns.flattening.progress counts them by this)
    with threadpool_limits(limits=1, user_api="blas"):
        # One BLAS thread: a sum split between threads rounds differently, and the
        # pattern must not depend on the machine's thread count.
        uv, extras = _engine(wv, wf, conn, seed, method, pins, lengths, progress, name, start=start,
                             max_iterations=max_iterations,
                             tolerance=energy_tolerance, min_stretch=min_stretch, energy=energy)
    loops = conn.loops
    if num is not None:  # back to the input's numbering
        uv, seed = np.ascontiguousarray(uv[num.vertex_inverse]), int(num.face[seed])
        loops = tuple(_readonly(num.vertex[loop]) for loop in loops)
    return Flattening(uv=_readonly(uv), vertices=_readonly(v), faces=_readonly(f), loops=loops, method=method,
                      seed_face=seed, overlap=overlap_verdict(uv, f, loops), **extras)


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


def _check_start(start, v, f, conn, name) -> np.ndarray:
    """A given start layout as ``(n, 2) float64``, refused unless finite and one-to-one."""
    try:
        uv = np.asarray(start, dtype=np.float64)
    except (TypeError, ValueError):
        uv = np.zeros((0,))
    if uv.shape != (len(v), 2) or not np.isfinite(uv).all():
        raise InputError(f"{name}: start must be a finite ({len(v)}, 2) layout, got shape {uv.shape}")
    if not overlap_verdict(uv, f, conn.loops).one_to_one:
        raise InputError(f"{name}: start must be a one-to-one layout (no folded triangle, no crossing boundary)")
    return uv


def _engine(v, f, conn, seed, method, pins, lengths, progress, name, start=None, **relax_options):
    """Flatten the canonically numbered mesh: ``(uv (n, 2), extra Flattening fields)``."""
    z = local_coordinates(v, f)
    if start is not None:
        return _relaxed(v, f, conn, start, z, pins, lengths, progress, label="given", **relax_options)
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
        overflow = not np.all(np.isfinite(signed_areas(uv, f)))
    if overflow:
        raise FlattenError(
            f"{name}: the {method} grower diverged (flat coordinates beyond double precision); "
            f"use method='isometric'"
        )
    return uv, {}


def _relaxed(v, f, conn, greedy, z, pins, lengths, progress, label="greedy", **options):
    """Pick a one-to-one start (greedy, else LSCM, else Tutte) and relax it: ``(uv, extra Flattening fields)``.

    The relaxation runs on the mesh renumbered in a nested-dissection order of
    the start (:mod:`patterns.flattening.numbering`): its time does not depend
    on the input's numbering, nor on the part's placement in space.
    """
    start, barrier = greedy, 0.0
    if label == "greedy" and not overlap_verdict(start, f, conn.loops).one_to_one:
        start, label = lscm(v, f, conn, local=z), "lscm"
        if not overlap_verdict(start, f, conn.loops).one_to_one:
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


