"""Stage 5b of an unfold: a cut across a bend whose wall is not square to the sheet, drawn on the neutral layer.

A hole drilled after bending, through the bend (along its bisector, say), has
a wall that leaves the two faces of the sheet at different places: the trace
on the inside face and the one on the outside face develop to different
shapes (85 and 114 mm² for a 10 mm hole across a 90-degree bend of a 1.5 mm
sheet).  The blank is cut flat and then bent, and only the neutral layer keeps
its length in the bend: the hole to cut is the wall's trace on the neutral
layer, developed.  :func:`neutral_trace` finds it point by point: from each
point of the fixed face's trace, along the wall's straight line through the
sheet (a drilled cylinder's axis, a cone's generator, a plane's line square to
the cut edge), to the neutral layer (the neutral cylinder in the bend, the
plane as deep in a flange), which it develops as the bend and flanges are.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..curves import Loop, Polyline
from .faces import SheetFace, normal, point, uv_mid
from .join import flat
from .sheet import SheetModel

__all__ = ["SQUARE", "neutral_trace"]

SQUARE = 1e-9
"""A wall whose straight line through the sheet is within this of the sheet's normal (``1 - |cos|``) at
every point of a cut is square to the sheet: the cut is drawn from the fixed face, exact lines and arcs."""
SAMPLE = 0.0001
"""Chord error of the fixed face's trace sampled for an oblique cut, mm."""


@dataclass(frozen=True)
class _Junction:
    """Where a bend meets a flange: the plane through the bend's axis square to the flange; ``side`` (3,)
    points from it along the flange, ``toward`` (3,) from the axis to the flange's plane.  A point is past
    the junction, in the flange, when it is ahead of the axis along both (a bend of 180 degrees or more has
    both its junctions in one plane, on either side of the axis)."""

    bend: int
    flange: int
    origin: np.ndarray
    side: np.ndarray
    toward: np.ndarray

    def past(self, q: np.ndarray) -> bool:
        return bool((q - self.origin) @ self.side > 0 and (q - self.origin) @ self.toward > 0)


def _ruling(wall) -> Callable[[np.ndarray, np.ndarray], np.ndarray] | None:
    """The wall face's straight line through the sheet at a point, as a function ``(p, tangent) -> (3,)``
    (unoriented); None for a wall that has none (a spline)."""
    from OCP.BRepAdaptor import BRepAdaptor_Surface
    from OCP.GeomAbs import GeomAbs_Cone, GeomAbs_Cylinder, GeomAbs_Plane

    s = BRepAdaptor_Surface(wall)
    kind = s.GetType()
    if kind == GeomAbs_Cylinder:
        d = s.Cylinder().Axis().Direction()
        axis = np.array([d.X(), d.Y(), d.Z()])
        return lambda p, tangent: axis
    if kind == GeomAbs_Cone:
        a = s.Cone().Apex()
        apex = np.array([a.X(), a.Y(), a.Z()])
        return lambda p, tangent: (p - apex) / np.linalg.norm(p - apex)
    if kind == GeomAbs_Plane:
        d = s.Plane().Axis().Direction()
        n = np.array([d.X(), d.Y(), d.Z()])
        return lambda p, tangent: np.cross(n, tangent) / np.linalg.norm(np.cross(n, tangent))
    return None


def _samples(edge, face: SheetFace, reverse: bool) -> tuple:
    """(k, 3) points, (k, 3) unit tangents and (k, 2) parameters on ``face`` along a skin edge, in the
    loop's direction."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Curve2d
    from OCP.GCPnts import GCPnts_QuasiUniformDeflection
    from OCP.gp import gp_Pnt, gp_Vec

    curve, c2 = BRepAdaptor_Curve(edge), BRepAdaptor_Curve2d(edge, face.face)
    sampler = GCPnts_QuasiUniformDeflection(curve, SAMPLE)
    ts = [sampler.Parameter(k) for k in range(1, sampler.NbPoints() + 1)] if sampler.IsDone() else []
    ts = np.unique(np.concatenate([ts, [curve.FirstParameter(), curve.LastParameter()]]))
    if reverse:
        ts = ts[::-1]
    ps, tangents, uvs = [], [], []
    for t in ts:
        p, d = gp_Pnt(), gp_Vec()
        curve.D1(float(t), p, d)
        q = c2.Value(float(t))
        ps.append((p.X(), p.Y(), p.Z()))
        tangents.append((d.X(), d.Y(), d.Z()))
        uvs.append((q.X(), q.Y()))
    tangents = np.array(tangents)
    return np.array(ps), tangents / np.linalg.norm(tangents, axis=1)[:, None], np.array(uvs)


def _uv(face: SheetFace, q: np.ndarray, surfaces: dict) -> np.ndarray:
    """(2,) parameters of the point of ``face``'s surface nearest ``q`` (a cylinder's angle on the branch
    nearest the face's middle); ``surfaces`` keeps each face's projector and middle angle, made once."""
    from OCP.BRep import BRep_Tool
    from OCP.gp import gp_Pnt
    from OCP.ShapeAnalysis import ShapeAnalysis_Surface

    if face.index not in surfaces:
        surfaces[face.index] = (ShapeAnalysis_Surface(BRep_Tool.Surface_s(face.face)), uv_mid(face.face)[0])
    projector, mid = surfaces[face.index]
    uv = projector.ValueOfUV(gp_Pnt(*map(float, q)), 1e-9)
    u, v = uv.X(), uv.Y()
    if face.kind == "cylinder":
        u = mid + (u - mid + np.pi) % (2 * np.pi) - np.pi
    return np.array([u, v])


def neutral_trace(chain: tuple, *, topology, faces: tuple, sheet: SheetModel, bends: tuple, maps: dict,
                  motions: dict) -> Loop | None:
    """A closed cut contour redrawn on the neutral layer, when it crosses a bend and its wall is not square
    to the sheet.

    Parameters
    ----------
    chain : tuple of (int, int, bool)
        The loop's skin edges in order: ``(edge, skin face, reversed)`` (:func:`~patterns.sheetmetal.contour.
        cut_loops`' ``chains``).
    topology : patterns.tessellate.topology.Topology
    faces : tuple of SheetFace
    sheet : SheetModel
    bends : tuple of BendGroup
    maps : dict
        ``{face: FaceMap}`` of the skin.
    motions : dict
        ``{face: patterns.curves.Motion}``: each skin face's placement on the blank.

    Returns
    -------
    patterns.curves.Loop or None
        One polyline per edge of ``chain`` through the developed neutral-layer points (mm, the loop's
        direction kept); None where the cut is drawn as it is: it crosses no cylindrical bend, its wall is
        square to the sheet, or a wall has no straight line through the sheet (a spline) or one that misses
        the neutral layer.
    """
    touched = {i for _, i, _ in chain}
    groups = [k for k, g in enumerate(bends) if g.kind == "cylinder" and touched & set(g.faces)]
    if not groups or any(faces[i].kind not in ("plane", "cylinder") for i in touched):
        return None
    walls = []
    for e, i, _ in chain:
        rims = [f for f in topology.edge_faces[e] if f not in sheet.skin]
        ruling = _ruling(topology.faces[rims[0]]) if len(rims) == 1 else None
        if ruling is None:
            return None
        walls.append(ruling)
    samples = [_samples(topology.edges[e], faces[i], reverse) for e, i, reverse in chain]
    inward = [-np.array([normal(faces[i], *uv) for uv in uvs]) for (_, i, _), (_, _, uvs) in zip(chain, samples)]
    rays = [np.array([ruling(p, t) for p, t in zip(ps, ts)]) for ruling, (ps, ts, _) in zip(walls, samples)]
    rays = [r * np.sign(np.einsum("ij,ij->i", r, n))[:, None] for r, n in zip(rays, inward)]
    if max(float(np.max(1 - np.einsum("ij,ij->i", r, n))) for r, n in zip(rays, inward)) < SQUARE:
        return None
    layer = _Layer.of(groups, faces=faces, sheet=sheet, bends=bends)
    pieces, last = [], None
    for (_, i, _), (ps, _, _), ray in zip(chain, samples, rays):
        pts = [layer.developed(p, d, i, maps=maps, motions=motions) for p, d in zip(ps, ray)]
        if any(q is None for q in pts):
            return None
        pts = np.array(pts)
        if last is not None:
            pts[0] = last
        last = pts[-1]
        pieces.append(Polyline(pts))
    first = pieces[0].points()
    pieces[0] = Polyline(np.vstack([last[None, :], first[1:]]))
    return Loop(tuple(pieces))


@dataclass(frozen=True)
class _Layer:
    """The neutral layer of the bends a cut crosses and of their flanges."""

    faces: tuple
    bends: tuple
    groups: tuple
    junctions: tuple
    depth: float
    planes: dict
    surfaces: dict = field(default_factory=dict, compare=False)  # each face's projector, made once (_uv)

    @classmethod
    def of(cls, groups: list, *, faces: tuple, sheet: SheetModel, bends: tuple) -> _Layer:
        junctions = []
        for k in groups:
            f = faces[bends[k].faces[0]]
            for j in bends[k].faces:
                for b, _ in sheet.neighbours[j]:
                    if b in sheet.skin and faces[b].kind == "plane" and b not in {x.flange for x in junctions
                                                                                   if x.bend == k}:
                        n, m = normal(faces[b], *uv_mid(faces[b].face)), point(faces[b], *uv_mid(faces[b].face))
                        origin = np.asarray(f.origin, dtype=np.float64)
                        side = np.cross(f.axis, n)
                        side /= np.linalg.norm(side)
                        side = side if (m - origin) @ side > 0 else -side
                        toward = n if (m - origin) @ n > 0 else -n
                        junctions.append(_Junction(k, b, origin, side, toward))
        first = bends[groups[0]]
        depth = abs(faces[first.faces[0]].radius - first.neutral_radius)  # a flange's neutral plane under its skin
        planes = {}
        for i in sorted(sheet.skin):
            if faces[i].kind == "plane":
                uv = uv_mid(faces[i].face)
                planes[i] = (point(faces[i], *uv), normal(faces[i], *uv))
        return cls(faces, bends, tuple(groups), tuple(junctions), depth, planes)

    def _on_bend(self, k: int, p: np.ndarray, d: np.ndarray) -> np.ndarray | None:
        """The first point ahead of ``p`` along ``d`` on bend ``k``'s neutral cylinder."""
        f, rn = self.faces[self.bends[k].faces[0]], self.bends[k].neutral_radius
        a = f.axis
        r0, dd = p - f.origin, d.copy()
        r0, dd = r0 - (r0 @ a) * a, dd - (dd @ a) * a
        qa, qb, qc = dd @ dd, r0 @ dd, r0 @ r0 - rn * rn
        disc = qb * qb - qa * qc
        if qa <= 0 or disc < 0:
            return None
        roots = sorted(((-qb - np.sqrt(disc)) / qa, (-qb + np.sqrt(disc)) / qa))
        s = next((r for r in roots if r > -1e-9), None)
        return None if s is None else p + s * d

    def _on_flange(self, b: int, p: np.ndarray, d: np.ndarray) -> np.ndarray | None:
        """The point along ``d`` from ``p`` on flange ``b``'s neutral plane."""
        origin, n = self.planes[b]
        across = -(d @ n)
        if across <= 1e-12:
            return None
        return p + (self.depth + (p - origin) @ n) / across * d

    def developed(self, p: np.ndarray, d: np.ndarray, face: int, *, maps: dict, motions: dict) -> np.ndarray | None:
        """(2,) the blank position of the neutral-layer point of the wall's line from ``p`` (on skin face
        ``face``) along ``d`` into the sheet, mm; None where it cannot be found."""
        bend = next((k for k in self.groups if face in self.bends[k].faces), None)
        flange = face if bend is None else None
        for _ in range(4):  # bend -> flange -> bend ... settles in two
            if bend is not None:
                q = self._on_bend(bend, p, d)
                if q is None:
                    return None
                past = next((x for x in self.junctions if x.bend == bend and x.past(q)), None)
                if past is None:
                    on = face if face in self.bends[bend].faces else self.bends[bend].faces[0]
                    return flat(maps, motions, on, _uv(self.faces[on], q, self.surfaces)[None, :])[0]
                bend, flange = None, past.flange
            else:
                if flange not in self.planes:
                    return None
                q = self._on_flange(flange, p, d)
                if q is None:
                    return None
                back = next((x for x in self.junctions if x.flange == flange and not x.past(q)), None)
                if back is None:
                    return flat(maps, motions, flange, _uv(self.faces[flange], q, self.surfaces)[None, :])[0]
                bend, flange = back.bend, None
        return None
