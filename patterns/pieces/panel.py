"""A flattened panel as a piece: its cut line (seam allowance and all), notches, marks and seam sides.

:func:`panel_piece` is where a pattern's panel becomes what a cutter cuts: the
seam line (the flattened outline) offset by each edge's seam allowance
(:mod:`~patterns.pieces.allowance`), straight runs drawn as one segment, arcs
fitted where asked (:func:`~patterns.pieces.arcs.fit_arcs`), the notches and
drill holes (:mod:`~patterns.pieces.notches`), a grain line, the rulings of a
rolled panel as bend lines, and each seam side with its lengths, for its label.
The piece lies where the panel lies (``FlatPanel.uv``).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
import shapely

from ..curves import Loop
from ..findings import Finding
from ..measure import strain_stats, triangle_strains
from ..mesh import extent
from ..pattern import FlatPanel, Pattern
from ..text import printable
from .allowance import allowance_outline, snap, straight_runs
from .arcs import fit_arcs
from .notches import drill_holes, notches, runs_along_loop, v_mouth
from .options import PieceOptions
from .piece import BendLine, Notch, Piece, SeamSide, Source, StrainMap

__all__ = ["panel_piece", "strain_title", "text_height_for"]


def text_height_for(size: float, text_height: float | None) -> float:
    """The label height of a piece ``size`` mm across: ``text_height`` if given, else 3 % of it, 2-12 mm."""
    return text_height if text_height else float(np.clip(0.03 * size, 2.0, 12.0))


def strain_title(stats) -> str:
    """``STRAIN RMS 0.65% MAX 1.57%``: the report's numbers, as a piece's label says them."""
    return f"STRAIN RMS {100 * stats.rms:.2f}% MAX {100 * stats.max:.2f}%"


@dataclass(frozen=True, eq=False)
class _Geometry:
    """The flat geometry of one panel that its marks are made from (mm, where the panel lies)."""

    index: int
    uv: np.ndarray
    seam_loops: list
    cut_loops: list
    polygon: shapely.Polygon
    label_at: np.ndarray
    text_height: float


def _segment_seams(pattern: Pattern, index: int) -> dict:
    """``(vertex a, vertex b) -> seam id`` for the boundary segments of panel ``index`` on a seam
    (a copy's are its source's)."""
    out = {}
    source = pattern.source_of(index)
    for fs in pattern.seams:
        seam = fs.seam
        for p, idx in zip(seam.panels, seam.vertices):
            if p == source:
                for a, b in itertools.pairwise(idx):
                    out[(int(a), int(b))] = seam.id
    return out


def _geometry(pattern: Pattern, index: int, allowance_of, options: PieceOptions) -> tuple:
    """``(_Geometry, allowance drawn)``: the seam and cut loops of one panel."""
    flat = pattern.panels[index]
    uv = np.asarray(flat.uv)
    seam_loops = [uv[loop] for loop in flat.loops]
    seam_of = _segment_seams(pattern, index)
    per_segment = []
    for loop in flat.loops:
        ids = [seam_of.get((int(a), int(b)), seam_of.get((int(b), int(a)))) for a, b in zip(loop, np.roll(loop, -1))]
        per_segment.append(np.array([allowance_of(i) for i in ids]))
    has_allowance = any(np.any(a > 0) for a in per_segment)
    polygon = shapely.Polygon(seam_loops[0], seam_loops[1:])
    if has_allowance:
        cut = allowance_outline(polygon, seam_loops, per_segment, options.seam_corners,
                                mitre_limit=options.mitre_limit)
        cut_loops = [np.asarray(cut.exterior.coords)[:-1]] + [np.asarray(r.coords)[:-1] for r in cut.interiors]
    else:
        cut_loops = seam_loops
    cut_loops = [straight_runs(snap(loop)) for loop in cut_loops]
    label_at = shapely.get_coordinates(shapely.point_on_surface(polygon))[0]
    height = text_height_for(extent(seam_loops[0]), options.text_height)
    return _Geometry(index, uv, seam_loops, cut_loops, polygon, label_at, height), has_allowance


def _seam_sides(pattern: Pattern, geo: _Geometry) -> tuple:
    """Every seam side on the panel, its line with the panel to its left."""
    flat = pattern.panels[geo.index]
    source = pattern.source_of(geo.index)
    out = []
    for fs in pattern.seams:
        seam = fs.seam
        for side, (p, idx) in enumerate(zip(seam.panels, seam.vertices)):
            if p != source:
                continue
            pts = geo.uv[idx]
            if runs_along_loop(flat.loops, idx) < 0:
                pts = pts[::-1]
            out.append(SeamSide(seam.id, side, float(fs.length), float(fs.flat_lengths[side]), pts))
    return tuple(out)


def _grain_line(geo: _Geometry) -> np.ndarray:
    """A grain line along the flat +v axis, beside the labels where there is room.

    (Until a grain direction is given, the flat +v axis is the grain.)
    """
    lo, hi = geo.uv.min(axis=0), geo.uv.max(axis=0)
    h = 0.3 * (hi[1] - lo[1])
    for dx in (12.0, -12.0, 0.0):
        base = geo.label_at + np.array([dx * geo.text_height, -0.5 * h])
        if shapely.contains_xy(geo.polygon, *base) and shapely.contains_xy(geo.polygon, *(base + [0.0, h])):
            break
    return np.array([base, base + [0.0, h]])


def _loop(points: np.ndarray, options: PieceOptions) -> Loop:
    if options.arcs:
        return Loop.of_vertices(fit_arcs(np.asarray(points), options.arc_tolerance))
    return Loop.of_points(points)


def panel_piece(pattern: Pattern, index: int, allowance_of, options: PieceOptions,
                findings: tuple[Finding, ...] = ()) -> Piece:
    """The piece of panel ``index`` of ``pattern``.

    Parameters
    ----------
    pattern : patterns.Pattern
    index : int
    allowance_of : callable
        ``allowance_of(seam id or None) -> mm`` (:func:`~patterns.pieces.allowance.allowance_lookup`).
    options : PieceOptions
    findings : tuple of patterns.Finding
        The check's findings about this panel (they travel with the piece).
    """
    flat: FlatPanel = pattern.panels[index]
    geo, has_allowance = _geometry(pattern, index, allowance_of, options)
    marks = []
    for start, inward, depth in notches(pattern, geo, allowance_of, options.notch_spacing):
        mouth = np.array(v_mouth(geo, start, depth)) if options.notch_style == "v" else None
        marks.append(Notch(start, inward, depth, mouth))
    bends = () if options.bend_spacing is None else tuple(
        BendLine(np.array([a, b]), turn) for a, b, turn in flat.rulings(options.bend_spacing))
    stats = strain_stats(flat.strains)  # the same numbers as patterns.check's report
    strain_map = None
    if options.strain_layer:
        s = triangle_strains(flat.vertices, flat.faces, flat.flattening.uv).dominant
        strain_map = StrainMap(geo.uv[flat.faces], s)
    cad_faces = tuple(int(f) for f in flat.panel.cad_faces)
    return Piece(
        name=printable(flat.name), outline=_loop(geo.cut_loops[0], options),
        holes=tuple(_loop(loop, options) for loop in geo.cut_loops[1:]), sew=tuple(geo.seam_loops),
        allowance=has_allowance, notches=tuple(marks), drills=drill_holes(flat, geo), grain=_grain_line(geo),
        bends=bends, seams=_seam_sides(pattern, geo), title=(strain_title(stats),), text_height=geo.text_height,
        label_at=geo.label_at, source=Source("panel", pattern.name, pattern.source_of(index), cad_faces),
        strain=stats, findings=tuple(f for f in findings if flat.name in f.panels), strain_map=strain_map)
