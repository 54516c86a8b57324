"""Seam-true flattening: which flat lengths a panel's seams are held at.

A pattern is sewn, welded or laminated back together along its seams, so by
default :func:`patterns.flatten` holds every seam edge of every freeform
panel at its 3D length (a boundary-length constraint, as Boundary First
Flattening prescribes boundary lengths): each seam comes out flat as long as
it is in 3D, edge by edge, so that its two sides -- and the notches along
them -- match, whatever panel is on the other side.  ``seams="total"`` holds
only each side's total length (less strain; the sides are equally long but
points along them may drift apart), ``seams="free"`` nothing (least strain;
seams come out longer or shorter than in 3D).  :class:`Ease` asks for
deliberate extra (or less) length on one side of a seam.

Measured on the cup sample (a hemisphere in four gores; area-weighted
principal-strain RMS): free 2.31 %, seams 4.9 % too long; "total" 3.02 %
(1.31 x), the sides exact in length, a point along a seam up to 2.8 mm from
where a true-length mate has it; "true" 3.69 % (1.60 x), every edge exact.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

import numpy as np

from ..errors import InputError
from ..options import check_number, is_number

__all__ = ["Ease", "SeamLengths", "held_lengths", "seam_edges", "validate_ease"]


class SeamLengths(str, Enum):
    """How :func:`patterns.flatten` treats the flat length of seams (``seams=``)."""

    TRUE = "true"
    """Every seam edge flat at its 3D length (times its ease): seams sew back true, notches match."""
    TOTAL = "total"
    """Each seam side's total flat length at its 3D length (times its ease); the edges along it are free."""
    FREE = "free"
    """No length held: the boundary takes whatever length least strains the panel."""


@dataclass(frozen=True)
class Ease:
    """Deliberate extra length on one side of a seam, eased (gathered) in when sewn.

    The side's target flat length is ``L (1 + ratio) + mm``, ``L`` its 3D
    length, spread evenly along the seam; negative values make it shorter.

    Attributes
    ----------
    seam : int
        The seam's index (:attr:`patterns.Seam.id`).
    panel : str
        The panel whose side is eased (one of the seam's two panels).
    mm : float
        Extra length, mm.
    ratio : float
        Extra length as a fraction of the 3D length (0.02 = 2 %).
    """

    seam: int
    panel: str
    mm: float = 0.0
    ratio: float = 0.0


def validate_ease(ease, model) -> dict:
    """``{(seam id, side): factor}`` from ``flatten(ease=...)``; InputError on a bad entry.

    ``factor`` multiplies every 3D edge length of that side.
    """
    if ease is None:
        return {}
    if isinstance(ease, Ease):
        ease = (ease,)
    out = {}
    for item in ease:
        if not isinstance(item, Ease):
            raise InputError(f"{model.name}: ease takes patterns.Ease values, got {type(item).__name__}")
        if not (is_number(item.seam, integer=True) and 0 <= item.seam < len(model.seams)):
            raise InputError(f"{model.name}: ease names seam {item.seam!r}; the model has seams 0..{len(model.seams) - 1}")
        seam = model.seams[item.seam]
        names = [model.panels[p].name for p in seam.panels]
        if item.panel not in names:
            raise InputError(f"{model.name}: ease on seam {item.seam} names panel {item.panel!r}; "
                             f"the seam joins {names[0]!r} and {names[1]!r}")
        for label, x in (("mm", item.mm), ("ratio", item.ratio)):
            check_number(x, f"ease {label}", name=model.name)
        length = seam.polyline_length
        factor = 1.0 + float(item.ratio) + float(item.mm) / length
        if not 0.5 <= factor <= 2.0:
            raise InputError(f"{model.name}: ease on seam {item.seam} makes it {factor:.3g} times its 3D length; "
                             f"ease takes 0.5 to 2")
        sides = [k for k, p in enumerate(seam.panels) if model.panels[p].name == item.panel]
        for side in sides[:1] if seam.closes_panel else sides:
            if (item.seam, side) in out:
                raise InputError(f"{model.name}: ease given twice for seam {item.seam}, panel {item.panel!r}")
            out[(item.seam, side)] = factor
    return out


def held_lengths(model, panel: int, vertices: np.ndarray, ease: dict, mode: SeamLengths = SeamLengths.TRUE, *,
                 mesh_edges: np.ndarray):
    """The seam edges of one panel and the flat lengths to hold them at.

    Parameters
    ----------
    model : patterns.Model
    panel : int
        Index of the panel.
    vertices : (n, 3) float64, mm
        The panel's vertices as flattened (moved to the neutral surface when
        there is a thickness): the targets are their 3D edge lengths.
    ease : dict
        From :func:`validate_ease`.
    mode : SeamLengths
        ``TRUE``: every edge held; ``TOTAL``: each seam side held in total.
    mesh_edges : (e, 2) int64
        The panel mesh's unique edges (:func:`seam_edges`).

    Returns
    -------
    ((k, 2) int64, (k,) float64, (k,) int64) or None
        Edges (vertex pairs of the panel), target lengths (mm) and groups
        (edges held together, in total: one per edge for ``TRUE``, one per
        seam side for ``TOTAL``); None when the panel has no seam or the
        mode holds nothing.
    """
    if mode is SeamLengths.FREE:
        return None
    edges, targets, groups = [], [], []
    for seam in model.seams_of(panel):
        for side, p in enumerate(seam.panels):
            if p != panel:
                continue
            idx = np.asarray(seam.vertices[side], dtype=np.int64)
            pairs = seam_edges(vertices, mesh_edges, np.column_stack([idx[:-1], idx[1:]]))
            length = np.linalg.norm(vertices[pairs[:, 1]] - vertices[pairs[:, 0]], axis=1)
            edges.append(pairs)
            targets.append(length * ease.get((seam.id, side), 1.0))
            groups.append(np.full(len(pairs), len(groups)))
    if not edges:
        return None
    edges, targets, groups = np.concatenate(edges), np.concatenate(targets), np.concatenate(groups)
    # A seam closing one panel on itself, or two seams meeting, may name an edge twice: keep it once.
    _, first = np.unique(np.sort(edges, axis=1), axis=0, return_index=True)
    first = np.sort(first)
    edges, targets, groups = edges[first], targets[first], groups[first]
    if mode is SeamLengths.TRUE:
        groups = np.arange(len(edges))
    else:
        groups = np.unique(groups, return_inverse=True)[1]
    return edges, targets, groups


def seam_edges(vertices: np.ndarray, edges: np.ndarray, pairs: np.ndarray) -> np.ndarray:
    """``pairs`` ``(k, 2)`` of consecutive seam vertices, each made an edge of the mesh.

    Where a panel was cut open (a group of faces closing into a tube, or a
    dart starting on a seam) the cut's end point has one copy per side, and a
    seam through it names one copy for both of its segments.  Such a pair is
    moved to the copies -- vertices at exactly the same 3D point -- that the
    mesh joins by an edge.

    Parameters
    ----------
    vertices : (n, 3) float64
    edges : (e, 2) int64
        The mesh's unique edges, ``edges[:, 0] < edges[:, 1]``.
    pairs : (k, 2) int64

    Returns
    -------
    (k, 2) int64
        Each row an edge of the mesh where one exists among the copies (else
        unchanged).
    """
    n = len(vertices)
    key = edges[:, 0] * n + edges[:, 1]
    lo, hi = np.minimum(pairs[:, 0], pairs[:, 1]), np.maximum(pairs[:, 0], pairs[:, 1])
    missing = np.flatnonzero(~np.isin(lo * n + hi, key))
    if not len(missing):
        return pairs
    # Copies of a point: vertices with bit-identical coordinates.
    _, group = np.unique(vertices, axis=0, return_inverse=True)
    group = group.ravel()
    members = {}
    for i in np.unique(pairs[missing]):
        members[int(i)] = np.flatnonzero(group == group[i]).tolist()
    present = set(key.tolist())
    out = pairs.copy()
    for row in missing.tolist():
        a, b = (int(x) for x in pairs[row])
        found = next(((x, y) for x in members[a] for y in members[b] if min(x, y) * n + max(x, y) in present), None)
        if found is not None:
            out[row] = found
    return out
