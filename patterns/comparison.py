"""Compare a blank with a flat pattern another CAD program made (SolidWorks, FreeCAD, ...).

A shop that moves to `patterns` checks its blanks against the flat patterns it
cut before.  :func:`read_flat_pattern` reads such a DXF -- its cut contours
(LINE, ARC, CIRCLE, polylines with bulges, chained end to end; arcs sampled
exactly) and its bend lines (a BEND layer, or any line not drawn continuous:
SolidWorks' centre lines, our dashed ones) -- and
:func:`compare_blank` sets the two side by side.  A contour lying inside a
hole (SolidWorks draws a countersunk or counterbored hole as two concentric
circles) is that hole's rim: the inner contour is the hole the laser cuts, the
outer is machined afterwards, so the area is the outline less the inner ones.
A contour the drawing leaves open is an error, or, with
``open_contours="leave-out"``, left out and recorded.  Then
:func:`compare_blank` sets the two side by side: area, outer perimeter, holes,
bend lines, and how far the outlines lie apart once the best rigid motion
(mirror allowed: a blank may be drawn from either side) has put one on the
other (Hausdorff distance); and where they differ (:class:`Difference`): each
stretch of the outlines more than 0.1 mm apart, each hole of another size or
place, each hole only one of them has.
"""

from __future__ import annotations

import itertools
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import shapely

from .curves import Arc, Loop
from .errors import InputError

__all__ = ["BlankComparison", "Difference", "FlatPattern", "compare_blank", "read_flat_pattern"]

_JOIN = 1e-3
"""Contour pieces whose ends lie closer than this (mm) are joined."""

APART = 0.1
"""How far (mm) two contours may lie apart and still be the same cut: the outline's "within 0.1 mm"."""

_STEP = 0.02
"""The spacing (mm) at which contours are resampled to be measured."""

_PLACE = 1.0
"""Stretches of the outlines that differ and lie closer than this (mm) are one place (a slot's sides and its mouth)."""


@dataclass(frozen=True, eq=False)
class FlatPattern:
    """A flat pattern read from a DXF.

    Attributes
    ----------
    outline : (k, 2) float64, mm
        The outer contour (counter-clockwise, not closed).
    holes : tuple of (j, 2) float64, mm
        The holes cut (clockwise): of a countersunk or counterbored hole, the inner contour.
    bend_lines : (b, 2, 2) float64, mm
    path : str
        The file it was read from.
    rims : tuple of (j, 2) float64, mm
        Contours lying inside a hole (clockwise): a countersink's or counterbore's rim, not cut.
    open_contours : (n, 2, 2) float64, mm
        The two end points of every chain of pieces that does not close, left out
        (``open_contours="leave-out"``).
    """

    outline: np.ndarray
    holes: tuple
    bend_lines: np.ndarray
    path: str = ""
    rims: tuple = ()
    open_contours: np.ndarray = field(default_factory=lambda: np.zeros((0, 2, 2)))

    @property
    def polygon(self) -> shapely.Polygon:
        return shapely.Polygon(self.outline, list(self.holes))

    @property
    def area(self) -> float:
        return float(self.polygon.area)

    @property
    def perimeter(self) -> float:
        return float(shapely.LinearRing(self.outline).length)


def _is_bend(entity, doc) -> bool:
    """A line that is not cut: on a bend layer (``BEND``, ``BEND_UP``, ``IV_BEND``, ...) or drawn in any linetype
    but a continuous one (SolidWorks' centre lines, our dashed bend lines), its own or its layer's."""
    layer = entity.dxf.get("layer", "0")
    linetype = entity.dxf.get("linetype", "BYLAYER").upper()
    if linetype == "BYLAYER" and layer in doc.layers:
        linetype = doc.layers.get(layer).dxf.get("linetype", "CONTINUOUS").upper()
    return "BEND" in layer.upper() or linetype not in ("CONTINUOUS", "BYLAYER", "BYBLOCK")


def _bulged(rows: np.ndarray, closed: bool, tolerance: float) -> np.ndarray:
    """Points of a polyline given as ``(x, y, bulge)`` rows, its arcs sampled exactly within ``tolerance``."""
    if closed:
        return Loop.of_vertices(rows).points(tolerance)
    pts = [rows[0, :2]]
    for (x0, y0, bulge), (x1, y1, _) in itertools.pairwise(rows):
        if bulge:
            pts.extend(Arc.from_bulge((x0, y0), (x1, y1), bulge).points(tolerance)[1:])
        else:
            pts.append(np.array([x1, y1]))
    return np.array(pts)


def _pieces(entity, tolerance: float):
    """``(closed, (k, 2) points)`` of a contour entity, arcs sampled exactly within ``tolerance`` mm; None for
    an entity that is no contour."""
    kind = entity.dxftype()
    if kind == "LINE":
        return False, np.array([entity.dxf.start, entity.dxf.end])[:, :2]
    if kind == "CIRCLE":
        return True, Arc(np.array(entity.dxf.center)[:2], entity.dxf.radius, 0.0, 2 * np.pi).points(tolerance)[:-1]
    if kind == "ARC":
        a0, a1 = np.radians(entity.dxf.start_angle), np.radians(entity.dxf.end_angle)
        sweep = (a1 - a0) % (2 * np.pi) or 2 * np.pi  # counter-clockwise from start to end
        return False, Arc(np.array(entity.dxf.center)[:2], entity.dxf.radius, a0, sweep).points(tolerance)
    if kind == "LWPOLYLINE":
        rows = np.array([(x, y, b) for x, y, b in entity.get_points("xyb")], dtype=np.float64)
        return bool(entity.closed), _bulged(rows, bool(entity.closed), tolerance)
    if kind == "POLYLINE" and entity.is_2d_polyline:
        rows = np.array([(*v.dxf.location[:2], v.dxf.get("bulge", 0.0)) for v in entity.vertices], dtype=np.float64)
        return bool(entity.is_closed), _bulged(rows, bool(entity.is_closed), tolerance)
    if kind in ("SPLINE", "ELLIPSE"):
        from ezdxf import path as ezpath

        pts = np.array([(v.x, v.y) for v in ezpath.make_path(entity).flattening(tolerance)])
        return False, pts
    return None


MAX_POINTS = 2_000_000
"""The most contour points a flat pattern read for comparison may have (the OpenAMR center bracket's, 124 holes,
is 64 kB of DXF): past it the file is refused, not read for minutes."""

MAX_FLAT_PATTERN_BYTES = 20_000_000
"""The largest DXF :func:`read_flat_pattern` reads, bytes (checked before ezdxf parses it: 26 MB of R12 LINEs,
200,000 of them, took 27 s to read and compare; a real flat pattern is under 100 kB)."""


def _finite(values) -> bool:
    """Every number among ``values`` (DXF attributes: numbers, vectors, text) finite."""
    from ezdxf.math import Vec3

    for value in values:
        if isinstance(value, float) and not np.isfinite(value):
            return False
        if isinstance(value, (tuple, Vec3)) and not all(np.isfinite(float(v)) for v in value):
            return False
    return True


OPEN_CONTOURS = ("error", "leave-out")
"""What :func:`read_flat_pattern` does with a chain of pieces that does not close."""


def read_flat_pattern(path, *, tolerance: float = 0.001, open_contours: str = "error") -> FlatPattern:
    """Read a flat pattern's contours and bend lines from a DXF file (model space, in its own unit).

    The largest closed contour is the outline; a contour inside another one that lies inside the outline is
    a hole, and the one around it a rim (a countersunk or counterbored hole drawn as two concentric
    circles: the laser cuts the inner, the rim is machined afterwards).

    Parameters
    ----------
    path : str or Path
    tolerance : float
        Chord error of arcs and curves sampled as points, mm.
    open_contours : {"error", "leave-out"}
        A chain of pieces that does not close: an InputError naming where it stops (``"error"``), or left
        out and its end points recorded in :attr:`FlatPattern.open_contours` (``"leave-out"``).

    Raises
    ------
    InputError
        Not a readable DXF, contours that do not close (unless left out), no closed contour, or an
        unknown ``open_contours``.
    """
    import ezdxf

    if open_contours not in OPEN_CONTOURS:
        raise InputError(f"{path}: open_contours must be one of {', '.join(map(repr, OPEN_CONTOURS))}, got "
                         f"{open_contours!r}")
    from .files import check_input_file

    size = check_input_file(path, what="DXF file").stat().st_size
    if size > MAX_FLAT_PATTERN_BYTES:
        raise InputError(f"{path}: {size / 1e6:.0f} MB, over the {MAX_FLAT_PATTERN_BYTES // 1_000_000} MB a flat "
                         f"pattern to compare with may have (is this the right file?)")
    try:
        doc = ezdxf.readfile(str(path))
    except (OSError, ezdxf.DXFError) as exc:
        raise InputError(f"{path}: not a readable DXF file ({exc})") from None
    closed, open_, bends = [], [], []
    points = 0
    for entity in doc.modelspace():
        if not _finite(entity.dxf.all_existing_dxf_attribs().values()):
            raise InputError(f"{path}: a {entity.dxftype()} (handle {entity.dxf.handle}) has a coordinate or size "
                             f"that is not a finite number")
        if entity.dxftype() == "LINE" and _is_bend(entity, doc):
            bends.append(np.array([entity.dxf.start, entity.dxf.end])[:, :2])
            continue
        got = _pieces(entity, tolerance)
        if got is None:
            continue
        if not np.all(np.isfinite(got[1])):
            raise InputError(f"{path}: a {entity.dxftype()} (handle {entity.dxf.handle}) has a point that is not a "
                             f"finite number")
        points += len(got[1])
        if points > MAX_POINTS:
            raise InputError(f"{path}: over {MAX_POINTS:,} contour points; a flat pattern is far smaller (is this the "
                             f"right file?)")
        (closed if got[0] else open_).append(got[1])
    chained, left_out = _chain(open_, path, leave_out=open_contours == "leave-out")
    loops = closed + chained
    if not loops:
        raise InputError(f"{path}: no closed contour" + (f" ({len(left_out)} open left out)" if left_out else ""))
    polys = [shapely.Polygon(lp) for lp in loops]
    outer = int(np.argmax([p.area for p in polys]))
    outline = np.array(shapely.geometry.polygon.orient(polys[outer], 1.0).exterior.coords)[:-1]
    inner = [k for k in range(len(polys)) if k != outer]
    others = np.array([polys[k] for k in inner], dtype=object)
    around, _ = shapely.STRtree(others).query(others, predicate="contains_properly")  # holds another contour
    rims = {inner[a] for a in around}

    def clockwise(p):
        return np.array(shapely.geometry.polygon.orient(p, 1.0).exterior.coords)[-2::-1]

    return FlatPattern(outline, tuple(clockwise(polys[k]) for k in inner if k not in rims),
                       np.array(bends).reshape(-1, 2, 2), os.fsdecode(path),
                       rims=tuple(clockwise(polys[k]) for k in inner if k in rims),
                       open_contours=np.array(left_out).reshape(-1, 2, 2))


def _chain(pieces, path, *, leave_out: bool = False):
    """Join open pieces end to end into closed loops: ``(loops, left out)``, ``left out`` the two end points
    ((2, 2) mm) of every chain that does not close, when ``leave_out`` (else an InputError)."""
    from scipy.spatial import cKDTree

    pieces = [p for p in pieces if len(p) >= 2]
    loops, left_out = [], []
    used = np.zeros(len(pieces), bool)
    ends = np.concatenate([np.array([p[0] for p in pieces]).reshape(-1, 2),
                           np.array([p[-1] for p in pieces]).reshape(-1, 2)])  # piece k's start, then its end at n + k
    tree = cKDTree(ends) if len(ends) else None  # each step looks only near its end: a million lines in seconds
    n = len(pieces)

    def take(at):
        """The unused piece that goes on from ``at``, turned to start there (marked used), or None: the nearest
        end within _JOIN (a tie: the piece read first, its start before its end)."""
        if tree is None:
            return None
        near = [i for i in tree.query_ball_point(at, _JOIN) if not used[i % n]]
        if not near:
            return None
        i = min(near, key=lambda i: (float(np.linalg.norm(ends[i] - at)), i % n, i // n))
        used[i % n] = True
        return pieces[i % n] if i < n else pieces[i % n][::-1]

    for k in range(len(pieces)):
        if used[k]:
            continue
        used[k] = True
        loop = [pieces[k]]
        first, at = pieces[k][0], pieces[k][-1]
        while np.linalg.norm(at - first) > _JOIN:
            piece = take(at)
            if piece is None:
                if not leave_out:
                    raise InputError(f"{path}: a contour does not close (open end at x {at[0]:.3f}, y {at[1]:.3f}; "
                                     f"open_contours='leave-out' reads the rest)")
                while (back := take(first)) is not None:  # the chain's other end: the pieces before its first
                    first = back[-1]
                left_out.append(np.array([first, at]))
                break
            loop.append(piece[1:])
            at = piece[-1]
        else:
            pts = np.concatenate(loop)
            pts = pts[:-1] if np.linalg.norm(pts[-1] - pts[0]) <= _JOIN else pts
            if len(np.unique(pts.round(9), axis=0)) < 3:
                raise InputError(f"{path}: a contour of fewer than three points (a line drawn there and back, at x "
                                 f"{pts[0][0]:.3f}, y {pts[0][1]:.3f}) bounds no area")
            loops.append(pts)
    return loops, left_out


@dataclass(frozen=True)
class Difference:
    """One place where a blank and a reference flat pattern differ by more than :data:`APART` (0.1 mm).

    Attributes
    ----------
    kind : {"outline", "hole", "hole-ours", "hole-reference"}
        A stretch of the outer contours apart; a hole each at one place, of another size, shape or
        position; a hole the reference does not have; a hole only the reference has.
    x, y : float
        Where, in the reference drawing's coordinates, mm: the mean of the stretch's points (of a whole
        contour: its centre), the reference hole's centre (ours where the reference has none).
    distance : float
        How far apart, mm: the stretch's largest distance from the other outline; the two holes' Hausdorff
        distance; a hole only one drawing has: its size.
    length : float
        ``"outline"``: how much of the two outlines (summed) lies more than :data:`APART` from the other, mm;
        0 for holes.
    size, size_reference : float
        Holes: the diameter of a circle of the hole's area, ours and the reference's, mm (0 where that
        drawing has none); 0 for the outline.
    """

    kind: str
    x: float
    y: float
    distance: float
    length: float = 0.0
    size: float = 0.0
    size_reference: float = 0.0

    def to_dict(self) -> dict:
        """The report's entry.

        Returns
        -------
        dict
            ``kind``, ``x_mm``, ``y_mm``, ``distance_mm``, ``length_mm``, ``size_mm``, ``size_reference_mm``.
        """
        return {"kind": self.kind, "x_mm": self.x, "y_mm": self.y, "distance_mm": self.distance,
                "length_mm": self.length, "size_mm": self.size, "size_reference_mm": self.size_reference}

    def describe(self, reference: str = "the reference") -> str:
        """One line: what differs, where (in the reference's coordinates) and by how much.

        Parameters
        ----------
        reference : str
            How the reference drawing is named in the line (its file's name).

        Returns
        -------
        str
        """
        at = f"at x {self.x:.2f}, y {self.y:.2f} mm"
        if self.kind == "outline":
            return f"outline {at}: up to {self.distance:.3f} mm apart over {self.length:.1f} mm"
        if self.kind == "hole":
            return (f"hole {at}: Ø {self.size:.2f} in the blank, Ø {self.size_reference:.2f} in {reference} "
                    f"({self.distance:.3f} mm apart)")
        if self.kind == "hole-ours":
            return f"hole {at}: Ø {self.size:.2f} in the blank, none in {reference}"
        return f"hole {at}: none in the blank, Ø {self.size_reference:.2f} in {reference}"


@dataclass(frozen=True, eq=False)
class BlankComparison:
    """A blank beside a reference flat pattern (each figure ours, then theirs).

    Attributes
    ----------
    area, area_reference : float
        Material area (outline less holes), mm².
    perimeter, perimeter_reference : float
        Outer contour length, mm.
    holes, holes_reference : int
    bend_lines, bend_lines_reference : int
    hausdorff : float
        Largest distance between the two outer contours after the best rigid alignment, mm.
    hausdorff_all : float
        The same over every contour (outline and holes), mm.
    within : float
        The share of our outer contour (by length) within 0.1 mm of theirs.
    mirrored : bool
        The reference is drawn from the other side of the sheet.
    rims, rims_reference : int
        Countersinks' and counterbores' rims (:attr:`patterns.Blank.rims`, :attr:`FlatPattern.rims`).
    hausdorff_rims : float or None
        Largest distance between the two sets of rims after the same alignment, mm; None unless both
        have rims.
    open_contours_reference : int
        Open chains the reference was read without (``open_contours="leave-out"``).
    differences : tuple of Difference
        Every place where the two differ by more than :data:`APART`, the farthest apart first.
    """

    area: float
    area_reference: float
    perimeter: float
    perimeter_reference: float
    holes: int
    holes_reference: int
    bend_lines: int
    bend_lines_reference: int
    hausdorff: float
    hausdorff_all: float
    within: float
    mirrored: bool
    rims: int = 0
    rims_reference: int = 0
    hausdorff_rims: float | None = None
    open_contours_reference: int = 0
    differences: tuple[Difference, ...] = ()

    @property
    def area_error(self) -> float:
        """Relative area difference (ours less theirs, over theirs)."""
        return (self.area - self.area_reference) / self.area_reference

    def to_dict(self, reference: str = "") -> dict:
        """The report's ``comparison`` entry (mm, ratios)."""
        return {"reference": reference, "area_error": self.area_error, "perimeter_mm": self.perimeter,
                "perimeter_reference_mm": self.perimeter_reference, "holes_reference": self.holes_reference,
                "bend_lines_reference": self.bend_lines_reference, "hausdorff_mm": self.hausdorff,
                "hausdorff_all_mm": self.hausdorff_all, "within_0.1mm": self.within, "mirrored": self.mirrored,
                "rims": self.rims, "rims_reference": self.rims_reference, "hausdorff_rims_mm": self.hausdorff_rims,
                "open_contours_reference": self.open_contours_reference,
                "differences": [d.to_dict() for d in self.differences]}


def _resample(loop: np.ndarray, step: float) -> np.ndarray:
    closed = np.vstack([loop, loop[:1]])
    seg = np.linalg.norm(np.diff(closed, axis=0), axis=1)
    s = np.concatenate([[0], np.cumsum(seg)])
    t = np.arange(0, s[-1], step)
    return np.column_stack([np.interp(t, s, closed[:, 0]), np.interp(t, s, closed[:, 1])])


def _align(ours: np.ndarray, theirs: np.ndarray):
    """Rotation (2, 2, maybe a mirror) and shift putting ``ours`` (points, a few per mm) best onto
    ``theirs`` (points dense enough that the nearest one is as good as the nearest on the curve).

    Trimmed iterative closest points (the worst tenth of the pairs left out: a corner drawn another
    way does not pull the fit) from six starts -- the four principal-axis placements, the two
    drawings as they lie, and that mirrored -- then polished by a simplex search on the same
    trimmed mean distance."""
    from scipy.optimize import minimize
    from scipy.spatial import cKDTree

    tree = cKDTree(theirs)

    def trimmed(rot, shift):
        d = tree.query(ours @ rot.T + shift)[0]
        return d[d <= np.quantile(d, 0.9)].mean()

    def whole(rot, shift):
        return tree.query(ours @ rot.T + shift)[0].mean()

    ca, cb = ours.mean(axis=0), theirs.mean(axis=0)
    _, va = np.linalg.eigh(np.cov((ours - ca).T))
    _, vb = np.linalg.eigh(np.cov((theirs - cb).T))
    starts = [(r, cb - ca @ r.T) for r in (vb @ np.diag([sx, sy]) @ va.T for sx in (1, -1) for sy in (1, -1))]
    starts += [(np.eye(2), np.zeros(2)), (np.diag([1.0, -1.0]), np.zeros(2))]
    def icp(rot, shift, rounds):
        for _ in range(rounds):
            dk, k = tree.query(ours @ rot.T + shift)
            a = dk <= np.quantile(dk, 0.9)
            src, dst = ours[a], theirs[k[a]]
            cs, cd = src.mean(axis=0), dst.mean(axis=0)
            u, _, vt = np.linalg.svd((src - cs).T @ (dst - cd))
            hand = np.sign(np.linalg.det(rot)) * np.sign(np.linalg.det(u @ vt))  # keep the start's handedness
            new = (u @ np.diag([1, hand]) @ vt).T
            shift_new = cd - cs @ new.T
            done = np.allclose(new, rot, atol=1e-12) and np.allclose(shift_new, shift, atol=1e-9)
            rot, shift = new, shift_new
            if done:
                break
        return rot, shift

    # a few rounds from each start, then on from the one nearest over ALL the points: a nearly symmetric part
    # (an H whose two notches differ) fits its mirror image well on nine tenths of its points, but not on all
    tried = [icp(rot, shift, 30) for rot, shift in starts]
    rot, shift = icp(*min(tried, key=lambda rs: whole(*rs)), 300)
    best = (trimmed(rot, shift), rot, shift)
    _, rot, shift = best
    mirror = np.diag([1.0, np.sign(np.linalg.det(rot))])
    angle0 = np.arctan2(*(rot @ mirror)[::-1, 0])

    def at(x):
        c, s_ = np.cos(x[0]), np.sin(x[0])
        return np.array([[c, -s_], [s_, c]]) @ mirror, x[1:]

    res = minimize(lambda x: trimmed(*at(x)), np.r_[angle0, shift], method="Nelder-Mead",
                   options={"xatol": 1e-7, "fatol": 1e-9, "maxiter": 600,
                            "initial_simplex": np.r_[angle0, shift] + np.vstack([np.zeros(3), np.diag([1e-4, 0.05, 0.05])])})
    return at(res.x) if res.fun <= best[0] else (rot, shift)


def compare_blank(blank, reference) -> BlankComparison:
    """Compare a blank (a :class:`patterns.Blank`, or a flat-pattern DXF path) with a reference flat-pattern DXF.

    The contours (outline and holes) are aligned by a rigid motion (a mirror allowed), fitted
    by trimmed iterative closest points (the worst tenth of the pairs left out, so
    that one corner drawn differently does not shift the rest) and a simplex polish; the Hausdorff distance is then measured on contours resampled
    every 0.02 mm.  Holes are compared with holes (of a countersunk hole, the through hole) and rims with
    rims; the reference's open contours, when it was read without them, are counted.  ``differences``
    lists every place the two lie more than :data:`APART` apart (:class:`Difference`), in the reference's
    coordinates.
    """
    from scipy.spatial import cKDTree

    ref = reference if isinstance(reference, FlatPattern) else read_flat_pattern(reference)
    if isinstance(blank, (str, Path)):
        ours = read_flat_pattern(blank)
        outline, holes, bends = ours.outline, ours.holes, len(ours.bend_lines)
        area, perimeter, rims = ours.area, ours.perimeter, ours.rims
    else:
        outline, holes = blank.outline.points(), tuple(h.points() for h in blank.holes)
        rims = tuple(r.circle.points()[:-1] for r in blank.rims)
        bends, area, perimeter = len(blank.bends), blank.area, blank.perimeter
    rot, shift = _align(np.vstack([_resample(lp, 0.5) for lp in (outline, *holes)]),
                        np.vstack([_resample(lp, _STEP) for lp in (ref.outline, *ref.holes)]))
    # Every contour resampled once, ours put on theirs: (k, 2) mm each, the outline first.
    ours_all = [_resample(lp, _STEP) @ rot.T + shift for lp in (outline, *holes)]
    theirs_all = [_resample(lp, _STEP) for lp in (ref.outline, *ref.holes)]
    there = cKDTree(theirs_all[0]).query(ours_all[0])[0]
    back = cKDTree(ours_all[0]).query(theirs_all[0])[0]
    d_ours = cKDTree(np.vstack(theirs_all)).query(np.vstack(ours_all))[0]
    d_theirs = cKDTree(np.vstack(ours_all)).query(np.vstack(theirs_all))[0]
    rims_off = None
    if rims and ref.rims:
        a = np.vstack([_resample(lp, _STEP) for lp in rims]) @ rot.T + shift
        b = np.vstack([_resample(lp, _STEP) for lp in ref.rims])
        rims_off = _hausdorff(a, b)
    places = _outline_places(ours_all[0], theirs_all[0], there, back)
    places += _hole_places([h @ rot.T + shift for h in holes], ref.holes, sampled=(ours_all[1:], theirs_all[1:]),
                           nearest=(d_ours[len(ours_all[0]):], d_theirs[len(theirs_all[0]):]))

    return BlankComparison(
        area=area, area_reference=ref.area, perimeter=perimeter, perimeter_reference=ref.perimeter,
        holes=len(holes), holes_reference=len(ref.holes), bend_lines=bends, bend_lines_reference=len(ref.bend_lines),
        hausdorff=float(max(there.max(), back.max())),
        hausdorff_all=float(max(d_ours.max(), d_theirs.max())),
        within=float(np.mean(there <= APART)),
        mirrored=bool(np.linalg.det(rot) < 0), rims=len(rims), rims_reference=len(ref.rims), hausdorff_rims=rims_off,
        open_contours_reference=len(ref.open_contours),
        differences=tuple(sorted(places, key=lambda d: (-d.distance, d.kind, d.x, d.y))))


def _hausdorff(a: np.ndarray, b: np.ndarray) -> float:
    """The Hausdorff distance of two point sets ``(k, 2)`` (contours resampled every :data:`_STEP`), mm."""
    from scipy.spatial import cKDTree
    return float(max(cKDTree(b).query(a)[0].max(), cKDTree(a).query(b)[0].max()))


def _runs(far: np.ndarray) -> list[np.ndarray]:
    """The runs of ``True`` in ``far`` ``(k,) bool``, the points of one closed contour in order: index arrays,
    a run that wraps past the last point kept whole."""
    if not far.any():
        return []
    if far.all():
        return [np.arange(len(far))]
    order = np.roll(np.arange(len(far)), -int(np.argmin(far)))  # start on a point that is not far
    step = np.diff(np.r_[0, far[order].astype(np.int8), 0])
    return [order[a:b] for a, b in zip(np.flatnonzero(step == 1), np.flatnonzero(step == -1))]


def _outline_places(ours: np.ndarray, theirs: np.ndarray, there: np.ndarray, back: np.ndarray) -> list[Difference]:
    """The stretches of the two outer contours (points ``(k, 2)`` every :data:`_STEP`, in the reference's
    coordinates, with each point's distance to the other contour) more than :data:`APART` apart, those closer
    than :data:`_PLACE` to each other one place."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    runs = [(points[r], distance[r]) for points, distance in ((ours, there), (theirs, back))
            for r in _runs(distance > APART)]
    if not runs:
        return []
    # Points APART from each other (every fifth) tell which runs come within _PLACE of each other.
    sparse = [p[::max(1, round(APART / _STEP))] for p, _ in runs]
    label = np.repeat(np.arange(len(runs)), [len(p) for p in sparse])
    pairs = cKDTree(np.vstack(sparse)).query_pairs(_PLACE, output_type="ndarray")
    graph = coo_matrix((np.ones(len(pairs)), (label[pairs[:, 0]], label[pairs[:, 1]])), shape=(len(runs),) * 2)
    _, place = connected_components(graph, directed=False)
    out = []
    for k in range(place.max() + 1):
        members = [runs[i] for i in np.flatnonzero(place == k)]
        points = np.vstack([p for p, _ in members])
        x, y = points.mean(axis=0)
        out.append(Difference("outline", float(x), float(y), float(max(d.max() for _, d in members)),
                              length=len(points) * _STEP))
    return out


def _hole_places(ours: list[np.ndarray], theirs: list[np.ndarray], *, sampled, nearest) -> list[Difference]:
    """The holes that differ.

    Two holes are one hole drawn twice when either's centre lies inside the other; of the pairs so
    found, those that look most alike go first (the gap between their centres plus half the difference
    of their sizes: for two circles, their Hausdorff distance), each hole in one pair at most.

    Parameters
    ----------
    ours, theirs : list of (k, 2) float64
        The holes' points, mm, ours already in the reference's coordinates.
    sampled : tuple of (list of (k, 2) float64, list of (k, 2) float64)
        The same holes resampled every :data:`_STEP`, ours then theirs.
    nearest : tuple of ((k,) float64, (k,) float64)
        Each resampled point's distance to the nearest contour of the other drawing, mm, the holes'
        points in the order of ``sampled``, ours then theirs.

    Returns
    -------
    list of Difference
        A ``"hole"`` for each pair more than :data:`APART` apart (the pair's own Hausdorff distance), a
        ``"hole-ours"`` or ``"hole-reference"`` for each hole with no mate.
    """
    def figures(loops):
        polygons = np.array([shapely.Polygon(h) for h in loops], dtype=object)
        if not len(loops):
            return polygons, np.zeros((0, 2)), np.zeros(0)
        return polygons, shapely.get_coordinates(shapely.centroid(polygons)), np.sqrt(4.0 * shapely.area(polygons) / np.pi)

    def worst(loops, d):
        if not loops:
            return np.zeros(0)
        return np.maximum.reduceat(d, np.r_[0, np.cumsum([len(p) for p in loops])[:-1]])

    p_ours, c_ours, size_ours = figures(ours)
    p_theirs, c_theirs, size_theirs = figures(theirs)
    far_ours, far_theirs = worst(sampled[0], nearest[0]), worst(sampled[1], nearest[1])
    mate, taken = np.full(len(ours), -1), set()
    if len(ours) and len(theirs):
        # (ours, theirs) index pairs: our centre in their hole, or their centre in ours
        a = shapely.STRtree(p_theirs).query(shapely.points(c_ours), predicate="within")
        b = shapely.STRtree(p_ours).query(shapely.points(c_theirs), predicate="within")
        pairs = np.unique(np.hstack([a, b[::-1]]), axis=1)
        i, k = pairs
        unlike = np.hypot(*(c_ours[i] - c_theirs[k]).T) + 0.5 * np.abs(size_ours[i] - size_theirs[k])
        for n in np.lexsort((k, i, unlike)):  # the most alike first, ties by index: one mate each
            if mate[i[n]] < 0 and int(k[n]) not in taken:
                mate[i[n]] = k[n]
                taken.add(int(k[n]))
    out = []
    for i, k in enumerate(mate):
        if k < 0:
            out.append(Difference("hole-ours", *map(float, c_ours[i]), float(size_ours[i]), size=float(size_ours[i])))
        elif max(far_ours[i], far_theirs[k]) > APART:  # some point lies farther than APART from every contour
            apart = _hausdorff(sampled[0][i], sampled[1][k])
            out.append(Difference("hole", *map(float, c_theirs[k]), apart, size=float(size_ours[i]),
                                  size_reference=float(size_theirs[k])))
    for k in sorted(set(range(len(theirs))) - taken):
        out.append(Difference("hole-reference", *map(float, c_theirs[k]), float(size_theirs[k]),
                              size_reference=float(size_theirs[k])))
    return out
