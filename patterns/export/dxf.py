"""DXF output with ezdxf.

:func:`write_outline_dxf` writes the cut contours of a flat pattern: each
boundary loop one closed polyline on layer ``CUT``, z = 0, true scale, units
declared in the header.
"""

from __future__ import annotations

import logging
import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import shapely
from shapely.geometry.polygon import orient

from ..errors import InputError
from ..files import atomic_output, output_target
from ..measure import strain_stats, triangle_strains
from ..mesh import polyline_arc
from ..options import Options, check_number, is_number, option
from ..text import printable
from ..units import UNIT_NAMES, Unit
from .arcs import fit_arcs
from .heatmap import display_offsets
from .labels import LabelPlacer, along

__all__ = ["ASTM_LAYERS", "MACHINE_LAYERS", "MACHINE_VERSIONS", "MAX_MARKS", "PROFILES", "DxfOptions", "check_marks",
           "seam_label", "write_outline_dxf", "write_pattern_dxf"]


def write_outline_dxf(path, loops: Sequence[np.ndarray], *, units: str = "mm", layer: str = "CUT") -> None:
    """Write closed flat loops as one closed polyline each.

    Parameters
    ----------
    path : str or Path
        The DXF file to write (replaced atomically).
    loops : sequence of (k, 2) float64
        Flat loops, in ``units``, not repeating the first point at the end.
    units : {"mm", "cm", "m", "in"}
        The unit the coordinates are in, declared in ``$INSUNITS``.
    layer : str
        Layer of the contours.

    Raises
    ------
    InputError
        Unknown unit, or a loop with fewer than 3 points or non-finite values.
    ExportError
        The file cannot be written.
    """
    import ezdxf  # heavy; only when exporting

    if units not in UNIT_NAMES:
        raise InputError(f"{path}: unknown unit {units!r}; choose one of {', '.join(UNIT_NAMES)}")
    for i, loop in enumerate(loops):
        loop = np.asarray(loop)
        if loop.ndim != 2 or loop.shape[1] != 2 or len(loop) < 3 or not np.all(np.isfinite(loop)):
            raise InputError(f"{path}: loop {i} is not a finite (k >= 3, 2) array")
    doc = ezdxf.new("R2000", setup=False)
    doc.header["$INSUNITS"] = Unit(units).insunits
    doc.header["$MEASUREMENT"] = Unit(units).measurement
    doc.layers.add(layer, color=1)
    msp = doc.modelspace()
    for loop in loops:
        msp.add_lwpolyline(np.asarray(loop, dtype=np.float64).tolist(), close=True, dxfattribs={"layer": layer})
    with atomic_output(path, what="DXF file") as tmp:
        _save(doc, tmp)


# --------------------------------------------------------------------------- #
# Whole patterns: machine and ASTM D6673 profiles
# --------------------------------------------------------------------------- #

PROFILES = ("machine", "astm")
"""DXF dialects :func:`write_pattern_dxf` writes."""

NOTCH_STYLES = ("slit", "v")
"""Notch shapes: a slit across the seam allowance, or a V."""

SEAM_CORNERS = ("mitre", "square")
"""Corners of the seam allowance."""

MACHINE_VERSIONS = {"R12": "AC1009", "R2000": "AC1015", "R2004": "AC1018", "R2007": "AC1021",
                    "R2010": "AC1024", "R2013": "AC1027", "R2018": "AC1032"}
"""DXF versions the machine profile writes, and their ``$ACADVER``."""


MAX_SEAM_ALLOWANCE = 1000.0
"""The largest seam allowance, mm: a metre of cloth or sheet outside the seam line is not an allowance."""


def _seam_allowance(value, option):
    """A number (mm, 0..1000) or a mapping ``{seam id or None: mm}``, checked (seam ids against the pattern later)."""
    if hasattr(value, "items"):
        return {key: check_number(mm, f"{option}[{key!r}] (mm)", low=0, high=MAX_SEAM_ALLOWANCE)
                for key, mm in value.items()}
    if is_number(value):
        return check_number(value, f"{option} (mm)", low=0, high=MAX_SEAM_ALLOWANCE)
    raise InputError(f"{option} must be a number (mm) or a mapping of seam ids to mm, got {type(value).__name__}")


@dataclass(frozen=True, repr=False)
class DxfOptions(Options):
    """How a pattern is written as DXF (:meth:`patterns.Pattern.to_dxf`, ``patterns flatten -o X.dxf``)."""

    profile: str = option("machine", "DXF dialect: machine (laser, plasma, waterjet, knife plotter: layers CUT, "
                                     "SEW, NOTCH, GRAIN, BEND, LABEL) or astm (garment CAD: ASTM D6673, R12, one "
                                     "block per piece); see docs/dxf.md", choices=PROFILES)
    seam_allowance: float | dict = option(0.0, "seam allowance added outside the seam line, mm: one number for every "
                                         "edge, or (API) a mapping {seam id: mm, None: mm for every other edge}; "
                                         "the seam line then goes on SEW (ASTM layer 14)",
                                    check=_seam_allowance, parse=float, unit="mm")
    units: str = option("mm", "unit of the drawing (machine profile; ASTM is mm); also, on the command line, "
                              "the unit of a mesh file's coordinates", choices=UNIT_NAMES)
    version: str | None = option(None, "machine profile: DXF version (default R2000; ASTM is R12)",
                                 choices=tuple(MACHINE_VERSIONS), flag="--dxf-version", optional=True)
    strain_layer: bool = option(False, "machine profile: the strain heat map as filled triangles on layer STRAIN "
                                       "(true colour from R2004)")
    text_height: float | None = option(None, "label height, mm (default 3 % of each panel's size, 2-12 mm)",
                                       low=0, low_open=True, optional=True, unit="mm")
    gap: float | None = option(None, "space between panels when the pattern is not laid out, mm",
                               low=0, optional=True, unit="mm")
    arcs: bool = option(False, "machine profile: cut contours as arcs and lines fitted within arc_tolerance")
    arc_tolerance: float = option(0.01, "largest distance of the fitted arcs from the contour, mm",
                                  low=0, low_open=True, unit="mm")
    bend_spacing: float | None = option(None, "draw the rulings of exactly developed cylinders and cones about "
                                              "this far apart (mm) on BEND with their bend angles",
                                        low=0, low_open=True, optional=True, unit="mm")
    notch_spacing: float | None = option(None, "matching notches along every seam every this many mm of 3D "
                                               "length, on both panels (default: at the seam ends only)",
                                         low=0, low_open=True, optional=True, unit="mm")
    notch_style: str = option("slit", "notch shape: a slit across the seam allowance, or a V", choices=NOTCH_STYLES)
    seam_corners: str = option("mitre", "corners of the seam allowance: offset lines meeting at a point (mitre), "
                                        "or each side's allowance run straight on past the corner (square)",
                               choices=SEAM_CORNERS)

    def __post_init__(self):
        super().__post_init__()
        if self.profile == "astm":
            if self.version not in (None, "R12"):
                raise InputError(f"the ASTM profile is written as R12 only, not {self.version!r}")
            if self.units != "mm":
                raise InputError("the ASTM profile is written in mm (METRIC) only")
            if self.arcs:
                raise InputError("arcs are written in the machine profile only")

MACHINE_LAYERS = {
    "CUT": 1,  # red: every cut contour, one closed polyline each
    "SEW": 5,  # blue: the seam line, when a seam allowance is added
    "NOTCH": 6,  # magenta: notch marks at seam ends
    "GRAIN": 3,  # green: grain line
    "BEND": 2,  # yellow: bend and ruling lines (sheet metal)
    "DRILL": 4,  # cyan: drill holes (POINT), at dart tips
    "LABEL": 7,  # white/black: every text
    "STRAIN": 8,  # grey: optional strain heat map (filled triangles)
    "STOCK": 9,  # light grey: the roll's edges or the sheets, once nested (never cut)
}
"""Layers of the machine profile and their colours (AutoCAD colour index)."""

ASTM_LAYERS = {1: "cut line, piece text", 2: "turn points", 3: "curve points", 4: "notches", 7: "grain line",
               8: "internal lines", 11: "internal cut-outs", 13: "drill holes", 14: "sew line", 15: "annotation"}
"""Layers of the ASTM D6673 profile."""


class _PanelGeometry:
    """Flat geometry of one panel as it goes into the file (mm, placed)."""

    def __init__(self, pattern, index, offset, allowances, text_height, corners):

        flat = pattern.panels[index]
        self.name = printable(flat.name)  # names are data: no control character reaches the file
        self.index = index
        uv = np.asarray(flat.uv) + offset
        self.uv = uv
        self.seam_loops = [uv[loop] for loop in flat.loops]
        seam_of = _segment_seams(pattern, index)
        per_segment = []
        for loop in flat.loops:
            ids = [seam_of.get((int(a), int(b)), seam_of.get((int(b), int(a)))) for a, b in
                   zip(loop, np.roll(loop, -1))]
            per_segment.append(np.array([allowances(i) for i in ids]))
        self.allowance = per_segment
        self.has_allowance = any(np.any(a > 0) for a in per_segment)
        polygon = shapely.Polygon(self.seam_loops[0], self.seam_loops[1:])
        self.polygon = polygon
        if self.has_allowance:
            cut = _allowance_outline(polygon, self.seam_loops, per_segment, corners)
            self.cut_loops = [np.asarray(cut.exterior.coords)[:-1]] + [np.asarray(r.coords)[:-1] for r in cut.interiors]
        else:
            self.cut_loops = self.seam_loops
        self.cut_loops = [_straight_runs(_snap(loop)) for loop in self.cut_loops]
        inside = shapely.get_coordinates(shapely.point_on_surface(polygon))[0]
        self.label_at = inside
        box = np.ptp(self.seam_loops[0], axis=0)
        self.text_height = text_height if text_height else float(np.clip(0.03 * box.max(), 2.0, 12.0))

        stats = strain_stats(flat.strains)  # the same numbers as patterns.check's report
        self.strain_rms, self.strain_max = stats.rms, stats.max
        self.box = np.r_[uv.min(axis=0), uv.max(axis=0)]


def _segment_seams(pattern, index) -> dict:
    """``(vertex a, vertex b) -> seam id`` for the boundary segments of panel ``index`` on a seam
    (a copy's are its source's)."""
    out = {}
    source = pattern.source_of(index)
    for fs in pattern.seams:
        seam = fs.seam
        for p, idx in zip(seam.panels, seam.vertices):
            if p == source:
                for a, b in zip(idx[:-1], idx[1:]):
                    out[(int(a), int(b))] = seam.id
    return out


def _allowance_outline(polygon, loops, per_segment, corners):
    """The cut outline: the seam line offset outwards by each segment's allowance.

    ``corners="mitre"``: offset lines meet at a point (mitre limit 4).
    ``"square"``: at every sharp corner (turning by more than 30 degrees
    towards the material's outside) each side's allowance is run straight on
    past the corner by its own width, so the corner is squared off.
    """

    values = np.concatenate(per_segment)
    base = float(values.min())
    if corners == "square":
        return _square_allowance(polygon, loops, per_segment)
    cut = polygon.buffer(base, join_style="mitre", mitre_limit=4.0) if base > 0 else polygon
    parts = [cut]
    for loop, allow in zip(loops, per_segment):
        if np.all(allow == base):
            continue
        # Runs of segments with the same larger allowance, buffered on their
        # outer (right-hand) side: the material lies to the left of every loop.
        n = len(loop)
        change = np.flatnonzero(allow != np.roll(allow, 1))
        starts = change if len(change) else np.array([0])
        for k, s in enumerate(starts):
            e = starts[(k + 1) % len(starts)] if len(starts) > 1 else s + n
            if e <= s:
                e += n
            a = float(allow[s % n])
            if a <= base:
                continue
            idx = np.arange(s, e + 1) % n
            line = shapely.LineString(loop[idx])
            parts.append(shapely.buffer(line, -a, single_sided=True, join_style="mitre", cap_style="flat",
                                        mitre_limit=4.0))
    out = shapely.union_all(parts)
    if out.geom_type != "Polygon":
        out = max(getattr(out, "geoms", [out]), key=lambda g: g.area)
    return shapely.orient_polygons(out) if hasattr(shapely, "orient_polygons") else _orient(out)


def _square_allowance(polygon, loops, per_segment):
    """Allowance with squared corners: each run between sharp corners offset on its own, extended."""

    parts = [polygon]
    for loop, allow in zip(loops, per_segment):
        n = len(loop)
        a_vec = loop - np.roll(loop, 1, axis=0)
        b_vec = np.roll(loop, -1, axis=0) - loop
        turn = np.arctan2(a_vec[:, 0] * b_vec[:, 1] - a_vec[:, 1] * b_vec[:, 0], (a_vec * b_vec).sum(axis=1))
        # Corners: sharp turns, and where the allowance changes.
        cut_at = np.flatnonzero((np.abs(turn) > np.radians(30)) | (allow != np.roll(allow, 1)))
        if not len(cut_at):
            cut_at = np.array([0])
        for k, s in enumerate(cut_at):
            e = cut_at[(k + 1) % len(cut_at)]
            if e <= s:
                e += n
            a = float(allow[s % n])
            if a <= 0:
                continue
            run = loop[np.arange(s, e + 1) % n].copy()
            # Run straight on past a convex corner (the material on the left turns left there).
            if turn[s % n] > np.radians(30):
                t = run[0] - run[1]
                run = np.vstack([run[0] + a * t / np.linalg.norm(t), run])
            if turn[e % n] > np.radians(30):
                t = run[-1] - run[-2]
                run = np.vstack([run, run[-1] + a * t / np.linalg.norm(t)])
            parts.append(shapely.buffer(shapely.LineString(run), -a, single_sided=True, join_style="mitre",
                                        cap_style="flat", mitre_limit=4.0))
    out = shapely.union_all(parts)
    if out.geom_type != "Polygon":
        out = max(getattr(out, "geoms", [out]), key=lambda g: g.area)
    # Holes of the panel shrink by their allowance: take the holes of the union.
    return shapely.orient_polygons(out) if hasattr(shapely, "orient_polygons") else _orient(out)


def _snap(loop: np.ndarray, tol: float = 1e-6) -> np.ndarray:
    """Drop points closer than ``tol`` mm to the previous one (a closed loop: also last to first)."""
    loop = np.asarray(loop, dtype=np.float64)
    keep = np.ones(len(loop), dtype=bool)
    d = np.linalg.norm(np.diff(loop, axis=0), axis=1)
    keep[1:] = d > tol
    loop = loop[keep]
    if len(loop) > 3 and np.linalg.norm(loop[-1] - loop[0]) <= tol:
        loop = loop[:-1]
    return loop


STRAIGHT = 0.001
"""A point within this (mm) of the line through its neighbours is dropped: a straight run is one segment."""


def _straight_runs(loop: np.ndarray, tolerance: float = STRAIGHT) -> np.ndarray:
    """A closed loop (k, 2) with the points of its straight runs dropped (Douglas-Peucker within ``tolerance``)."""
    simple = shapely.simplify(shapely.LinearRing(loop), tolerance, preserve_topology=True)
    pts = np.asarray(simple.coords)[:-1]
    return pts if len(pts) >= 3 else np.asarray(loop)


def _allowance_lookup(seam_allowance, seam_ids, path):
    """A function ``seam id or None -> allowance, mm`` from a checked number or mapping (:class:`DxfOptions`)."""
    if not isinstance(seam_allowance, dict):
        return lambda seam: seam_allowance
    for key in seam_allowance:
        if key is not None and key not in seam_ids:
            raise InputError(f"{path}: seam_allowance names seam {key!r}, which the pattern does not have "
                             f"(seams {sorted(seam_ids)}; None for every other edge)")
    default = seam_allowance.get(None, 0.0)
    return lambda seam: seam_allowance.get(seam, default)


def _readable_angle(direction) -> float:
    angle = float(np.degrees(np.arctan2(direction[1], direction[0])))
    if angle > 90:
        angle -= 180
    elif angle <= -90:
        angle += 180
    return angle


def _seam_annotations(pattern, geo, unit: Unit = Unit.MM):
    """``(text, [(place (2,), tangent (2,)), ...])`` for every seam side on the panel: the places its
    label may go, along the seam (its middle first), 1.6 label heights inside the panel."""
    flat = pattern.panels[geo.index]
    source = pattern.source_of(geo.index)
    out = []
    for fs in pattern.seams:
        seam = fs.seam
        for side, (p, idx) in enumerate(zip(seam.panels, seam.vertices)):
            if p != source:
                continue
            pts = geo.uv[idx]
            if _runs_along_loop(flat.loops, idx) < 0:
                pts = pts[::-1]  # the panel to the left of the seam
            out.append((seam_label(fs, side, unit), along(pts, 1.6 * 0.6 * geo.text_height)))
    return out


def seam_label(flat_seam, side: int, unit: Unit = Unit.MM) -> str:
    """The annotation written next to a seam: id, 3D length and this side's flat length, in the drawing's unit.

    Two decimals in mm, four in the larger units (0.01 mm or finer either way).
    """
    digits = 2 if unit is Unit.MM else 4
    length, flat = flat_seam.length / unit.mm, flat_seam.flat_lengths[side] / unit.mm
    return f"S{flat_seam.seam.id} 3D {length:.{digits}f} FLAT {flat:.{digits}f} {unit.label}"


def notch_positions(flat_seam, side: int, uv: np.ndarray, spacing: float | None) -> list:
    """Where the notches of one side of a seam go: at equal 3D arc length on both sides.

    Parameters
    ----------
    flat_seam : patterns.FlatSeam
    side : int
        0 or 1.
    uv : (n, 2) float64
        The flat positions of that side's panel (as placed).
    spacing : float or None
        A notch every ``spacing`` mm of 3D seam length, and at both ends; None:
        at the ends only.

    Returns
    -------
    list of (float, (2,) float64, (2,) float64)
        The 3D arc length, the flat point, and the flat tangent (unit) there.
    """
    seam = flat_seam.seam
    pts = uv[seam.vertices[side]]
    c3 = polyline_arc(seam.points)
    total = c3[-1]
    if spacing:
        marks = np.arange(0.0, total, spacing)
        if total - marks[-1] < 0.25 * spacing:
            marks = marks[:-1]  # not a notch a hair before the end one
        marks = np.append(marks, total)
    else:
        marks = np.array([0.0, total])
    out = []
    for s in marks:
        j = int(np.clip(np.searchsorted(c3, s, side="right") - 1, 0, len(c3) - 2))
        t = (s - c3[j]) / max(c3[j + 1] - c3[j], 1e-300)
        point = pts[j] + t * (pts[j + 1] - pts[j])
        tangent = pts[j + 1] - pts[j]
        out.append((float(s), point, tangent / max(np.linalg.norm(tangent), 1e-300)))
    return out


def _notches(pattern, geo, allowance_of, spacing=None):
    """``(start on the cut line, inward direction, depth)`` of every notch on the panel, right by construction.

    With a seam allowance, a notch runs from the cut line to the seam line, square
    to the seam there: it starts where the ray from the seam point outwards (the
    seam's own outward normal, taken from which side of it the panel lies, not
    from a probe) meets the cut line, and ends on the seam point -- at a corner
    as well, where it lies in the allowance of the edge beyond.  Without one,
    the cut line is the seam line and the notch is a snip into the piece along the
    outline's inward normal, the bisector of the two edges at a corner (never
    along an edge).
    """
    flat = pattern.panels[geo.index]
    source = pattern.source_of(geo.index)
    cut = shapely.Polygon(geo.cut_loops[0], geo.cut_loops[1:])
    out = []
    for fs in pattern.seams:
        seam = fs.seam
        for side, p in enumerate(seam.panels):
            if p != source:
                continue
            along = _runs_along_loop(flat.loops, seam.vertices[side])
            depth = allowance_of(seam.id)
            for _, point, tangent in notch_positions(fs, side, geo.uv, spacing):
                inward = along * np.array([-tangent[1], tangent[0]])  # the panel lies to the left of its loops
                out.append(_notch(cut, geo, point, inward, depth))
    depth = allowance_of(None)
    for point, normal in _dart_mouths(flat, geo, across=depth > 0):
        out.append(_notch(cut, geo, point, -normal, depth))
    return out


def _runs_along_loop(loops, vertices) -> float:
    """+1 when a seam's vertices run the way its panel's boundary loop does (panel to their left), else -1."""
    a, b = int(vertices[0]), int(vertices[1])
    for loop in loops:
        at = np.flatnonzero(np.asarray(loop) == a)
        if len(at):
            return 1.0 if int(loop[(at[0] + 1) % len(loop)]) == b else -1.0
    return 1.0


def _notch(cut, geo, point, inward, depth):
    """One notch at a seam-line ``point`` whose inward normal is ``inward``: see :func:`_notches`."""
    if depth > 0:
        # Where the allowance steps from one seam to the next, the step of the cut line runs along
        # the ray from the seam's end: the notch moves half a millimetre along its own seam.
        along = np.array([inward[1], -inward[0]])
        for at in (point, point + 0.5 * along, point - 0.5 * along):
            ray = shapely.LineString([at, at - 3.0 * depth * inward])
            meet = ray.intersection(cut.boundary)
            hits = shapely.get_coordinates(meet)
            if len(hits) and shapely.get_type_id(meet) in (0, 4):  # points, not a run along the cut line
                start = hits[np.argmin(np.linalg.norm(hits - at, axis=1))]
                gap = float(np.linalg.norm(start - at))
                inside = shapely.points(start + np.linspace(0.1, 0.9, 9)[:, None] * (at - start))
                along_cut = shapely.distance(cut.boundary, inside).min() < 1e-3  # partly on a step of it
                if not along_cut and (abs(gap - depth) < 1e-6 or (at is point and gap > 1e-9)):
                    return start, inward, gap
        return point - depth * inward, inward, float(depth)
    rings = [shapely.LinearRing(loop) for loop in geo.cut_loops]  # straight runs dropped within 0.001 mm:
    ring = rings[int(np.argmin([r.distance(shapely.Point(point)) for r in rings]))]  # start on the line drawn
    point = np.array(ring.interpolate(ring.project(shapely.Point(point))).coords[0])
    direction = inward
    for loop in geo.cut_loops:  # at a corner of the outline: the bisector of its two edges' inward normals
        k = np.flatnonzero(np.linalg.norm(loop - point, axis=1) < 1e-9)
        if len(k):
            i = int(k[0])
            before, after = loop[i] - loop[i - 1], loop[(i + 1) % len(loop)] - loop[i]
            normals = [np.array([-d[1], d[0]]) / max(np.linalg.norm(d), 1e-300) for d in (before, after)]
            if normals[0] @ normals[1] < np.cos(np.radians(10)):
                bisector = normals[0] + normals[1]
                if np.linalg.norm(bisector) > 1e-9:
                    direction = bisector / np.linalg.norm(bisector)
                    if not shapely.contains_xy(cut, *(point + 0.5 * direction)):
                        direction = -direction
            break
    return point, direction, 3.0


def _v_mouth(geo, start, width) -> tuple:
    """The two ends of a V notch's mouth: on the cut outline, half ``width`` along it either side of ``start``."""
    rings = [shapely.LinearRing(loop) for loop in geo.cut_loops]
    ring = rings[int(np.argmin([r.distance(shapely.Point(start)) for r in rings]))]
    at = ring.project(shapely.Point(start))
    return tuple(np.array(ring.interpolate((at + d) % ring.length).coords[0]) for d in (-0.5 * width, 0.5 * width))


def _dart_mouths(flat, geo, *, across: bool) -> list:
    """``(point, outward direction)`` where each leg of each dart meets the outline.

    ``across`` (a seam allowance is drawn): square to the leg, as at the end
    of a seam side (the two legs are sewn like one), so that the notch runs
    from the seam line out across the leg's allowance.  Otherwise the corner
    where leg and outline meet is a cut line both ways, and the notch is a
    snip into the piece along the corner's bisector (the direction returned
    is its opposite: notches without an allowance are drawn inwards).
    """
    out = []
    loops = [np.asarray(loop) for loop in flat.loops]
    for dart in flat.darts:
        for leg in dart.legs:
            mouth = geo.uv[leg[0]]
            along = geo.uv[leg[1]] - mouth
            along = along / max(np.linalg.norm(along), 1e-300)
            if across:
                normal = np.array([along[1], -along[0]])
            else:
                (loop,) = [lp for lp in loops if np.any(lp == leg[0])]
                at = int(np.flatnonzero(loop == leg[0])[0])
                nbrs = [int(loop[at - 1]), int(loop[(at + 1) % len(loop)])]
                rim = geo.uv[nbrs[1] if nbrs[0] == leg[1] else nbrs[0]] - mouth
                normal = -(along + rim / max(np.linalg.norm(rim), 1e-300))
                normal = normal / max(np.linalg.norm(normal), 1e-300)
            probe = mouth + 0.25 * float(np.linalg.norm(geo.uv[leg[1]] - mouth)) * normal
            if shapely.contains_xy(geo.polygon, *probe):
                normal = -normal  # outward = away from the piece
            out.append((mouth, normal))
    return out


def _drill_holes(flat, geo) -> np.ndarray:
    """(d, 2) float64, mm, placed: the tip of each dart (a drill hole marks it, on the DRILL layer or ASTM 13)."""
    return np.array([geo.uv[dart.tip] for dart in flat.darts]).reshape(-1, 2)


def write_pattern_dxf(pattern, path, options: DxfOptions | None = None, **keywords) -> None:
    """Write a whole pattern as a DXF for cutters (atomically: a refused or failed write leaves nothing).

    Parameters
    ----------
    pattern : patterns.Pattern
    path : str or Path
    options : DxfOptions, optional
        The options, as a record; ``keywords`` (any :class:`DxfOptions` field)
        go over it.  See :meth:`patterns.Pattern.to_dxf` and docs/dxf.md.
    """
    import ezdxf

    opts = DxfOptions.of(options, keywords, name=str(path))
    check_marks(pattern.name, [fs.seam.length for fs in pattern.seams],
                [float(np.ptp(flat.uv, axis=0).max()) for flat in pattern.panels], opts)
    output_target(path, what="DXF file")  # before the drawing: a path that cannot be written fails at once
    allowance_of = _allowance_lookup(opts.seam_allowance, {s.seam.id for s in pattern.seams}, path)
    biggest = max(float(np.max(_allowance_values(pattern, allowance_of))), 0.0)
    offsets = display_offsets(pattern, gap=opts.gap, margin=biggest)
    geos = [_PanelGeometry(pattern, i, offsets[i], allowance_of, opts.text_height, opts.seam_corners)
            for i in range(len(pattern.panels))]
    if opts.profile == "machine":
        doc = _machine_doc(ezdxf, pattern, geos, allowance_of, offsets, opts)
        _first_quadrant(doc, MARGIN / Unit(opts.units).mm)
        with atomic_output(path, what="DXF file") as tmp:
            _save(doc, tmp)
            if opts.version == "R12":
                _r12_units(tmp, Unit(opts.units), doc.output_encoding)
    else:
        from ezdxf.addons import gerber_D6673

        doc = _astm_doc(ezdxf, pattern, geos, allowance_of, offsets, opts)
        _first_quadrant(doc, MARGIN)
        with atomic_output(path, what="DXF file") as tmp:
            _export_astm(gerber_D6673, doc, tmp)


MAX_MARKS = 100_000
"""The most notches, and the most bend lines, one DXF file gets: a spacing that would draw more
(a notch every 0.1 mm) is refused before anything is drawn."""


SMALLEST_PANEL = 0.01
"""The smallest panel drawn, mm across: ten times the 0.001 mm to which straight runs are drawn."""


def check_marks(name: str, seam_lengths, panel_sizes, options: DxfOptions) -> None:
    """InputError when a panel is too small to draw (:data:`SMALLEST_PANEL`), or when ``notch_spacing`` or
    ``bend_spacing`` would draw more than :data:`MAX_MARKS` marks.

    Parameters
    ----------
    name : str
        The part, for the message.
    seam_lengths : sequence of float
        Every seam's 3D length, mm (a notch every ``notch_spacing`` on each side).
    panel_sizes : sequence of float
        Every panel's largest extent, mm (a bend line every ``bend_spacing`` across it, at most).
    options : DxfOptions
    """
    small = [size for size in panel_sizes if not size >= SMALLEST_PANEL]
    if small:
        raise InputError(f"{name}: a panel {small[0]:.3g} mm across, under the {SMALLEST_PANEL:g} mm a DXF draws "
                         f"a panel at (parts are read in mm: check the file's unit)")
    total = float(np.sum(seam_lengths)) if len(seam_lengths) else 0.0
    if options.notch_spacing:
        notches = 2 * (total / options.notch_spacing + len(seam_lengths))
        if notches > MAX_MARKS:
            raise InputError(f"{name}: notch_spacing {options.notch_spacing:g} mm would draw about {notches:.3g} "
                             f"notches along {total:.0f} mm of seams; at most {MAX_MARKS} are drawn: give a larger "
                             f"spacing")
    if options.bend_spacing:
        lines = float(np.sum(panel_sizes)) / options.bend_spacing if len(panel_sizes) else 0.0
        if lines > MAX_MARKS:
            raise InputError(f"{name}: bend_spacing {options.bend_spacing:g} mm would draw up to {lines:.3g} bend "
                             f"lines across {len(panel_sizes)} panels; at most {MAX_MARKS} are drawn: give a "
                             f"larger spacing")


MARGIN = 5.0
"""Every drawing starts this far (mm) from the X and Y axes, in the first quadrant, where a cutter's
work area and a page are."""


def _first_quadrant(doc, margin: float) -> None:
    """Move everything in model space so that the drawing's extents start at (margin, margin)."""
    from ezdxf import bbox

    box = bbox.extents(doc.modelspace(), fast=True)
    if not box.has_data:
        return
    dx, dy = margin - box.extmin.x, margin - box.extmin.y
    for entity in doc.modelspace():
        if entity.dxftype() == "INSERT":  # an ASTM piece: its block's own geometry moves (readers that
            for inner in doc.blocks[entity.dxf.name]:  # ignore insertion points still see it in place)
                inner.translate(dx, dy, 0.0)
        else:
            entity.translate(dx, dy, 0.0)


def _allowance_values(pattern, allowance_of):
    return [allowance_of(None)] + [allowance_of(s.seam.id) for s in pattern.seams]


def _machine_doc(ezdxf, pattern, geos, allowance_of, offsets, opts: DxfOptions):
    version = opts.version or "R2000"
    unit = Unit(opts.units)
    scale = 1.0 / unit.mm  # drawing units per mm
    arc_tolerance = opts.arc_tolerance if opts.arcs else None
    bend_spacing, notch_spacing, notch_style, strain_layer = (opts.bend_spacing, opts.notch_spacing,
                                                              opts.notch_style, opts.strain_layer)
    r12 = version == "R12"
    doc = _new_doc(ezdxf, version, 0 if r12 else unit.insunits)  # $INSUNITS (R12 has none)
    doc.header["$MEASUREMENT"] = unit.measurement
    stock = getattr(pattern, "stock", ())
    for name, color in MACHINE_LAYERS.items():
        if (name != "STRAIN" or strain_layer) and (name != "STOCK" or stock):
            doc.layers.add(name, color=color)
    msp = doc.modelspace()

    def poly(points, layer, close=True):
        if arc_tolerance is not None and layer == "CUT":

            fitted = fit_arcs(np.asarray(points), arc_tolerance)
            fitted[:, :2] *= scale
            if r12:
                msp.add_polyline2d(fitted[:, :2].tolist(), close=True, dxfattribs={"layer": layer})
                entity = msp[-1]
                for vertex, bulge in zip(entity.vertices, fitted[:, 2]):
                    vertex.dxf.bulge = float(bulge)
            else:
                msp.add_lwpolyline(fitted.tolist(), format="xyb", close=True, dxfattribs={"layer": layer})
            return
        pts = (np.asarray(points) * scale).tolist()
        if r12:
            msp.add_polyline2d(pts, close=close, dxfattribs={"layer": layer})
        else:
            msp.add_lwpolyline(pts, close=close, dxfattribs={"layer": layer})

    def text(s, at, height, angle=0.0, layer="LABEL"):
        msp.add_text(s, height=height * scale, rotation=angle,
                     dxfattribs={"layer": layer}).set_placement(tuple(np.asarray(at) * scale),
                                                                  align=ezdxf.enums.TextEntityAlignment.MIDDLE_CENTER)

    for g in geos:
        for loop in g.cut_loops:
            poly(loop, "CUT")
        if g.has_allowance:
            for loop in g.seam_loops:
                poly(_straight_runs(loop), "SEW")
        for start, inward, depth in _notches(pattern, g, allowance_of, notch_spacing):
            tip = start + inward * depth  # on the seam line (or, with no allowance, a snip into the piece)
            if notch_style == "slit":
                msp.add_line(tuple(start * scale), tuple(tip * scale), dxfattribs={"layer": "NOTCH"})
            else:  # a V: its tip inside, opening on the cut line, as wide as deep
                for end in _v_mouth(g, start, depth):
                    msp.add_line(tuple(tip * scale), tuple(end * scale), dxfattribs={"layer": "NOTCH"})
        for tip in _drill_holes(pattern.panels[g.index], g):
            msp.add_point(tuple(tip * scale), dxfattribs={"layer": "DRILL"})
        a, b = _grain_line(g)
        msp.add_line(tuple(np.asarray(a) * scale), tuple(np.asarray(b) * scale), dxfattribs={"layer": "GRAIN"})
        rulings = [] if bend_spacing is None else [(a + offsets[g.index], b + offsets[g.index], turn) for a, b, turn
                                                   in pattern.panels[g.index].rulings(bend_spacing)]
        for a, b, _ in rulings:
            msp.add_line(tuple(a * scale), tuple(b * scale), dxfattribs={"layer": "BEND"})
        for label, layer in _machine_labels(pattern, g, unit, rulings):
            text(label.text, label.at, label.height, label.angle, layer=layer)
        if strain_layer:
            _strain_solids(msp, pattern.panels[g.index], g.uv, scale, truecolor=version not in ("R12", "R2000"))
    for x0, y0, x1, y1 in stock:  # the roll's edges, or each sheet: a nest's marker
        poly(np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]]), "STOCK")
    if stock and pattern.stock_note:
        x0, y0, x1, _ = stock[0]
        th = max(g.text_height for g in geos)
        text(f"{pattern.name}: {pattern.stock_note}", ((x0 + x1) / 2, y0 - 2 * th), th)
    if r12:  # above the whole drawing, clear of every piece
        top = max(float(np.max(loop[:, 1])) for g in geos for loop in g.cut_loops)
        left = min(float(np.min(loop[:, 0])) for g in geos for loop in g.cut_loops)
        th = geos[0].text_height
        msp.add_text(f"UNITS: {unit.label}", height=th * scale, dxfattribs={"layer": "LABEL"}).set_placement(
            (left * scale, (top + th) * scale), align=ezdxf.enums.TextEntityAlignment.BOTTOM_LEFT)
    return doc


def _machine_labels(pattern, g, unit, rulings) -> list:
    """``(Label, layer)`` of one panel in the machine profile, each placed clear of the lines and the
    others (:class:`~patterns.export.labels.LabelPlacer`): name and strain, each seam side's lengths,
    each ruling's bend angle."""
    placer = LabelPlacer(g.polygon)
    th = g.text_height
    strain = f"STRAIN RMS {100 * g.strain_rms:.2f}% MAX {100 * g.strain_max:.2f}%"
    out = [(label, "LABEL") for label in placer.place_block([(g.name, 0.8, 1.2), (strain, -0.9, 0.7)],
                                                            placer.inside_places(g.label_at, th), th)]
    for s, places in _seam_annotations(pattern, g, unit):
        for place, tangent in places:
            label = placer.place(s, [place], 0.6 * th, _readable_angle(tangent))
            if label is not None:
                out.append((label, "LABEL"))
                break
    for a, b, turn in rulings:
        direction = (b - a) / max(np.linalg.norm(b - a), 1e-12)
        places = [b - direction * f * np.linalg.norm(b - a) for f in (0.1, 0.3, 0.5, 0.7, 0.9)]
        label = placer.place(f"BEND {turn:.2f} DEG", places, 0.5 * th, _readable_angle(direction))
        if label is not None:
            out.append((label, "BEND"))
    return out


def _save(doc, path) -> None:
    """Save with fixed metadata (dates 2000-01-01, constant GUIDs): the same pattern and
    options always give a byte-identical file."""

    import ezdxf

    old = ezdxf.options.write_fixed_meta_data_for_testing
    ezdxf.options.write_fixed_meta_data_for_testing = True
    try:
        doc.saveas(path)
    finally:
        ezdxf.options.write_fixed_meta_data_for_testing = old
    # ezdxf also stamps its own "created/written by" records with the time of day.
    path = Path(path)
    text = path.read_text(encoding=doc.output_encoding, errors="surrogateescape")
    fixed = re.sub(r"(\d+\.\d+\.\d+) @ \d{4}-\d\d-\d\dT[\d:.]+\+00:00", r"\1 @ 2000-01-01T00:00:00+00:00", text)
    if fixed != text:
        path.write_text(fixed, encoding=doc.output_encoding, errors="surrogateescape")


def _export_astm(gerber_D6673, doc, path) -> None:
    """Write an ASTM file as ezdxf's ``gerber_D6673`` add-on lays it out (no handles, only the piece
    blocks, which Gerber's reader needs), its empty header replaced by one declaring the units and
    followed by a TABLES section declaring every layer the pieces use."""
    import io

    from ezdxf.lldxf.tagwriter import TagWriter

    stream = io.StringIO()
    gerber_D6673.export_stream(doc, stream)
    empty = "  0\nSECTION\n  2\nHEADER\n  0\nENDSEC\n"
    text = stream.getvalue()
    if not text.startswith(empty):  # pragma: no cover - the add-on's layout changed
        raise RuntimeError("ezdxf's gerber_D6673 add-on no longer writes an empty header first")
    tables = io.StringIO()
    writer = TagWriter(tables, write_handles=False, dxfversion=doc.dxfversion)
    tables.write("  0\nSECTION\n  2\nTABLES\n")
    doc.tables.linetypes.export_dxf(writer)
    doc.tables.layers.export_dxf(writer)
    tables.write("  0\nENDSEC\n")
    header = (f"  0\nSECTION\n  2\nHEADER\n  9\n$INSUNITS\n 70\n{Unit.MM.insunits}\n  9\n$MEASUREMENT\n 70\n"
              f"{Unit.MM.measurement}\n  0\nENDSEC\n")
    Path(path).write_text(header + tables.getvalue() + text[len(empty):], encoding="ascii", errors="dxfreplace")


def _r12_units(path, unit: Unit, encoding: str) -> None:
    """Write ``$INSUNITS`` and ``$MEASUREMENT`` into an R12 file's header as well.

    DXF R12 predates both variables (ezdxf leaves them out), but readers that scale
    by them -- Inkscape's "read from file" -- take a file without them for inches
    and draw a millimetre drawing 25.4 times too large; R12 readers that do not
    know them skip unknown header variables.  The unit is also in a text of every
    file (``UNITS: MM``, ASTM ``Units:METRIC``)."""
    path = Path(path)
    text = path.read_text(encoding=encoding, errors="surrogateescape")
    head = re.search(r"(?m)^\s*2\r?\nHEADER\r?\n", text)
    if head is None:  # pragma: no cover - every file ezdxf writes has a header section
        return
    found = [f"  9\n$INSUNITS\n 70\n{unit.insunits}\n", f"  9\n$MEASUREMENT\n 70\n{unit.measurement}\n"]
    path.write_text(text[:head.end()] + "".join(found) + text[head.end():], encoding=encoding,
                    errors="surrogateescape")


def _new_doc(ezdxf, version, units):
    """``ezdxf.new`` without its warning that R12 has no ``$INSUNITS`` (we know, and say it in a text)."""

    log = logging.getLogger("ezdxf")
    level = log.level
    log.setLevel(logging.ERROR)
    try:
        return ezdxf.new(version, setup=False, units=units)
    finally:
        log.setLevel(level)


def _grain_line(g):
    """A grain line along the flat +v axis, beside the labels where there is room.

    (Until a grain direction is given, the flat +v axis is the grain.)
    """
    h = 0.3 * (g.box[3] - g.box[1])
    for dx in (12.0, -12.0, 0.0):
        base = g.label_at + np.array([dx * g.text_height, -0.5 * h])
        if _inside(g.polygon, base) and _inside(g.polygon, base + [0.0, h]):
            break
    return (float(base[0]), float(base[1])), (float(base[0]), float(base[1] + h))


def _inside(polygon, point) -> bool:

    return bool(shapely.contains_xy(polygon, *point))


def _strain_solids(msp, flat, uv, scale, truecolor):
    """Every triangle as a filled SOLID coloured by its dominant strain (layer STRAIN)."""
    from matplotlib import colormaps
    from matplotlib.colors import TwoSlopeNorm


    s = triangle_strains(flat.vertices, flat.faces, flat.uv).dominant
    lim = max(float(np.max(np.abs(s))), 1e-6)
    rgba = colormaps["RdBu_r"](TwoSlopeNorm(0.0, -lim, lim)(s))
    for tri, c in zip(flat.faces, rgba):
        p = uv[tri] * scale
        attribs = {"layer": "STRAIN"}
        if truecolor:
            from ezdxf.colors import rgb2int

            attribs["true_color"] = rgb2int(tuple(int(255 * x) for x in c[:3]))
        else:
            attribs["color"] = 5 if c[2] > c[0] else 1
        msp.add_solid([tuple(p[0]), tuple(p[1]), tuple(p[2])], dxfattribs=attribs)


def _astm_doc(ezdxf, pattern, geos, allowance_of, offsets, opts: DxfOptions):
    """ASTM D6673 (AAMA) R12 document: one block per piece, inserted on layer 1."""
    bend_spacing, notch_spacing, notch_style = opts.bend_spacing, opts.notch_spacing, opts.notch_style
    doc = _new_doc(ezdxf, "R12", 0)
    for layer in ASTM_LAYERS:
        doc.layers.add(str(layer))
    msp = doc.modelspace()
    used = set()
    for g in geos:
        name = _block_name(g.name, used)
        block = doc.blocks.new(name=name)
        outer, holes = g.cut_loops[0], g.cut_loops[1:]
        block.add_polyline2d(outer.tolist(), close=True, dxfattribs={"layer": "1"})
        for loop in holes:
            block.add_polyline2d(loop.tolist(), close=True, dxfattribs={"layer": "11"})
        for loop in g.cut_loops:
            turn = _turning(loop)
            for p, t in zip(loop, turn):
                block.add_point((float(p[0]), float(p[1])), dxfattribs={"layer": "2" if t > np.radians(20) else "3"})
        if g.has_allowance:
            for loop in g.seam_loops:
                block.add_polyline2d(_straight_runs(loop).tolist(), close=True, dxfattribs={"layer": "14"})
        for base, inward, depth in _notches(pattern, g, allowance_of, notch_spacing):
            # ASTM notch: a POINT on the cut line; z = depth, group 50 = angle (into the
            # piece), group 39 = width for a V notch.
            angle = float(np.degrees(np.arctan2(inward[1], inward[0])))
            attribs = {"layer": "4", "angle": angle}
            if notch_style == "v":
                attribs["thickness"] = float(depth)
            block.add_point((float(base[0]), float(base[1]), float(depth)), dxfattribs=attribs)
        for tip in _drill_holes(pattern.panels[g.index], g):
            block.add_point((float(tip[0]), float(tip[1])), dxfattribs={"layer": "13"})
        block.add_line(*_grain_line(g), dxfattribs={"layer": "7"})
        if bend_spacing is not None:  # internal lines (layer 8): the rulings of a rolled panel
            for a, b, _ in pattern.panels[g.index].rulings(bend_spacing):
                block.add_line(tuple(a + offsets[g.index]), tuple(b + offsets[g.index]), dxfattribs={"layer": "8"})
        th = g.text_height
        placer = LabelPlacer(g.polygon)
        lines = [f"Piece Name:{g.name}", f"Size:{SAMPLE_SIZE}", "Quantity:1", "Material:",
                 f"Style Name:{printable(pattern.name)}",
                 "Units:METRIC"]
        strain = f"STRAIN RMS {100 * g.strain_rms:.2f}% MAX {100 * g.strain_max:.2f}%"
        block_lines = [(s, 2.0 - k, 0.6) for k, s in enumerate(lines)] + [(strain, -5.0, 0.6)]
        centre = ezdxf.enums.TextEntityAlignment.MIDDLE_CENTER
        for k, label in enumerate(placer.place_block(block_lines, placer.inside_places(g.label_at, th), th)):
            block.add_text(label.text, height=label.height, dxfattribs={"layer": "1" if k < len(lines) else "15"}
                           ).set_placement(tuple(label.at), align=centre)
        for s, places in _seam_annotations(pattern, g):
            for place, tangent in places:
                label = placer.place(s, [place], 0.6 * th, _readable_angle(tangent))
                if label is not None:
                    block.add_text(s, height=label.height, rotation=label.angle, dxfattribs={"layer": "15"}
                                   ).set_placement(tuple(label.at), align=centre)
                    break
        msp.add_blockref(name, (0.0, 0.0), dxfattribs={"layer": "1"})
    # The style's own text, in model space above the pieces (ASTM D6673 / AAMA): which standard,
    # style, date, author, sample size, grade rule table (none: one size) and units.
    top = max(float(np.max(loop[:, 1])) for g in geos for loop in g.cut_loops)
    left = min(float(np.min(loop[:, 0])) for g in geos for loop in g.cut_loops)
    th = geos[0].text_height
    style = [ASTM_VERSION, f"Style Name:{printable(pattern.name)}", f"Creation Date:{_creation_date()}", "Author:patterns",
             f"Sample Size:{SAMPLE_SIZE}", "Grading Rule Table:", "Units:METRIC"]
    for k, line in enumerate(style):  # the version line on top
        msp.add_text(line, height=0.6 * th, dxfattribs={"layer": "1"}).set_placement(
            (left, top + th * (len(style) - k)), align=ezdxf.enums.TextEntityAlignment.BOTTOM_LEFT)
    return doc


ASTM_VERSION = "ASTM/D6673/10"
"""The standard's version line, first of the style text."""

SAMPLE_SIZE = "BASE"
"""The one size a flattened pattern is (no grading): the piece text's ``Size:`` and the style's sample size."""


def _creation_date() -> str:
    """Today (UTC) as MM-DD-YYYY, or the day of ``SOURCE_DATE_EPOCH`` when set (reproducible builds)."""
    import datetime
    import os

    epoch = os.environ.get("SOURCE_DATE_EPOCH")
    when = (datetime.datetime.fromtimestamp(int(epoch), tz=datetime.timezone.utc) if epoch and epoch.isdigit()
            else datetime.datetime.now(tz=datetime.timezone.utc))
    return when.strftime("%m-%d-%Y")


def _block_name(name: str, used: set) -> str:

    base = re.sub(r"[^A-Za-z0-9_\-]", "_", name)[:31] or "PIECE"
    out, k = base, 1
    while out.upper() in used:
        k += 1
        out = f"{base[:28]}_{k}"
    used.add(out.upper())
    return out


def _turning(loop: np.ndarray) -> np.ndarray:
    """Turning angle at every vertex of a closed polyline, radians (0 = straight on)."""
    a = loop - np.roll(loop, 1, axis=0)
    b = np.roll(loop, -1, axis=0) - loop
    cross = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    dot = (a * b).sum(axis=1)
    return np.abs(np.arctan2(cross, dot))


def _orient(polygon):
    """Exterior counter-clockwise, interiors clockwise (shapely < 2.1)."""

    return orient(polygon, 1.0)
