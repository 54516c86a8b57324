"""Check a pattern or a blank before cutting: an auditor that collects findings (overlaps, strain, seams).

The geometric predicates it rests on (the overlap verdict, crossing outlines)
live in :mod:`patterns.predicates`; they are re-exported here.  The finding
type is the one :func:`patterns.unfold` reports with (:mod:`patterns.findings`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import shapely

from .blank import Blank
from .curves import Motion
from .errors import InputError
from .findings import Code, Finding, Severity
from .measure import edge_strain, folded_faces, strain_stats
from .mesh import extent
from .model import Bookkeeping
from .options import Options, option
from .pattern import Pattern
from .pieces import Drawing
from .predicates import Overlap, boundary_crossings, crossing_segments, flat_polygon, overlap_verdict
from .text import counted

__all__ = ["CheckOptions", "Code", "DartReport", "Finding", "Overlap", "PanelReport", "Report", "SeamReport", "Severity",
           "boundary_crossings", "check", "checked_drawing", "crossing_segments", "overlap_verdict"]


# --------------------------------------------------------------------------- #
# The report: an auditor that collects findings, never raises on geometry
# --------------------------------------------------------------------------- #


@dataclass(frozen=True)
class PanelReport:
    """Numbers of one panel (strains dimensionless: 0.01 = 1 %; areas mm^2; places mm).

    The strains are the principal strains of the map from the surface to the
    plane, weighted by 3D triangle area (:class:`patterns.measure.StrainStats`):
    the material's strain, which converges as the mesh is refined.  The edge
    strain columns count edges, so they change with the triangulation; they
    are kept for comparison only.  An exact development has no strain.
    """

    name: str
    n_triangles: int
    area_3d: float
    area_flat: float
    strain_rms: float
    """RMS of both principal strains of every triangle."""
    strain_p95: float
    """95th percentile of each triangle's largest principal strain magnitude."""
    strain_p99: float
    strain_max: float
    strain_max_at: tuple
    """``(x, y)`` of the most strained triangle's centre in the flat pattern as placed, mm."""
    stretch_min: float
    """The smallest principal stretch of any triangle (1 = its 3D size, near 0 = pressed flat)."""
    share_above_limit: float | None
    """Share of the 3D area whose triangle strain exceeds ``max_strain`` (None without a limit)."""
    edge_strain_rms: float
    edge_strain_max: float
    n_folded: int
    one_to_one: bool
    iterations: int
    converged: bool
    energy: str = ""
    """The energy the relaxation minimised (``"arap"``, ``"hybrid"``, ...); "" for a grower or an exact development."""
    darts: tuple = ()
    """The :class:`DartReport` of each dart cut by ``flatten(..., max_strain=...)``."""


@dataclass(frozen=True)
class DartReport:
    """One dart of a panel (lengths in mm): its legs are sewn together, so they count as a seam."""

    length_3d: float
    """The cut's length on the 3D surface."""
    legs_flat: tuple
    """The flat length of each leg (equal: they close on each other)."""
    tip: tuple
    """``(x, y)`` of the dart's point in the flat pattern as placed (a drill hole marks it)."""


@dataclass(frozen=True)
class SeamReport:
    """Numbers of one seam (lengths in mm)."""

    id: int
    panels: tuple
    """Names of the panels on side 0 and side 1 (equal for a seam closing one panel)."""
    cad_edge: int | None
    length_3d: float
    """The seam's exact length (the CAD edge's curve length)."""
    length_3d_polyline: float
    """The 3D length of the polyline a relaxed side's flat length is measured along (shorter
    than ``length_3d`` on a curve by the chords' sag): compare a relaxed side with this."""
    length_flat: tuple
    """Flat length on side 0 and on side 1: a relaxed side's flat polyline, an exactly
    developed side's exact curve laid flat (:attr:`patterns.FlatSeam.flat_lengths`)."""
    length_held: tuple | None
    """The flat length each side was held at (``flatten(seams="true")``: its 3D polyline
    length times its ease; None for a side that is an exact development); None for a free seam."""
    mismatch: float
    """``length_flat[0] - length_flat[1]``, mm."""
    mismatch_percent: float
    """``mismatch / length_3d * 100``."""


@dataclass(frozen=True, eq=False)
class Report:
    """Everything :func:`check` found about a pattern.

    Attributes
    ----------
    pattern : str
        The pattern's (model's) name.
    panels : tuple of PanelReport
    seams : tuple of SeamReport
    findings : tuple of Finding
        Errors first, then limits, then notes.
    max_strain, max_seam_mismatch : float or None
        The limits asked for.
    area_tolerance, max_distortion : float or None
        The limits of a usable pattern (:class:`CheckOptions`).
    loading : patterns.Bookkeeping
        What loading did to the input (vertices welded, pieces split, cuts
        made, units converted); nothing, for a report made by hand.
    blanks : tuple of patterns.Blank
        The sheet-metal blanks checked (their size, bends and findings).
    """

    pattern: str
    panels: tuple
    seams: tuple
    findings: tuple
    max_strain: float | None = None
    max_seam_mismatch: float | None = None
    area_tolerance: float | None = None
    max_distortion: float | None = None
    loading: Bookkeeping = Bookkeeping()
    blanks: tuple = ()

    @property
    def ok(self) -> bool:
        """No error and no exceeded limit (notes do not count)."""
        return not any(f.severity is not Severity.NOTE for f in self.findings)

    @property
    def errors(self) -> tuple:
        return tuple(f for f in self.findings if f.severity is Severity.ERROR)

    def to_dict(self) -> dict:
        """The report as plain Python types: what the JSON profile writes (``patterns.write(x, "x.json")``,
        with the pieces; see docs/report.md)."""
        from dataclasses import asdict

        return {
            "pattern": self.pattern,
            "ok": self.ok,
            "units": {"length": "mm", "area": "mm2", "strain": "ratio (0.01 = 1 %)"},
            "limits": {"max_strain": self.max_strain, "max_seam_mismatch": self.max_seam_mismatch,
                       "area_tolerance": self.area_tolerance, "max_distortion": self.max_distortion},
            "loading": {**asdict(self.loading), "said": str(self.loading)},
            "panels": [{**asdict(p), "strain_max_at": list(p.strain_max_at),
                        "darts": [{"length_3d": d.length_3d, "legs_flat": list(d.legs_flat), "tip": list(d.tip)}
                                  for d in p.darts]} for p in self.panels],
            "seams": [{**asdict(s), "panels": list(s.panels), "length_flat": list(s.length_flat),
                       "length_held": None if s.length_held is None else list(s.length_held)}
                      for s in self.seams],
            "blanks": [b.to_dict() for b in self.blanks],
            "findings": [f.to_dict() for f in self.findings],
        }

    def __str__(self) -> str:
        lines = [f"{self.pattern}: {'ok' if self.ok else 'NOT ok'} "
                 f"({counted(len(self.panels), 'panel')}, {counted(len(self.seams), 'seam')}, "
                 f"{counted(len(self.findings), 'finding')})"]
        lines += [f"  {f.severity.value}: {f.message}" for f in self.findings]
        return "\n".join(lines)


@dataclass(frozen=True, repr=False)
class CheckOptions(Options):
    """The limits a pattern is checked against (:func:`check`, ``patterns flatten/check --max-strain``)."""

    max_strain: float | None = option(None, "largest acceptable triangle strain, a ratio (0.03 = 3 %); triangles "
                                            "above it are findings (the command line then exits with 1)",
                                      optional=True, unit="ratio")
    max_seam_mismatch: float | None = option(None, "largest acceptable difference of a seam's two flat lengths, "
                                                   "mm (above it the command line exits with 1)",
                                             low=0, low_open=True, optional=True, unit="mm")
    area_tolerance: float | None = option(0.05, "a panel whose flat area differs from its 3D area by more than "
                                                "this ratio (0.05 = 5 %) is not a usable pattern of it (an error; none: "
                                                "not checked)", optional=True, unit="ratio")
    max_distortion: float | None = option(2.0, "a triangle laid flat at more than this factor of its 3D size in "
                                               "some direction (2: doubled or halved) is grossly distorted; a "
                                               "panel with more than 1 % of its area so is not a usable pattern "
                                               "(an error; none: not checked)", low=1, low_open=True,
                                          optional=True, metavar="F")


def check(source, options: CheckOptions | None = None, **keywords) -> Report:
    """Check a pattern or a blank before cutting: overlaps, strain, seams, a blank's faults.

    Never raises on geometry: every problem becomes a :class:`Finding` with
    the place it is at.

    Parameters
    ----------
    source : patterns.Pattern, patterns.Blank, or a list of them
        A list gives one report of them all (a marker of several parts).
    options : CheckOptions, optional
        The limits as a record; keywords (``max_strain``: largest acceptable
        triangle strain, 0.03 = 3 %, triangles above it are reported with the
        share of area they cover -- by default the limit the pattern was
        flattened to, :attr:`Pattern.max_strain`; ``max_seam_mismatch``:
        largest acceptable difference between the two flat lengths of a seam,
        mm) go over it.  A blank is exact: its findings are the unfold's
        (flanges that collide, a bend with no flange, a meshed face).

    Returns
    -------
    Report

    Raises
    ------
    InputError
        Not a pattern or a blank, or a limit that is not a positive number.

    Notes
    -----
    A seam held at its length (``flatten(seams="true")``) whose flat length on
    a side is off by more than :data:`SEAM_LENGTH_TOLERANCE` is a
    ``seam-length-not-kept`` finding, whose message names what kept it from its
    length (folds, a relaxation stopped early, ease asked of an exact
    development).  An exactly developed side is measured on its exact curve:
    an isometry keeps the 3D length.
    """
    items = list(source) if isinstance(source, (list, tuple)) else [source]
    for item in items:
        if not isinstance(item, (Pattern, Blank)):
            raise InputError(f"check() takes a patterns.Pattern (from patterns.flatten) or a patterns.Blank (from "
                             f"patterns.unfold), got {type(item).__name__}")
    if not items:
        raise InputError("check() takes a pattern or a blank, got an empty list")
    name = " + ".join(dict.fromkeys(item.name for item in items))
    opts = CheckOptions.of(options, keywords, name=name)
    reports = [_check_pattern(item, opts) if isinstance(item, Pattern) else _check_blank(item, opts) for item in items]
    if len(reports) == 1:
        return reports[0]
    findings = sorted((f for r in reports for f in r.findings), key=lambda f: _ORDER[f.severity])
    first = reports[0]
    return Report(name, sum((r.panels for r in reports), ()), sum((r.seams for r in reports), ()), tuple(findings),
                  first.max_strain, opts.max_seam_mismatch, opts.area_tolerance, opts.max_distortion, first.loading,
                  sum((r.blanks for r in reports), ()))


_ORDER = {Severity.ERROR: 0, Severity.LIMIT: 1, Severity.NOTE: 2}


def _check_blank(blank: Blank, opts: CheckOptions) -> Report:
    return Report(blank.name, (), (), tuple(sorted(blank.findings, key=lambda f: _ORDER[f.severity])),
                  opts.max_strain, opts.max_seam_mismatch, opts.area_tolerance, opts.max_distortion, blanks=(blank,))


def _check_pattern(pattern: Pattern, opts: CheckOptions) -> Report:
    max_strain, max_seam_mismatch = opts.max_strain, opts.max_seam_mismatch
    if max_strain is None:
        max_strain = pattern.max_strain  # the limit the pattern was flattened (and darted) to travels with it
    findings = []
    panel_reports = []
    for flat in pattern.panels:
        report, found = _panel_report(flat, max_strain)
        panel_reports.append(report)
        findings += found + _usable(flat, report, opts)
    findings += _overlaps_between(pattern) + _insert_notes(pattern, max_strain) + _gore_notes(pattern, max_strain)
    findings += _unit_notes(pattern) + _sheet_notes(pattern)
    seam_reports = []
    for fs in pattern.seams:
        report, found = _seam_report(pattern, fs, max_seam_mismatch)
        seam_reports.append(report)
        findings += found
    findings.sort(key=lambda f: _ORDER[f.severity])
    return Report(pattern.name, tuple(panel_reports), tuple(seam_reports), tuple(findings), max_strain,
                  max_seam_mismatch, opts.area_tolerance, opts.max_distortion, pattern.model.bookkeeping)


TINY = 1.0
"""mm: a pattern whose largest panel is smaller than this across gets a :attr:`Code.TINY_PART` note."""


def _unit_notes(pattern: Pattern) -> list:
    """A note when the whole pattern is under :data:`TINY` across: the unit that would make it 10 mm or more
    (metres, then centimetres, then inches), and how to say it."""
    if not pattern.panels:
        return []
    size = max(extent(flat.uv) for flat in pattern.panels)
    if size >= TINY:
        return []
    unit, scale = next(((u, mm) for u, mm in (("m", 1000.0), ("cm", 10.0), ("in", 25.4)) if size * mm >= 10.0),
                       ("m", 1000.0))
    return [Finding(Code.TINY_PART, Severity.NOTE, (pattern.panels[0].name,), np.zeros((0, 2)), (), None,
                    f"{pattern.name}: the pattern is {size:.3g} mm across: was it modelled in {unit}? read in {unit} "
                    f"it is {size * scale:.3g} mm (a mesh's unit: --input-units {unit}, load(..., units={unit!r}); "
                    f"a CAD file is read in mm)")]


def _sheet_notes(pattern: Pattern) -> list:
    """A note when the flattened part is a bent sheet (:func:`patterns.sheetmetal.sheet.bent_sheet`): unfold it."""
    from .sheetmetal.sheet import bent_sheet

    found = bent_sheet([(p.surface, p.area) for p in pattern.model.panels])
    if found is None or not pattern.panels:
        return []
    t, bends = found
    return [Finding(Code.SHEET_METAL, Severity.NOTE, (pattern.panels[0].name,), np.zeros((0, 2)), (), None,
                    f"{pattern.name}: a bent sheet, it seems ({t:.3g} mm, {counted(bends, 'bend')}): flattened, each "
                    f"face is a loose panel; patterns unfold (patterns.unfold) makes one blank with bend lines")]


def _placed_like(item, drawing: Drawing):
    """A pattern or blank moved as its first (unmirrored) pieces lie in ``drawing``."""
    if isinstance(item, Blank):
        kind, count = "blank", 1
    else:
        kind, count = "panel", len(item.panels)
    where = {}
    for piece in drawing.pieces:
        s = piece.source
        if s.kind == kind and s.part == item.name and s.copy == 0 and not piece.placement.mirrored:
            where.setdefault(s.index, piece.placement)
    if isinstance(item, Blank):
        return item.moved(where.get(0, Motion()))
    placements = []
    for i in range(count):
        moved = where.get(i, Motion()) @ Motion(*item.panels[i].placement)
        placements.append((moved.angle, moved.dx, moved.dy))
    return item.placed(placements)


def checked_drawing(source, drawing: Drawing, options: CheckOptions | None = None) -> tuple:
    """``(Report, Drawing)``: the check of ``source`` (a pattern, a blank or a list of them) as its pieces lie
    in ``drawing`` -- every point and message in the drawing's frame -- and the drawing with that report
    and each piece's findings: its own about its drawing (a label left out) and the check's about it."""
    items = list(source) if isinstance(source, (list, tuple)) else [source]
    placed = [_placed_like(item, drawing) for item in items]
    report = check(placed if len(placed) > 1 else placed[0], options)
    panel_names = {(item.name, i): flat.name for item in items if isinstance(item, Pattern)
                   for i, flat in enumerate(item.panels)}
    pieces = []
    for piece in drawing.pieces:
        s = piece.source
        about = panel_names.get((s.part, s.index)) if s.kind == "panel" else s.part
        first = s.copy == 0 and not piece.placement.mirrored
        own = tuple(f for f in piece.findings if f.code is Code.LABEL_LEFT_OUT)
        pieces.append(replace(piece, findings=own + tuple(f for f in report.findings if first and about in f.panels)))
    return report, replace(drawing, pieces=tuple(pieces), report=report.to_dict())


GROSS_SHARE = 0.01
"""A panel with more than this share of its 3D area grossly distorted (``max_distortion``) is not usable."""


def _usable(flat, report, opts) -> list:
    """Errors for a panel that is not a usable pattern of its surface, whatever limit was asked for:
    its flat area off its 3D area (``area_tolerance``), or more than :data:`GROSS_SHARE` of its area
    laid flat at more than ``max_distortion`` times its size, or a fraction of it, in some direction."""
    out = []
    name = flat.name
    change = report.area_flat / report.area_3d - 1.0 if report.area_3d > 0 else 0.0
    at = np.array([report.strain_max_at])
    if opts.area_tolerance is not None and abs(change) > opts.area_tolerance:
        out.append(Finding(Code.AREA_NOT_KEPT, Severity.ERROR, (name,), at, (), None,
                           f"panel {name}: flat area {report.area_flat:.1f} mm^2 is {abs(change):.1%} "
                           f"{'smaller' if change < 0 else 'larger'} than its 3D area {report.area_3d:.1f} mm^2 "
                           f"(tolerance {opts.area_tolerance:.1%}): not a usable pattern of this surface; give it "
                           f"seams or darts"))
    if opts.max_distortion is not None and flat.flattening.method != "exact":
        ts = flat.strains
        with np.errstate(divide="ignore"):
            factor = np.maximum(ts.stretch[:, 0], np.where(ts.stretch[:, 1] > 0, 1.0 / ts.stretch[:, 1], np.inf))
        gross = np.flatnonzero(factor > opts.max_distortion)
        share = float(ts.area_3d[gross].sum() / ts.area_3d.sum()) if len(gross) else 0.0
        if share > GROSS_SHARE:
            worst = gross[np.argmax(factor[gross])]
            c = flat.uv[flat.faces[worst]].mean(axis=0)
            out.append(Finding(Code.GROSSLY_DISTORTED, Severity.ERROR, (name,), c[None, :],
                               gross, None,
                               f"panel {name}: {share:.1%} of its area is laid flat at more than "
                               f"{opts.max_distortion:g} times its size, or 1/{opts.max_distortion:g} of it, in some "
                               f"direction (worst at ({c[0]:.1f}, {c[1]:.1f}) mm): not a usable pattern of this "
                               f"surface; give it seams or darts"))
    return out


DARTS_PER_GORE = 1.2
"""Darts a dome takes for each balanced gore of the gore bound (measured: a hemisphere's 11 darts at 3 %
against the bound's 9.07)."""


def _dart_notes(flat, mag, uv, faces) -> list:
    """The note on a panel's darts: how many and how long, and whether they met the limit they were
    cut for; where they did not (or there was none to cut), the best strain reached and where."""
    search = flat.dart_search
    if not flat.darts and (search is None or search.met):
        return []
    i = int(np.argmax(mag))
    worst, at = float(mag[i]), uv[faces[i]].mean(axis=0)
    where = f"{worst:.2%} at ({at[0]:.1f}, {at[1]:.1f}) mm"
    if flat.darts:
        tips = np.array([uv[d.tip] for d in flat.darts])
        length = sum(d.length_3d for d in flat.darts)
        cut = f"{counted(len(flat.darts), 'dart')} cut"
        of = f" ({length:.1f} mm of cuts; points: their tips)"
    else:
        tips, cut, of = at[None, :], "no dart cut", ""
    if search is None or (search.met and search.sewn):
        text = f"panel {flat.name}: {cut} to keep the strain within the limit{of}"
    else:
        limit, tried = search.limit, len(search.tries)
        text = (f"panel {flat.name}: {cut}{of}; the strain limit {limit:.2%} was not met within {counted(search.max_darts, 'dart')} "
                f"({tried} cuts measured): the best reached is {where}, from {search.before:.2%} "
                f"without darts")
        if search.needed == 0:
            text += ("; the surface has no positive curvature for darts to take out (it is saddle-shaped): "
                     "allow more slashes with inserts (max_darts), or cut gores")
        else:
            text += (f"; the surface's curvature asks for about {search.needed:.1f} darts at this limit (the gore "
                     f"bound; darts take about {DARTS_PER_GORE:g} times as many)")
        if 0 < search.needed and DARTS_PER_GORE * search.needed > search.max_darts:
            text += ": allow more darts, or cut gores"
        if not search.sewn:
            apart = max(abs(np.subtract(*d.leg_lengths(uv))) for d in flat.darts)
            text += f"; the legs could not be held to equal lengths (up to {apart:.2f} mm apart)"
        if search.met and not search.sewn:
            text = (f"panel {flat.name}: {cut}{of} keep the strain within {limit:.2%}, but their legs could not "
                    f"be held to equal lengths with the panel's seams")
    return [Finding(Code.DARTS, Severity.NOTE, (flat.name,), tips, (), None, text)]


def _insert_notes(pattern, max_strain) -> list:
    """The note on each slashed panel: its inserts, the tips of the slashes they fill (points), and whether
    every piece met the strain limit they were cut for."""
    index = {flat.name: i for i, flat in enumerate(pattern.panels)}
    out = []
    for name in dict.fromkeys(f.panel.insert_into for f in pattern.panels if f.panel.insert_into is not None):
        main = index[name]
        inserts = [f.name for f in pattern.panels if f.panel.insert_into == name]
        tips = {int(fs.seam.vertices[fs.seam.panels.index(main)][-1]) for fs in pattern.seams
                if main in fs.seam.panels and pattern.panels[sum(fs.seam.panels) - main].panel.insert_into == name}
        uv = pattern.panels[main].uv
        text = (f"panel {name}: saddle-shaped (its curvature is negative), so slashed "
                f"{counted(len(inserts), 'time')} from its outline; each slash opens into a wedge that "
                f"an insert fills ({', '.join(inserts)}), sewn along its 3D length")
        pieces = [pattern.panels[index[p]] for p in (name, *inserts)]
        worst = [float(p.strains.magnitude.max()) for p in pieces]
        if max_strain is not None and max(worst) > max_strain:
            at = int(np.argmax(worst))
            text += (f"; the strain limit {max_strain:.2%} was not met: the worst piece reaches {worst[at]:.2%} "
                     f"(panel {pieces[at].name}): allow more slashes (max_darts), or cut gores")
        out.append(Finding(Code.INSERTS, Severity.NOTE, (name, *inserts), uv[sorted(tips)], (), None, text))
    return out


def _gore_notes(pattern, max_strain) -> list:
    """The note on each panel split into gores: how many, and whether every gore met the strain limit they were
    cut for; its panels are the gores, the one of highest strain first, and its point that gore's worst triangle."""
    out = []
    for name in dict.fromkeys(f.panel.gore_of for f in pattern.panels if f.panel.gore_of is not None):
        gores = [f for f in pattern.panels if f.panel.gore_of == name]
        worst = [float(f.strains.magnitude.max()) for f in gores]
        at = int(np.argmax(worst))
        first = gores[at]
        i = int(np.argmax(first.strains.magnitude))
        point = first.uv[first.faces[i]].mean(axis=0)
        names = [g.name for g in gores]
        listed = ", ".join(names) if len(names) <= 4 else f"{names[0]} ... {names[-1]}"
        darts = [len(g.darts) for g in gores]  # any: parted in darts mode, darts alone fell short
        text = (f"panel {name}: split into {counted(len(gores), 'piece' if any(darts) else 'gore')} ({listed}) "
                f"along cuts from its outline to its crown, each cut a seam held at its 3D length")
        if any(darts):
            text += (f", with {', '.join(map(str, darts))} darts: darts alone (at most max_darts on one panel) "
                     f"could not bring it within the strain limit")
        if max_strain is not None and worst[at] > max_strain:
            text += (f"; the strain limit {max_strain:.2%} was not met: the worst gore reaches {worst[at]:.2%} at "
                     f"({point[0]:.1f}, {point[1]:.1f}) mm (panel {first.name}): allow more gores (max_gores)")
        panels = (first.name, *(g.name for g in gores if g is not first))
        out.append(Finding(Code.GORES, Severity.NOTE, panels, point[None, :], (), None, text))
    return out


SEAM_LENGTH_TOLERANCE = 1e-3
"""A held seam side whose flat length is off its held length by more than this fraction is reported."""


def _panel_report(flat, max_strain):
    """``(PanelReport, findings)`` of one flat panel."""
    uv, faces, vertices = flat.uv, flat.faces, flat.vertices
    ts = flat.strains
    mag, w = ts.magnitude, ts.area_3d
    stats = strain_stats(ts)
    exact = flat.flattening.method == "exact"
    es = np.zeros(len(faces)) if exact else edge_strain(vertices, faces, uv)  # exact: no strain at all
    findings = []
    share = None
    if max_strain is not None:
        above = np.flatnonzero(mag > max_strain)
        share = float(w[above].sum() / w.sum())
        if len(above):
            worst = above[np.argmax(mag[above])]
            centre = uv[faces[worst]].mean(axis=0)
            findings.append(Finding(
                Code.STRAIN_ABOVE_LIMIT, Severity.LIMIT, (flat.name,), centre[None, :], above, None,
                f"panel {flat.name}: strain above {max_strain:.2%} on {share:.1%} of its area "
                f"({len(above)} triangles), up to {mag[worst]:.2%} at ({centre[0]:.1f}, {centre[1]:.1f}) mm"))
    findings += _panel_overlaps(flat)
    res = flat.flattening
    findings += _dart_notes(flat, mag, uv, faces)
    if not res.converged:
        findings.append(Finding(Code.NOT_CONVERGED, Severity.NOTE, (flat.name,), np.zeros((0, 2)), (), None,
                                f"panel {flat.name}: the relaxation stopped after {res.iterations} iterations "
                                f"before converging"))
    at = uv[faces[stats.worst]].mean(axis=0)
    report = PanelReport(
        name=flat.name, n_triangles=len(faces), area_3d=float(w.sum()), area_flat=flat.area,
        strain_rms=stats.rms, strain_p95=stats.p95, strain_p99=stats.p99, strain_max=stats.max,
        strain_max_at=(float(at[0]), float(at[1])), stretch_min=float(ts.stretch[:, 1].min()),
        share_above_limit=share,
        edge_strain_rms=float(np.sqrt(np.mean(es**2))), edge_strain_max=float(es.max()),
        n_folded=int(np.count_nonzero(ts.area_change <= -1.0)), one_to_one=bool(res.one_to_one),
        iterations=int(res.iterations), converged=bool(res.converged), energy=res.energy,
        darts=tuple(DartReport(float(d.length_3d), d.leg_lengths(uv), tuple(float(x) for x in uv[d.tip]))
                    for d in flat.darts))
    return report, findings


def _seam_report(pattern, fs, max_seam_mismatch):
    """``(SeamReport, findings)`` of one flat seam."""
    seam = fs.seam
    names = tuple(pattern.panels[p].name for p in seam.panels)
    pct = 100.0 * fs.mismatch / seam.length if seam.length > 0 else 0.0
    held = None if fs.held_lengths is None else tuple(None if x is None else float(x) for x in fs.held_lengths)
    report = SeamReport(seam.id, names, seam.cad_edge, float(seam.length), seam.polyline_length,
                        tuple(float(x) for x in fs.flat_lengths), held, fs.mismatch, pct)
    findings = []
    mid = pattern.panels[seam.panels[0]].uv[seam.vertices[0][len(seam.vertices[0]) // 2]]
    if max_seam_mismatch is not None and abs(fs.mismatch) > max_seam_mismatch:
        findings.append(Finding(
            Code.SEAM_MISMATCH_ABOVE_LIMIT, Severity.LIMIT, names, mid[None, :], (),
            seam.id, f"seam {seam.id} ({names[0]} / {names[1]}): flat lengths {fs.flat_lengths[0]:.2f} and "
                     f"{fs.flat_lengths[1]:.2f} mm differ by {abs(fs.mismatch):.2f} mm "
                     f"(limit {max_seam_mismatch:g} mm)"))
    if held is not None:
        off = [(side, fs.flat_lengths[side], held[side]) for side in range(2)
               if held[side] is not None and abs(fs.flat_lengths[side] / held[side] - 1.0) > SEAM_LENGTH_TOLERANCE]
        if off:
            side, got, want = max(off, key=lambda x: abs(x[1] / x[2] - 1.0))
            cause = _why_not_kept(pattern.panels[seam.panels[side]].flattening)
            findings.append(Finding(
                Code.SEAM_LENGTH_NOT_KEPT, Severity.LIMIT, names, mid[None, :], (), seam.id,
                f"seam {seam.id} ({names[0]} / {names[1]}): could not be held at its length ({cause}): "
                f"{got:.2f} mm flat on {names[side]}'s side, {want:.2f} mm wanted ({100 * (got / want - 1):+.2f} %)"))
    return report, findings


def _why_not_kept(flattening) -> str:
    """What kept a held seam side from its length, as far as its panel's flattening says."""
    if flattening.n_folded:
        return f"{flattening.n_folded} folded triangles in the panel stood in the way"
    if not flattening.converged:
        return (f"the relaxation stopped after {flattening.iterations} iterations, before the held lengths were "
                f"reached: give max_iterations more")
    return (f"the relaxation held each edge within {flattening.length_error:.2%} only: the held lengths pull "
            f"against the panel's other constraints (pins, darts, min_stretch)")


def _panel_overlaps(flat) -> list:
    """Findings for one panel overlapping itself: folds, crossing loops, misplaced holes."""
    uv, faces, loops, name = flat.uv, flat.faces, flat.loops, flat.name
    out = []
    folded = folded_faces(uv, faces)
    if len(folded):
        centres = uv[faces[folded]].mean(axis=1)
        c = centres[0]
        out.append(Finding(Code.FOLDED_TRIANGLES, Severity.ERROR, (name,), centres, folded, None,
                           f"panel {name}: {len(folded)} folded triangles (first: face {int(folded[0])} "
                           f"at ({c[0]:.1f}, {c[1]:.1f}) mm)"))
    for a, b, pts in boundary_crossings(uv, loops):
        code = Code.OUTLINE_CROSSES_ITSELF if a == b == 0 else Code.HOLE_CROSSES_OUTLINE
        what = ("its outline crosses itself" if a == b == 0 else
                f"hole {b} crosses the outline" if a == 0 else
                f"hole {a} crosses itself" if a == b else f"holes {a} and {b} cross")
        out.append(Finding(code, Severity.ERROR, (name,), pts, (), None,
                           f"panel {name}: {what} at {len(pts)} points (first: ({pts[0, 0]:.1f}, {pts[0, 1]:.1f}) mm)"))
    rings = [shapely.linearrings(uv[loop]) for loop in loops]
    if not shapely.is_ccw(rings[0]):
        c = uv[loops[0]].mean(axis=0)
        out.append(Finding(Code.INSIDE_OUT, Severity.ERROR, (name,), c[None, :], (), None,
                           f"panel {name}: the flat outline runs clockwise (the panel is turned inside out)"))
    outer = flat_polygon(uv, loops, holes=False)
    for k in range(1, len(loops)):
        inside = shapely.contains_xy(outer, uv[loops[k], 0], uv[loops[k], 1])
        if not inside.any():
            p = uv[loops[k]][0]
            out.append(Finding(Code.HOLE_OUTSIDE_OUTLINE, Severity.ERROR, (name,), p[None, :], (), None,
                               f"panel {name}: hole {k} lies outside the outline, near ({p[0]:.1f}, {p[1]:.1f}) mm"))
    return out


def _overlaps_between(pattern) -> list:
    """Findings for placed panels that overlap each other."""
    if len(pattern.panels) < 2 or not pattern.laid_out:
        return []
    polys = []
    for flat in pattern.panels:
        uv = flat.uv
        polys.append(shapely.make_valid(flat_polygon(uv, flat.loops)))
    polys = np.array(polys, dtype=object)
    i, j = shapely.STRtree(polys).query(polys, predicate="intersects")
    keep = i < j
    out = []
    for a, b in zip(i[keep], j[keep]):
        common = shapely.intersection(polys[a], polys[b])
        area = shapely.area(common)
        scale = min(shapely.area(polys[a]), shapely.area(polys[b]))
        if area <= 1e-9 * scale:
            continue  # touching along an edge or at a point
        p = shapely.get_coordinates(shapely.point_on_surface(common))[0]
        na, nb = pattern.panels[a].name, pattern.panels[b].name
        out.append(Finding(Code.PANELS_OVERLAP, Severity.ERROR, (na, nb), p[None, :], (), None,
                           f"panels {na} and {nb} overlap by {area:.1f} mm^2 around ({p[0]:.1f}, {p[1]:.1f}) mm"))
    return out
