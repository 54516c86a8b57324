"""The flat pattern: every panel laid flat at true scale, with its seams.

:func:`patterns.flatten_mesh` returns a :class:`Flattening` (one mesh laid flat:
positions, overlap verdict, how the engine got there); :func:`patterns.flatten`
returns a :class:`Pattern`.  A :class:`FlatPanel` keeps its Flattening and the
3D panel it came from; vertex ``i`` of the panel is at ``uv[i]`` in the
plane (the 3D <-> 2D map is the vertex index).  Millimetres throughout.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np
import shapely

from .curves import Motion
from .errors import InputError
from .measure import Distortion, TriangleStrain, distortion, flat_direction, no_strain, triangle_strains
from .mesh import extent, polyline_arc
from .model import Model, Panel, Seam, SurfaceKind
from .options import check_number
from .predicates import Overlap, flat_polygon
from .text import counted

__all__ = ["Dart", "DartSearch", "FlatPanel", "FlatSeam", "Flattening", "Pattern"]


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
        The triangle the greedy grower laid down first, without distortion;
        -1 for an exact development (no grower).
    overlap : Overlap
        The overlap verdict: folded triangles, loop tests, ``one_to_one``.
    start : str
        ``"relaxed"`` only: the layout the relaxation started from --
        ``"greedy"`` (the isometric grower's, when it is one-to-one), else
        ``"lscm"`` (when that is one-to-one), else ``"tutte"``; ``"exact"``:
        ``"analytic"``; "" otherwise.
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


@dataclass(frozen=True)
class DartSearch:
    """How ``flatten(..., max_strain=...)`` looked for a panel's darts, and whether it met the limit.

    Attributes
    ----------
    limit : float
        The strain limit the darts were cut for (0.03 = 3 %).
    max_darts : int
        The most darts allowed.
    before : float
        The worst triangle's principal strain without darts.
    worst : float
        The worst triangle's principal strain of the panel as cut.
    met : bool
        ``worst <= limit``.
    sewn : bool
        The darts' legs were held to one length each (False: the relaxation
        could not hold them with the panel's seams, and the legs are left as
        they fell).
    tries : tuple of (int, float, float)
        Every flattening tried, in order: ``(darts, core radius mm, worst
        strain)``; the darts ran from the outline to a circle of that radius
        about the crown (``inf``: the try could not be cut or its seams held).
    needed : float
        How many darts the surface's curvature asks for at the limit, the
        gore bound (a hemisphere: 9.07 at 3 %; a panel within the limit
        without darts: 0); measured, darts need about 1.2 times as many.
    """

    limit: float
    max_darts: int
    before: float
    worst: float
    met: bool
    sewn: bool = True
    tries: tuple = ()
    needed: float = 0.0


@dataclass(frozen=True, eq=False)
class Dart:
    """A dart: a cut from the outline into a panel, whose two legs are sewn together.

    Indices are into the flattening's vertices (:attr:`FlatPanel.vertices`).

    Attributes
    ----------
    legs : tuple of two (p,) int64
        The vertices of each leg, from the outline to the tip (the last
        vertex, shared by both legs).  Sewn, leg 0 meets leg 1 point by point.
    length_3d : float
        The cut's length on the 3D surface, mm.
    """

    legs: tuple
    length_3d: float

    @property
    def path(self) -> np.ndarray:
        """(p,) int64: the cut, as leg 0."""
        return self.legs[0]

    @property
    def tip(self) -> int:
        """The vertex at the dart's point (a drill hole marks it)."""
        return int(self.legs[0][-1])

    def leg_lengths(self, uv: np.ndarray) -> tuple:
        """Flat length of each leg, mm, in the layout ``uv`` ``(n, 2)``."""
        return tuple(float(np.linalg.norm(np.diff(uv[leg], axis=0), axis=1).sum()) for leg in self.legs)


@dataclass(frozen=True, eq=False)
class FlatPanel:
    """One panel laid flat.

    Attributes
    ----------
    name : str
    panel : patterns.Panel
        The 3D panel (``panel.vertices[i]`` is laid at ``uv[i]``).
    flattening : patterns.Flattening
        The engine's result: ``uv``, overlap verdict, distortion, iterations.
    """

    name: str
    panel: Panel
    flattening: Flattening
    placement: tuple = (0.0, 0.0, 0.0)
    """``(angle, dx, dy)``: the rigid motion (radians, mm) that puts the
    flattened panel where it lies on the sheet: rotate about the origin, then
    move.  ``(0, 0, 0)`` until the pattern is laid out."""
    darts: tuple = ()
    """The :class:`Dart` s cut by ``flatten(..., max_strain=...)``."""
    source: int | None = None
    """For a copy (:meth:`Pattern.with_copies`): the index of the panel it copies, whose seams and
    notches it shares; None for the panel itself."""
    mirrored: bool = False
    """A mirror image of its source (the left piece of a left and right pair): 3D panel and flat
    piece reflected across their first axis, faces and loops turned so that both stay
    counter-clockwise."""
    dart_search: DartSearch | None = None
    """How the darts were looked for (None: no ``max_strain`` was given, or the panel is exact)."""

    def copy(self, name: str, *, source: int, mirrored: bool = False) -> FlatPanel:
        """Another piece of this panel, named ``name`` (a mirror image if ``mirrored``)."""
        if not mirrored:
            return replace(self, name=name, source=source, mirrored=self.mirrored)
        fl, panel = self.flattening, self.panel
        flip3, flip2 = np.array([-1.0, 1.0, 1.0]), np.array([-1.0, 1.0])
        faces = np.ascontiguousarray(fl.faces[:, ::-1])
        loops = tuple(np.ascontiguousarray(loop[::-1]) for loop in fl.loops)
        uv = fl.uv * flip2
        uv.setflags(write=False)
        from .predicates import overlap_verdict

        flattening = replace(fl, uv=uv, vertices=fl.vertices * flip3, faces=faces, loops=loops,
                             overlap=overlap_verdict(uv, faces, loops))
        surface = panel.surface
        if surface is not None:
            surface = replace(surface, origin=surface.origin * flip3, x_dir=surface.x_dir * flip3,
                              y_dir=surface.y_dir * flip3, axis=surface.axis * flip3,
                              directrix=None if surface.directrix is None else surface.directrix * flip3)
        mirror = replace(panel, vertices=panel.vertices * flip3, faces=panel.faces[:, ::-1],
                         loops=tuple(loop[::-1] for loop in panel.loops), surface=surface)
        return FlatPanel(name, mirror, flattening, self.placement, self.darts, source, not self.mirrored,
                         self.dart_search)

    @property
    def uv(self) -> np.ndarray:
        """(n, 2) float64, mm: flat position of each panel vertex, as placed."""
        angle, dx, dy = self.placement
        if angle == 0.0 and dx == 0.0 and dy == 0.0:
            return self.flattening.uv
        uv = self.place(self.flattening.uv)
        uv.setflags(write=False)
        return uv

    @property
    def motion(self) -> Motion:
        """The placement ``(angle, dx, dy)`` as a :class:`~patterns.curves.Motion`, what a piece's
        ``placement`` is."""
        angle, dx, dy = self.placement
        return Motion(float(angle), float(dx), float(dy))

    def place(self, points) -> np.ndarray:
        """Points of the flattening's own frame, (k, 2) mm, moved by the panel's placement."""
        return self.motion(points)

    def rulings(self, spacing: float) -> list:
        """Straight rulings of an exactly developed cylinder or cone, about ``spacing`` mm apart.

        The lines a press brake bumps or a roll follows: on a cylinder parallel
        to its axis, on a cone through its apex.  Spaced evenly in angle so that
        neighbours are ``spacing`` apart along the longest edge, the outline's
        own edges excluded.

        Returns
        -------
        list of ((2,) float64, (2,) float64, float)
            Each line's two ends in the flat pattern as placed (mm, clipped to
            the panel) and the bend angle it carries: the turn about the axis
            between neighbouring rulings, degrees.  Empty for any other panel.
        """


        surface = self.panel.surface
        if self.flattening.method != "exact" or surface is None or surface.kind is SurfaceKind.PLANE:
            return []
        spacing = check_number(spacing, "ruling spacing (mm)", low=0, low_open=True, name=f"panel {self.name}")
        uv = self.flattening.uv
        polygon = flat_polygon(uv, self.loops)
        size = extent(uv) * 4 + 1.0
        lines = []
        if surface.kind is SurfaceKind.CYLINDER:
            along = flat_direction(self.vertices, self.faces, uv, surface.axis)  # the rulings' direction
            across = np.array([along[1], -along[0]])
            w = uv @ across
            x0, x1 = w.min(), w.max()
            n = max(int(round((x1 - x0) / spacing)), 1)
            step = (x1 - x0) / n
            turn = np.degrees(step / self._radius())
            for k in range(1, n):
                base = (x0 + k * step) * across
                lines.append((shapely.LineString([base - size * along, base + size * along]), turn))
        else:
            apex3d = surface.origin if surface.kind is SurfaceKind.GENERAL_CONE else \
                surface.origin - surface.radius / np.tan(surface.semi_angle) * surface.axis
            s3 = np.linalg.norm(self.vertices - apex3d, axis=1)
            # The apex in the plane: the point at each vertex's 3D distance from the apex
            # (a development keeps it), least squares: 2 uv.a - |a|^2 = |uv|^2 - s^2.
            lhs = np.column_stack([2 * uv, -np.ones(len(uv))])
            sol = np.linalg.lstsq(lhs, (uv * uv).sum(axis=1) - s3 * s3, rcond=None)[0]
            apex = sol[:2]
            if surface.kind is SurfaceKind.CONE:
                rel = uv - apex
                theta = np.unwrap(np.arctan2(rel[self.loops[0], 1], rel[self.loops[0], 0]))
                t0, t1 = theta.min(), theta.max()
                r = np.hypot(rel[:, 0], rel[:, 1])
                n = max(int(round((t1 - t0) * r.max() / spacing)), 1)
                step = (t1 - t0) / n
                turn = np.degrees(step / abs(np.sin(surface.semi_angle)))
                for k in range(1, n):
                    t = t0 + k * step
                    lines.append((shapely.LineString([apex, apex + size * np.array([np.cos(t), np.sin(t)])]), turn))
            else:
                lines = self._general_cone_rulings(surface, apex, spacing, size)
        out = []
        for line, turn in lines:
            part = line.intersection(polygon)
            for seg in getattr(part, "geoms", [part]):
                if seg.is_empty or seg.length <= 0:
                    continue
                a, b = np.asarray(seg.coords)[[0, -1]]
                a, b = self.place([a, b])
                out.append((a, b, float(turn)))
        return out

    def _general_cone_rulings(self, surface, apex, spacing, size):
        """The classic triangulation lines of an oblique cone: apex to points along the
        directrix ``spacing`` mm apart (3D), each with the fold angle between the flat
        facets on either side of it."""

        d3 = surface.directrix
        arc = polyline_arc(d3)
        n = max(int(round(arc[-1] / spacing)), 1)
        marks = np.linspace(0.0, arc[-1], n + 1)
        pts = np.column_stack([np.interp(marks, arc, d3[:, k]) for k in range(3)])
        # Flat positions of the marks: on the panel's outline, by its 3D polyline.
        loop = self.loops[0]
        ring3, ring2 = self.vertices[np.r_[loop, loop[:1]]], self.flattening.uv[np.r_[loop, loop[:1]]]
        a, b = ring3[:-1], ring3[1:]
        out = []
        apex3d = surface.origin
        for k in range(1, n):
            p = pts[k]
            ab = b - a
            t = np.clip(((p - a) * ab).sum(axis=1) / np.maximum((ab * ab).sum(axis=1), 1e-300), 0.0, 1.0)
            j = int(np.argmin(np.linalg.norm(a + t[:, None] * ab - p, axis=1)))
            flat = ring2[j] + t[j] * (ring2[j + 1] - ring2[j])
            n1 = np.cross(pts[k - 1] - apex3d, p - apex3d)
            n2 = np.cross(p - apex3d, pts[k + 1] - apex3d)
            fold = np.degrees(np.arccos(np.clip(n1 @ n2 / (np.linalg.norm(n1) * np.linalg.norm(n2)), -1.0, 1.0)))
            direction = (flat - apex) / max(np.linalg.norm(flat - apex), 1e-300)
            out.append((shapely.LineString([apex, flat + 1e-6 * size * direction]), float(fold)))
        return out

    def _radius(self) -> float:
        """A cylinder panel's developed radius (of the neutral surface)."""
        s = self.panel.surface
        rel = self.vertices - s.origin
        radial = rel - np.outer(rel @ s.axis, s.axis)
        return float(np.median(np.linalg.norm(radial, axis=1)))

    @property
    def vertices(self) -> np.ndarray:
        """(n, 3) float64, mm: the 3D surface that was laid flat -- the panel's
        vertices, or with a sheet thickness their neutral-surface offset."""
        return self.flattening.vertices

    @property
    def faces(self) -> np.ndarray:
        """(m, 3) int64: the triangles (counter-clockwise in the plane)."""
        return self.flattening.faces

    @property
    def loops(self) -> tuple:
        """Outline loops (vertex indices), the outer one first (darts open it)."""
        return self.flattening.loops if self.darts else self.panel.loops

    def outline(self, loop: int = 0) -> np.ndarray:
        """(k, 2) float64, mm: flat points of one outline loop (not repeated at the end)."""
        return self.uv[self.loops[loop]]

    @cached_property
    def strains(self) -> TriangleStrain:
        """The principal strains of every triangle, as :func:`patterns.check`, the heat map and the DXF
        labels report them: zero for an exact development (:func:`patterns.measure.no_strain`)."""
        if self.flattening.method == "exact":
            return no_strain(self.vertices, self.faces)
        return triangle_strains(self.vertices, self.faces, self.flattening.uv)

    @property
    def area(self) -> float:
        """Flat area, mm^2."""
        p = self.uv[self.faces]
        a = p[:, 1] - p[:, 0]
        b = p[:, 2] - p[:, 0]
        return float(0.5 * np.sum(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]))


@dataclass(frozen=True, eq=False)
class FlatSeam:
    """A seam and its flat length on each side.

    Attributes
    ----------
    seam : patterns.Seam
    flat_lengths : (float, float)
        Flat length of the seam on side 0 and side 1, mm: the length of its
        polyline in the flat pattern, or, on an exactly developed side, of its
        exact curve laid flat (an isometry: the seam's exact CAD length, on the
        neutral surface with a thickness).  The difference is what puckers when
        the pieces are sewn or welded.
    held_lengths : (float or None, float or None) or None
        The flat length each side was held at (``flatten(seams="true")``): the
        3D length of its polyline times its ease, mm; None for a side that is
        not held (an exact development keeps every length without being
        held), None for a free seam.
    """

    seam: Seam
    flat_lengths: tuple
    held_lengths: tuple | None = None

    @property
    def length(self) -> float:
        """The seam's exact 3D length, mm."""
        return self.seam.length

    @property
    def mismatch(self) -> float:
        """``flat_lengths[0] - flat_lengths[1]``, mm."""
        return float(self.flat_lengths[0] - self.flat_lengths[1])


@dataclass(frozen=True, eq=False)
class Pattern:
    """A model's panels laid flat, with its seams.

    Attributes
    ----------
    model : patterns.Model
    panels : tuple of FlatPanel
        In the model's panel order.
    seams : tuple of FlatSeam
        In the model's seam order.
    method : str
        The flattening method used.
    max_strain : float or None
        The strain limit the pattern was flattened to (``flatten(max_strain=...)``,
        which cut darts to meet it): :func:`patterns.check` judges against it
        unless told another limit.
    thickness, k_factor, reference
        The sheet the panels were developed for (``flatten(thickness=...)``: each panel's
        neutral surface), as given; 0 thickness: the surface itself.
    laid_out : bool
        The panels have been placed on a sheet (:meth:`placed`).
    """

    model: Model
    panels: tuple
    seams: tuple
    method: str
    thickness: float = 0.0
    k_factor: float = 0.5
    reference: str = "mid"
    laid_out: bool = False
    """True once the panels have been placed on a sheet (:meth:`placed`): only
    then are panels checked against each other."""
    max_strain: float | None = None

    @property
    def name(self) -> str:
        return self.model.name

    @property
    def one_to_one(self) -> bool:
        """True when no panel overlaps itself."""
        return all(p.flattening.one_to_one for p in self.panels)

    @classmethod
    def combined(cls, patterns) -> Pattern:
        """Several patterns as one, to nest together (a marker of many parts): panels named
        ``"<pattern>/<panel>"``, seams renumbered, each pattern's own seams kept between its own panels."""
        patterns = list(patterns)
        if not patterns or not all(isinstance(p, Pattern) for p in patterns):
            raise InputError("combined() takes one or more patterns.Pattern")
        if any(p.laid_out for p in patterns):
            raise InputError("combined() takes patterns that are not laid out yet")
        panels, seams, flats, flat_seams = [], [], [], []
        for p in patterns:
            offset, sid = len(panels), len(seams)
            for flat in p.panels:
                if flat.source is not None:
                    raise InputError(f"{p.name}: combine the patterns before making copies")
                panels.append(replace(flat.panel, name=f"{p.name}/{flat.panel.name}"))
                flats.append(replace(flat, name=f"{p.name}/{flat.name}", panel=panels[-1]))
            for fs in p.seams:
                seam = replace(fs.seam, id=sid + fs.seam.id, panels=tuple(offset + k for k in fs.seam.panels))
                seams.append(seam)
                flat_seams.append(replace(fs, seam=seam))
        model = Model(name=" + ".join(p.name for p in patterns), panels=tuple(panels), seams=tuple(seams),
                      max_edge=max(p.model.max_edge for p in patterns))
        first = patterns[0]
        return replace(first, model=model, panels=tuple(flats), seams=tuple(flat_seams),
                       method="+".join(dict.fromkeys(p.method for p in patterns)))

    def source_of(self, index: int) -> int:
        """The panel whose seams panel ``index`` shares: itself, or the panel it is a copy of."""
        source = self.panels[index].source
        return index if source is None else source

    def with_copies(self, counts, *, mirror: bool = False) -> Pattern:
        """The pattern with ``counts[i]`` pieces of panel ``i`` (and, with ``mirror``, as many mirror
        images besides): the copies come after the panels, named ``face0 #2``, ``face0 mirrored``, ...,
        each sharing its source's seams, notches and labels."""
        counts = [int(c) for c in counts]
        if len(counts) != len(self.panels) or min(counts, default=1) < 1:
            raise InputError(f"{self.name}: one count >= 1 per panel, got {counts!r}")
        extra = []
        for i, (flat, n) in enumerate(zip(self.panels, counts)):
            for k in range(1, n):
                extra.append(flat.copy(f"{flat.name} #{k + 1}", source=i))
            if mirror:
                for k in range(n):
                    label = f"{flat.name} mirrored" if k == 0 else f"{flat.name} #{k + 1} mirrored"
                    extra.append(flat.copy(label, source=i, mirrored=True))
        return replace(self, panels=self.panels + tuple(extra))

    def placed(self, placements) -> Pattern:
        """A copy with the panels moved rigidly: one ``(angle, dx, dy)`` per panel.

        Rotation (radians) about the origin of the flattened panel, then a
        translation (mm).  Nothing is scaled; seams' flat lengths are unchanged.
        """


        placements = list(placements)
        if len(placements) != len(self.panels):
            raise InputError(f"{self.name}: {len(placements)} placements for {len(self.panels)} panels")
        panels = []
        for panel, place in zip(self.panels, placements):
            try:
                angle, dx, dy = (float(x) for x in place)
            except (TypeError, ValueError):
                raise InputError(f"{self.name}: a placement is (angle, dx, dy), got {place!r}") from None
            if not np.all(np.isfinite([angle, dx, dy])):
                raise InputError(f"{self.name}: placements must be finite, got {place!r}")
            panels.append(replace(panel, placement=(angle, dx, dy)))
        return replace(self, panels=tuple(panels), laid_out=True)

    def __repr__(self) -> str:
        return (f"Pattern({self.name!r}, {counted(len(self.panels), 'panel')}, {counted(len(self.seams), 'seam')}, "
                f"method={self.method!r})")
