"""A whole model flattened panel by panel: :func:`flatten` (a ``Model`` in, a ``Pattern`` out).

Each panel goes to its exact development (:mod:`patterns.flattening.develop`)
or to the mesh engine (:func:`patterns.flattening.engine.flatten_mesh`) with its
seams held (:mod:`patterns.flattening.seams`), is cut with darts where asked
(:mod:`patterns.flattening.darts`) and turned to its grain
(:mod:`patterns.flattening.grain`).
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..mesh import polyline_length, unique_edges
from ..model import Model
from ..pattern import FlatPanel, FlatSeam, Flattening, Pattern
from .darts import cut_darts, worst_strain
from .develop import developed, neutral_offset, offset_along_normals
from .engine import flatten_mesh
from .gores import gore_search, gored
from .grain import grain_table, turn_to_grain
from .inserts import is_saddle, slashed
from .parted import darts_needed, parting
from .progress import Bar
from .remedy import Flattener, PanelFlat, Remedy
from .seams import SeamLengths, held_lengths, seam_edges, validate_ease
from .settings import FlattenOptions

__all__ = ["flatten"]


def flatten(model, options: FlattenOptions | None = None, *, progress=None, **keywords) -> Pattern:
    """Lay every panel of a model flat at true scale.

    Parameters
    ----------
    model : patterns.Model
        From :func:`patterns.load`.
    options : FlattenOptions, optional
        The options as a record; keywords (any field of
        :class:`~patterns.FlattenOptions`) go over it:

        * ``method`` (``"relaxed"``): the mesh engine for freeform panels (see
          :func:`flatten_mesh`); ``exact`` (True): planar, cylindrical and
          conical CAD faces are unrolled analytically
          (:mod:`patterns.flattening.develop`: exact to round-off), their
          :attr:`Flattening.method` is ``"exact"``;
        * ``thickness`` (mm), ``k_factor``, ``reference`` (``"inside"``,
          ``"outside"``, ``"mid"``): a sheet's neutral surface is developed, at
          ``k_factor * thickness`` from the inside skin, offset towards the
          convex side of cylinders and cones, along the face normal on
          freeform faces;
        * ``grain``: a 3D direction (or ``{panel name: direction}``) turned to
          +Y on each flat panel (a rotation only);
        * ``seams`` (``"true"``): every seam edge of a freeform panel held flat
          at its 3D length (:mod:`patterns.flattening.seams`), so that each
          seam is as long flat as in 3D and its two sides match point by point;
          ``"total"``: each side's total length only; ``"free"``: the
          least-strain lengths;
        * ``ease``: :class:`~patterns.Ease` entries, deliberate extra (or less)
          length on one side of a seam;
        * ``max_strain``, ``max_darts`` (12): a freeform panel whose worst
          triangle is above the strain gets evenly spaced darts (at most
          ``max_darts``), their count and length first from the surface's
          curvature, then measured, their legs sewn to equal length
          (:mod:`patterns.flattening.darts`); they are in
          :attr:`FlatPanel.darts`, the search in :attr:`FlatPanel.dart_search`;
          a saddle-shaped panel is slashed instead, each slash's wedge an
          insert (:mod:`patterns.flattening.inserts`, at most ``max_darts``);
        * ``gores``, ``max_gores`` (24): with ``max_strain``, such a panel is
          split into the fewest gores (at most ``max_gores``) that each flatten
          within it, every cut a seam (:mod:`patterns.flattening.gores`; each
          piece's :attr:`Panel.gore_of` names the panel it was cut from);
          without ``gores``, a panel that ``max_darts`` darts cannot bring
          within the limit is parted into a few pieces with darts
          (:mod:`patterns.flattening.parted`), or else into gores, at most
          ``max_gores`` (0: darts on the one panel only);
        * ``max_iterations`` (500), ``energy_tolerance`` (1e-6; ``flatten_mesh``:
          1e-5, a pattern is relaxed to convergence), ``min_stretch``,
          ``energy`` (``"auto"``): the relaxation, see :func:`flatten_mesh`.
    progress : callable, optional
        ``progress(done, total)``: how far it is, ``done`` (float) of ``total`` (float: the model's panel
        count), never back; after each panel, and within one as its flattening's iterations go.  Where
        ``max_strain`` splits panels (parts and darts them, or gores), the first half of the bar is that
        search, a share per panel, moving with every flattening it makes (how many is not known before:
        ``k / (k + 1)`` of the share after ``k``); the second half the pieces.

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
    if not isinstance(model, Model):
        raise InputError(f"flatten() takes a patterns.Model (from patterns.load), got {type(model).__name__}")
    opts = FlattenOptions.of(options, keywords, name=model.name)
    method, max_strain, max_darts = opts.method, opts.max_strain, opts.max_darts
    offset = neutral_offset(opts.thickness, opts.k_factor, opts.reference, name=model.name)
    grain_table(opts.grain, model)  # bad grain or ease refused before any long work
    eased = validate_ease(opts.ease, model)
    mode = SeamLengths(opts.seams)
    darted = {}  # panel name -> Darted: darted while the panels were split
    bar = None if progress is None else Bar(progress, len(model.panels))
    first = 0.0  # where the panels' part of the bar starts
    if max_strain is not None:
        keep = {model.seams[s].panels[side] for s, side in eased}  # an eased seam's panel keeps its name
        first = len(model.panels) / 2
        model, darted = _split(model, opts, offset, keep, bar)
        eased = validate_ease(opts.ease, model)
    tick = None if bar is None else bar.engine
    grains = grain_table(opts.grain, model)
    eased_panels = {model.seams[s].panels[side] for s, side in eased}
    flat, targets = [], {}
    no_darts = {name for p in model.panels if p.insert_into is not None for name in (p.name, p.insert_into)}
    for i, panel in enumerate(model.panels):
        if bar is not None:
            share = (bar.total - first) / len(model.panels)
            bar.span(first + i * share, first + (i + 1) * share)
        darts, search = (), None
        if opts.exact and panel.surface is not None and i not in eased_panels:
            result = developed(panel, offset, f"{model.name}: panel {panel.name}")
        elif panel.name in darted:
            got = darted[panel.name]
            result, darts, search = got.flattening, got.darts, got.search
        else:
            start = _flat_panel(model, i, opts, offset, eased, tick=tick)
            result = start.flattening
            if max_strain is not None and not opts.gores and panel.name not in no_darts:  # slashed, or an insert
                got = cut_darts(result, max_strain, max_darts, start.held, start.options)
                result, darts, search = got.flattening, got.darts, got.search
        targets.update(_side_targets(model, i, result, eased, mode))
        if panel.name in grains:
            result = turn_to_grain(result, grains[panel.name])
        flat.append(FlatPanel(panel.name, panel, result, darts=darts, dart_search=search))
    if bar is not None:
        bar.finish()
    seams_out = []
    edges = [unique_edges(fp.faces) for fp in flat]  # once per panel, not per seam side
    for seam in model.seams:
        lengths = tuple(_flat_length(flat[p], edges[p], idx, seam) for p, idx in zip(seam.panels, seam.vertices))
        held_at = tuple(targets.get((seam.id, side)) for side in range(2))
        seams_out.append(FlatSeam(seam, lengths, None if held_at == (None, None) else held_at))
    return Pattern(model=model, panels=tuple(flat), seams=tuple(seams_out), method=method,
                   thickness=opts.thickness, k_factor=opts.k_factor, reference=opts.reference,
                   max_strain=opts.max_strain)


def _engine_options(opts: FlattenOptions, name: str) -> dict:
    """The keywords of :func:`flatten_mesh` that ``opts`` sets (darts and gores flatten with them too)."""
    return {"method": opts.method, "max_iterations": opts.max_iterations, "energy_tolerance": opts.energy_tolerance,
            "min_stretch": opts.min_stretch, "energy": opts.energy, "name": name}


def _flat_panel(model: Model, i: int, opts: FlattenOptions, offset: float, eased, *, tick=None) -> PanelFlat:
    """Panel ``i`` by the mesh engine (its neutral surface where ``offset``), its seams held as ``opts.seams``
    says (with the ``eased`` sides' ease), and the keywords of :func:`flatten_mesh` it was flattened with
    (``tick`` its ``progress``, kept for the flattenings of its darts and pieces)."""
    panel = model.panels[i]
    vertices = offset_along_normals(panel, offset) if offset else panel.vertices
    held = None
    if opts.method == "relaxed":
        held = held_lengths(model, i, vertices, eased, SeamLengths(opts.seams), mesh_edges=unique_edges(panel.faces))
    options = _engine_options(opts, f"{model.name}: panel {panel.name}")
    if tick is not None:
        options["progress"] = tick
    return PanelFlat(flatten_mesh(vertices, panel.faces, lengths=held, **options), held, options)


def _split(model: Model, opts: FlattenOptions, offset: float, keep: set, bar: Bar | None = None) -> tuple:
    """``max_strain``: every freeform panel above the limit split into gores (``gores=True``, :mod:`.gores`),
    or, if saddle-shaped, slashed and given inserts (:mod:`.inserts`), or else darted, and parted into pieces
    with darts where darts alone fall short (:func:`_darted`; not with ``max_gores`` 0: darted later).

    Panels are taken last to first, so that a split does not move the
    panels still to be looked at.  Returns the model and ``{panel name:
    Darted}`` of the panels darted here.  ``bar``: each panel's search fills
    its share of the bar's first half.
    """
    tick = None if bar is None else bar.engine

    def flat(m: Model, p: int) -> PanelFlat:  # a piece of a split panel, flattened as the panels are
        return _flat_panel(m, p, opts, offset, {}, tick=tick)

    darted = {}
    n = len(model.panels)
    for i in reversed(range(n)):
        if bar is not None:
            bar.span((n - 1 - i) / 2, (n - i) / 2)
        panel = model.panels[i]
        if (opts.exact and panel.surface is not None) or opts.method != "relaxed" or i in keep:
            continue
        saddle = is_saddle(panel.vertices, panel.faces, panel.loops)
        if not (opts.gores or saddle or opts.max_gores):
            continue
        start = _flat_panel(model, i, opts, offset, {}, tick=tick)
        if opts.gores:
            model = gored(model, i, start.flattening, opts.max_strain, opts.max_gores, flat, max_slashes=opts.max_darts)
        elif saddle:
            model = slashed(model, i, start.flattening, opts.max_strain, opts.max_darts, start.options)
        else:
            remedy = _darted(model, i, start, opts, flat)
            model = remedy.model
            darted.update(remedy.darted)
    return model, darted


def _darted(model: Model, i: int, start: PanelFlat, opts: FlattenOptions, flat: Flattener) -> Remedy:
    """Panel ``i`` (``start``: it flattened without darts; ``flat`` flattens a piece) darted whole, or, where
    darts alone fall short of the limit, parted into pieces with darts (:func:`.parted.parted`), or else cut
    into dartless gores (:func:`.gores.gore_search`): the first that meets the limit, or the one that came
    closest (on a tie, the one tried first: whole, parted, gores)."""
    result = start.flattening
    limit, max_darts, name = opts.max_strain, opts.max_darts, model.panels[i].name
    whole = None
    if worst_strain(result) <= limit or darts_needed(result, limit) <= max_darts:
        whole = cut_darts(result, limit, max_darts, start.held, start.options)
        if worst_strain(whole.flattening) <= limit:
            return Remedy(worst_strain(whole.flattening), model, {name: whole})
    pieces = parting(model, i, result, limit, max_darts, opts.max_gores, flat)  # stopped where it cannot meet it
    if pieces is not None and pieces.met is not None:
        return pieces.met
    gores = gore_search(model, i, result, limit, opts.max_gores, flat, max_slashes=max_darts)
    if gores is not None and gores.worst <= limit:
        return gores
    tries = [t for t in (None if pieces is None else pieces.closest(), gores) if t is not None]
    if whole is None:
        whole = cut_darts(result, limit, max_darts, start.held, start.options)
    tries.insert(0, Remedy(worst_strain(whole.flattening), model, {name: whole}))
    return min(tries, key=lambda t: t.worst)


def _flat_length(flat: FlatPanel, edges: np.ndarray, idx, seam) -> float:
    """Flat length of a seam side given by its vertices.

    A side of an exact development is measured on its true curve: the development is an isometry of the
    surface it unrolls, so the curve lies flat as long as it is on that surface -- the seam's exact (CAD)
    length, scaled by how much longer its polyline is on the neutral surface than on the skin when a
    thickness moved it there.  (The polyline through its points is shorter by the chords' sag, in 3D and
    flat alike, but not by the same amount: a cylinder's end arc lies flat as a straight line.)  Any other
    side is the flat polyline's length, segment by segment along the mesh's ``edges``.
    """
    result = flat.flattening
    idx = np.asarray(idx, dtype=np.int64)
    if result.method == "exact":
        skin = polyline_length(flat.panel.vertices[idx])
        return float(seam.length * (polyline_length(result.vertices[idx]) / skin if skin > 0 else 1.0))
    pairs = seam_edges(result.vertices, edges, np.column_stack([idx[:-1], idx[1:]]))
    return float(np.linalg.norm(result.uv[pairs[:, 1]] - result.uv[pairs[:, 0]], axis=1).sum())


def _side_targets(model, panel: int, result: Flattening, eased: dict, mode) -> dict:
    """``{(seam id, side): flat length the side should have}`` for the seams of one flattened panel.

    The 3D length of the side's polyline (on the surface that was flattened)
    times its ease, where the length was held (seams "true" or "total"); nothing
    for a free seam, nor for an exact development (an isometry: nothing is
    held, every length is kept).
    """
    if mode is SeamLengths.FREE or result.method != "relaxed":
        return {}
    out = {}
    for seam in model.seams_of(panel):
        for side, p in enumerate(seam.panels):
            if p == panel:
                pts = result.vertices[np.asarray(seam.vertices[side])]
                # 3D: the copies of a point coincide, so the polyline is measured as it is.
                length = polyline_length(pts)
                out[(seam.id, side)] = length * eased.get((seam.id, side), 1.0)
    return out
