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
from ..mesh import unique_edges
from ..model import Model
from ..options import check_number
from ..pattern import FlatPanel, FlatSeam, Pattern
from .darts import cut_darts
from .develop import developed, neutral_offset, offset_along_normals
from .engine import METHODS, Flattening, flatten_mesh
from .grain import grain_table, turn_to_grain
from .seams import SeamLengths, held_lengths, seam_edges, seam_mode, validate_ease

__all__ = ["flatten"]


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
        (:mod:`patterns.flattening.develop`: exact to round-off, no mesh engine);
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
        at its 3D length (``method="relaxed"``; :mod:`patterns.flattening.seams`),
        so that each seam is as long flat as in 3D and its two sides match
        point by point, also against an exactly developed neighbour.
        ``"total"``: only each seam side's total length is held (less strain;
        points along the seam may drift a few mm from their mate's).
        ``"free"``: the boundary takes the least-strain lengths (seams come
        out longer or shorter, and the two sides of a seam differ).
    ease : Ease or sequence of Ease, optional
        Deliberate extra (or less) length on one side of a seam
        (:class:`~patterns.flattening.seams.Ease`): that side is held at its 3D
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
    if not isinstance(model, Model):
        raise InputError(f"flatten() takes a patterns.Model (from patterns.load), got {type(model).__name__}")
    if method not in METHODS:
        raise InputError(f"unknown flattening method {method!r}; choose one of {', '.join(METHODS)}")
    offset = neutral_offset(thickness, k_factor, reference, name=model.name)
    grains = grain_table(grain, model)
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
            result = developed(panel, offset, name)
        else:
            vertices = offset_along_normals(panel, offset) if offset else panel.vertices
            held = None
            if method == "relaxed":
                held = held_lengths(model, i, vertices, eased, mode, mesh_edges=unique_edges(panel.faces))
            options = dict(method=method, max_iterations=max_iterations, tolerance=tolerance,
                           min_stretch=min_stretch, energy=energy, name=name)
            result = flatten_mesh(vertices, panel.faces, lengths=held, **options)
            if max_strain is not None:
                result, darts = cut_darts(result, max_strain, max_darts, held, options)
        targets.update(_side_targets(model, i, result, eased, mode))
        if panel.name in grains:
            result = turn_to_grain(result, grains[panel.name])
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
    idx = np.asarray(idx, dtype=np.int64)
    pairs = seam_edges(result.vertices, edges, np.column_stack([idx[:-1], idx[1:]]))
    return float(np.linalg.norm(result.uv[pairs[:, 1]] - result.uv[pairs[:, 0]], axis=1).sum())


def _side_targets(model, panel: int, result: Flattening, eased: dict, mode) -> dict:
    """``{(seam id, side): flat length the side should have}`` for the seams of one flattened panel.

    The 3D length of the side's polyline (on the surface that was flattened)
    times its ease, where the length was held (seams "true") or kept by an
    exact development; nothing for a free seam.
    """
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
