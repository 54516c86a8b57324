"""Stage 5b of an unfold: a cut across a bend whose wall is not square to the sheet, drawn on the neutral layer.

A hole drilled after bending, through the bend (along its bisector, say), has
a wall that leaves the two faces of the sheet at different places: the trace
on the inside face and the one on the outside face develop to different
shapes (85 and 114 mm² for a 10 mm hole across a 90-degree bend of a 1.5 mm
sheet).  The blank is cut flat and then bent, and only the neutral layer keeps
its length in the bend: the hole to cut is the wall's trace on the neutral
layer, developed.  :func:`neutral_trace` finds it point by point: from each
point of the fixed face's trace, along a straight line of the wall through the
sheet (a drilled cylinder's axis, a cone's generator; on a plane, the
direction of its own edges across the sheet at the two ends, turned from one
to the other along the cut), to the first point of the neutral layer (the
neutral cylinder within each bend's angle, the plane as deep as that bend's
neutral layer under each flange, ending at its bends and its free end), which it
develops as the bend and flanges are; between samples the developed trace is
refined until it bows no more than :data:`SAMPLE`.  A cut edge whose trace lies
within :data:`SQUARE` of the fixed face's on the blank is square to the sheet
and keeps its exact piece (a line, an arc); a cut on flanges only is traced
when its tilted wall reaches a bend under the skin.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import shapely

from ..curves import Loop, Polyline
from ..tessellate.topology import Topology
from .contour import edge_parameters, edge_piece
from .faces import SheetFace, normal, point, uv_mid
from .join import flat
from .sheet import SheetModel

__all__ = ["LOOK", "ROUNDS", "SAMPLE", "SQUARE", "STEEP", "Oblique", "neutral_trace"]

SQUARE = 0.001
"""A cut edge whose neutral-layer trace lies within this of the fixed face's trace on the blank (mm, each way)
is square to the sheet: drawn from the fixed face, its exact line or arc.  A cut is redrawn only when one of its
edges is further off: a wall tilted by 0.04 degrees in a 1.5 mm sheet moves it 0.001 mm."""
SAMPLE = 0.00002
"""Chord error of an oblique cut's trace, mm: of the fixed face's trace as sampled, and of the developed neutral
trace between its samples (halved where it bows more, up to :data:`ROUNDS` times)."""
ROUNDS = 24
"""How many times an oblique cut's samples are halved where its developed trace bows."""
LOOK = 0.01
"""Chord error of the first look at a cut (is its wall square to the sheet; does it reach a bend), mm."""
STEEP = 0.05
"""A wall whose line through the sheet runs within this of the sheet's plane (the cosine of its angle to the
sheet's normal) is not traced: its trace on the neutral layer is too far from the face's to be one cut."""


@dataclass(frozen=True)
class Oblique:
    """A cut across a bend with a wall not square to the sheet.

    Attributes
    ----------
    loop : patterns.curves.Loop or None
        The cut redrawn: each cut edge as its trace on the neutral layer (a polyline, mm), or its exact piece
        where that is square; None where it could not be traced (``why``).
    faces : tuple of int
        The skin face of each piece of ``loop``.
    why : str
        Why it was not traced ("" when it was): its wall has no straight line through the sheet, changes
        within the sheet (a counterbore or a countersink), or runs nearly along it.
    """

    loop: Loop | None
    faces: tuple
    why: str = ""


@dataclass(frozen=True)
class _Junction:
    """Where bend ``bend`` meets flange ``flange``: ``side`` (3,) points from the plane through the bend's axis
    square to the flange along the flange; the flange's neutral plane lies ``depth`` mm under its skin
    (``origin`` (3,), outward ``normal`` (3,)), as deep as the bend's neutral cylinder under the bend's skin."""

    bend: int
    flange: int
    axis_point: np.ndarray
    side: np.ndarray
    origin: np.ndarray
    normal: np.ndarray
    depth: float

    def on_flange(self, q: np.ndarray) -> bool:
        return bool((q - self.axis_point) @ self.side >= -1e-9)


def _across(topology, wall: int, skin: frozenset, at: np.ndarray, inward: np.ndarray) -> np.ndarray | None:
    """(3,) the direction into the sheet of plane ``wall``'s edge across the sheet (on no skin face) that
    starts at ``at``: the wall's own line across the sheet there; None when it has none."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.gp import gp_Pnt, gp_Vec

    for wire in topology.wires[wall]:
        for f, edge in wire:
            if topology.degenerate[f] or any(k in skin for k in topology.edge_faces[f]):
                continue
            curve = BRepAdaptor_Curve(edge)
            for t in (curve.FirstParameter(), curve.LastParameter()):
                p, d = gp_Pnt(), gp_Vec()
                curve.D1(t, p, d)
                if np.linalg.norm(np.array([p.X(), p.Y(), p.Z()]) - at) < 1e-6 and d.Magnitude() > 1e-12:
                    v = np.array([d.X(), d.Y(), d.Z()]) / d.Magnitude()
                    return v if v @ inward > 0 else -v
    return None


def _rulings(topology, faces: tuple, skin: frozenset, wall: int, run: list, along: list | None = None,
             ends: list | None = None) -> list | None:
    """The wall's straight lines through the sheet at the points of a run of cut edges along it: per edge of
    ``run`` (``[((k, 3) points, (k, 3) inward normals), ...]``, in the loop's order), (k, 3) unit directions
    into the sheet; None for a wall with none (a spline surface).  A plane's lines turn from its edge across
    the sheet at the run's start to the one at its end (``ends``, two (3,), where given: :func:`_ends`), evenly
    along the run: by ``along`` (per edge (k,), the share of the run's length before each point) where given,
    else by the points' own polyline."""
    f = faces[wall]
    ps, inward = np.vstack([p for p, _ in run]), np.vstack([n for _, n in run])
    if f.kind == "cylinder":
        rays = np.broadcast_to(f.axis, ps.shape).copy()
    elif f.kind == "cone":
        a = f.adaptor.Cone().Apex()
        rays = ps - np.array([a.X(), a.Y(), a.Z()])
    elif f.kind == "plane":
        n = normal(f, *uv_mid(f.face))
        ends = ends if ends is not None else _ends(topology, f, skin, wall, ps, inward)
        if along is not None:
            lam = np.concatenate(along)[:, None]
        else:
            along = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(ps, axis=0), axis=1))])
            lam = (along / along[-1] if along[-1] > 0 else np.zeros(len(ps)))[:, None]
        rays = (1 - lam) * ends[0] + lam * ends[1]
        rays -= (rays @ n)[:, None] * n  # in the plane
    else:
        return None
    rays *= np.sign(np.einsum("ij,ij->i", rays, inward))[:, None]
    length = np.linalg.norm(rays, axis=1)
    if np.any(length < 1e-12):
        return None
    rays /= length[:, None]
    return np.split(rays, np.cumsum([len(p) for p, _ in run])[:-1])


def _ends(topology, f: SheetFace, skin: frozenset, wall: int, ps: np.ndarray, inward: np.ndarray) -> list:
    """A plane wall's two lines across the sheet at a run's first and last points ``ps[0]``, ``ps[-1]`` (of
    (k, 3); ``inward`` (k, 3) the skin's inward normals): its own edges there, or where it has none (a closed
    edge) its line nearest the sheet's normal."""
    n = normal(f, *uv_mid(f.face))
    ends = [_across(topology, wall, skin, ps[j], inward[j]) for j in (0, -1)]
    return [v if v is not None else inward[j] - (inward[j] @ n) * n for v, j in zip(ends, (0, -1))]


def _runs(walls: list) -> list:
    """The chain's edge numbers grouped into runs of consecutive edges along one wall face, in order (a run
    may go on from the last edge to the first)."""
    n = len(walls)
    start = next((k for k in range(n) if walls[k] != walls[k - 1]), 0)
    runs: list = []
    for k in range(start, start + n):
        if runs and walls[k % n] == walls[runs[-1][-1]]:
            runs[-1].append(k % n)
        else:
            runs.append([k % n])
    return runs


def _at(edge, face: SheetFace, ts: np.ndarray) -> tuple:
    """(k, 3) points and (k, 2) parameters on ``face`` of a cut edge at its curve's parameters ``ts`` (k,)."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Curve2d

    curve, c2 = BRepAdaptor_Curve(edge), BRepAdaptor_Curve2d(edge, face.face)
    ps, uvs = [], []
    for t in ts:
        p, q = curve.Value(float(t)), c2.Value(float(t))
        ps.append((p.X(), p.Y(), p.Z()))
        uvs.append((q.X(), q.Y()))
    return np.array(ps, dtype=np.float64).reshape(-1, 3), np.array(uvs, dtype=np.float64).reshape(-1, 2)


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


def _holds(face: SheetFace, q: np.ndarray, surfaces: dict) -> bool:
    """Whether ``q`` (3,) lies on the bounded face (its surface's nearest point within 1e-6 mm, in its
    boundary or on it)."""
    from OCP.BRepClass import BRepClass_FaceClassifier
    from OCP.gp import gp_Pnt2d
    from OCP.TopAbs import TopAbs_IN, TopAbs_ON

    uv = _uv(face, q, surfaces)
    if np.linalg.norm(point(face, *uv) - q) > 1e-6:
        return False
    state = BRepClass_FaceClassifier(face.face, gp_Pnt2d(*map(float, uv)), 1e-6).State()
    return state in (TopAbs_IN, TopAbs_ON)


def _square_wall(face: SheetFace, ps: np.ndarray, inward: np.ndarray, thickness: float, surfaces: dict) -> bool:
    """Whether a wall with no straight line through the sheet is square to it at every point ``ps`` (k, 3):
    tilted so little that across the sheet it moves less than :data:`SQUARE`."""
    for p, n in zip(ps, inward):
        m = normal(face, *_uv(face, p, surfaces))
        c = abs(float(m @ n))
        if c >= 1 or thickness * c / np.sqrt(1 - c * c) > SQUARE:
            return False
    return True


def _reach(topology: Topology, b: int, xs: tuple) -> tuple:
    """How far flange ``b`` reaches from each of its junctions ``xs``, along the junction's ``side`` (mm): the
    furthest of its edges, sampled at 1e-5 mm chord error (its free end, or its next bend).  Only the edges
    whose bounding box reaches past the furthest point found so far are sampled (a flange's holes never are)."""
    from OCP.Bnd import Bnd_Box
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.BRepBndLib import BRepBndLib

    edges = [edge for walk in topology.wires[b] for _, edge in walk]
    corners = []
    for edge in edges:
        box = Bnd_Box()
        BRepBndLib.Add_s(edge, box)
        lo, hi = box.CornerMin(), box.CornerMax()
        x0, y0, z0, x1, y1, z1 = lo.X(), lo.Y(), lo.Z(), hi.X(), hi.Y(), hi.Z()
        corners.append([(x, y, z) for x in (x0, x1) for y in (y0, y1) for z in (z0, z1)])
    corners = np.array(corners)  # (edges, 8, 3)
    sampled: dict = {}
    out = []
    for x in xs:
        def along(q: np.ndarray) -> np.ndarray:  # written out: no BLAS product (the CPU's kernels round it)
            d = q - x.axis_point
            return d[..., 0] * x.side[0] + d[..., 1] * x.side[1] + d[..., 2] * x.side[2]

        bound = along(corners).max(axis=1)
        best = -np.inf
        for i in sorted(range(len(edges)), key=lambda i: (-bound[i], i)):
            if bound[i] < best:
                break
            if i not in sampled:
                curve = BRepAdaptor_Curve(edges[i])
                sampled[i] = np.array([(q.X(), q.Y(), q.Z()) for q in (
                    curve.Value(float(t)) for t in edge_parameters(edges[i], 1e-5, reverse=False))])
            best = max(best, float(along(sampled[i]).max()))
        out.append(best)
    return tuple(out)


def _bowed(xy: np.ndarray) -> np.ndarray:
    """(j,) bool: for ``xy`` (2 j + 1, 2) the ends and middles of ``j`` intervals interleaved, whether each
    middle lies further than :data:`SAMPLE` from its interval's chord."""
    a, b, m = xy[0:-1:2], xy[2::2], xy[1::2]
    ab = b - a
    length = np.einsum("ij,ij->i", ab, ab)
    lam = np.clip(np.einsum("ij,ij->i", m - a, ab) / np.where(length > 0, length, 1.0), 0.0, 1.0)
    return np.linalg.norm(a + lam[:, None] * ab - m, axis=1) > SAMPLE


def _lines(edges: list, ts: list, wall: int, *, topology, faces: tuple, sheet: SheetModel,
           surfaces: dict, along: list | None = None, ends: list | None = None) -> tuple | str | None:
    """``(at, inwards, rays)`` of a run's cut edges (``edges``: ``(edge, skin face, reversed)``) at their curves'
    parameters ``ts``: per edge its (k, 3) points and (k, 2) skin parameters, (k, 3) inward normals and (k, 3)
    wall lines into the sheet; None where the wall is square to the sheet at every point (it moves less than
    :data:`SQUARE` across it); a str saying why it cannot be traced."""
    at = [_at(edge, face, t) for (edge, face, _), t in zip(edges, ts)]
    inwards = [np.broadcast_to(-normal(face, *uv_mid(face.face)), (len(uvs), 3)) if face.kind == "plane" else
               -np.array([normal(face, *uv) for uv in uvs]).reshape(-1, 3) for (_, face, _), (_, uvs) in zip(edges, at)]
    rays = _rulings(topology, faces, sheet.skin, wall, [(ps, n) for (ps, _), n in zip(at, inwards)], along, ends)
    if rays is None:
        if all(_square_wall(faces[wall], ps, n, sheet.thickness, surfaces) for (ps, _), n in zip(at, inwards)):
            return None
        return "its wall has no straight line through the sheet (a spline surface)"
    cos = np.concatenate([np.einsum("ij,ij->i", r, n) for r, n in zip(rays, inwards)])
    if float(np.min(cos)) < STEEP:
        return "its wall runs nearly along the sheet"
    if float(np.max(sheet.thickness * np.sqrt(np.clip(1 - cos * cos, 0.0, None)) / cos)) <= SQUARE:
        return None
    return at, inwards, rays


def _traced(run: list, wall: int, *, chain: tuple, topology, faces: tuple, sheet: SheetModel, layer: _Layer,
            maps: dict, motions: dict, deflection: float = SAMPLE, rounds: int = ROUNDS) -> tuple:
    """``(pieces, reached)`` for a run of chain edges (consecutive edges along one wall face): ``pieces`` per
    edge the (k, 2) blank positions of its wall's trace on the neutral layer (mm), or all None where the run is
    square to the sheet (its trace within :data:`SQUARE` of the fixed face's), or a str saying why it cannot be
    traced; ``reached`` whether a line of the wall met a bend's neutral cylinder.  Each edge is sampled at
    ``deflection`` mm chord error on the skin, then halved where the developed trace bows more than
    :data:`SAMPLE` from its chords, up to ``rounds`` times: a straight edge of a flange whose lines meet a bend
    develops to a curve."""
    edges = [(topology.edges[chain[k][0]], faces[chain[k][1]], chain[k][2]) for k in run]
    ts = [edge_parameters(edge, deflection, reverse=reverse) for edge, _, reverse in edges]
    # where each parameter lies along the run (mm, by the first samples' polyline): a plane wall's line at a
    # point is then the same whichever points are around it, and a point traced once is kept (``done``)
    first = [_at(edge, face, t) for (edge, face, _), t in zip(edges, ts)]
    lengths = [np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(ps, axis=0), axis=1))] for ps, _ in first]
    starts = np.r_[0.0, np.cumsum([x[-1] for x in lengths])]
    total = starts[-1] if starts[-1] > 0 else 1.0
    increasing = [(t, x) if t[0] <= t[-1] else (t[::-1], x[::-1]) for t, x in zip(ts, lengths)]
    ends = None
    if faces[wall].kind == "plane":
        (p0, uv0), (p1, uv1) = first[0], first[-1]
        inward = np.array([-normal(edges[0][1], *uv0[0]), -normal(edges[-1][1], *uv1[-1])])
        ends = _ends(topology, faces[wall], sheet.skin, wall, np.array([p0[0], p1[-1]]), inward)
    done: list = [{} for _ in run]  # per edge: parameter -> (developed (2,), reached, skin parameters (2,))
    for round_ in range(rounds):
        full = [np.insert(t, np.arange(1, len(t)), (t[:-1] + t[1:]) / 2) for t in ts]  # ends and middles
        new = [np.array([t for t in f if float(t) not in d]) for f, d in zip(full, done)]
        along = [(starts[j] + np.interp(t, *increasing[j])) / total for j, t in enumerate(new)]
        got = _lines(edges, new, wall, topology=topology, faces=faces, sheet=sheet, surfaces=layer.surfaces,
                     along=along, ends=ends)
        if got is None:
            return [None] * len(run), False
        if isinstance(got, str):
            return got, False
        at, _, rays = got
        for j, ((ps, uvs), ds) in enumerate(zip(at, rays)):
            for t, p, uv, d in zip(new[j], ps, uvs, ds):
                found = layer.neutral(p, d, sheet.thickness / STEEP)
                if found is None:
                    return ("its wall's line meets no neutral layer (two bends with no flat between them, whose "
                            "neutral layers lie at different depths, leave a gap)"), False
                if not _holds(faces[wall], found[0], layer.surfaces):
                    return ("its wall changes within the sheet (a counterbore or a countersink: a step before the "
                            "neutral layer)"), False
                done[j][float(t)] = (layer.developed(*found, maps=maps, motions=motions), found[1] in layer.bend_faces,
                                     uv)
        traced = [np.array([done[j][float(t)][0] for t in f]) for j, f in enumerate(full)]
        reached = any(done[j][float(t)][1] for j, f in enumerate(full) for t in f)
        kept = [t[1::2][_bowed(xy)] for t, xy in zip(full, traced)]
        if round_ == rounds - 1 or not any(len(k) for k in kept):
            break
        ts = [np.sort(np.concatenate([t, k]))[::-1 if t[0] > t[-1] else 1] for t, k in zip(ts, kept)]
    skin = np.vstack([flat(maps, motions, chain[k][1], np.array([done[j][float(t)][2] for t in f]))
                      for j, (k, f) in enumerate(zip(run, full))])
    drawn = np.vstack(traced)
    off = max(float(np.max(shapely.distance(shapely.points(drawn), shapely.LineString(skin)))),
              float(np.max(shapely.distance(shapely.points(skin), shapely.LineString(drawn)))))
    return ([None] * len(run) if off <= SQUARE else traced), reached


def neutral_trace(chain: tuple, *, topology, faces: tuple, sheet: SheetModel, bends: tuple, maps: dict,
                  motions: dict) -> Oblique | None:
    """A closed cut contour redrawn on the neutral layer, when its wall is not square to the sheet and crosses a
    bend.

    Parameters
    ----------
    chain : tuple of (int, int, bool)
        The loop's cut edges in order: ``(edge, skin face, reversed)`` (:func:`~patterns.sheetmetal.contour.
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
    Oblique or None
        The cut redrawn (the loop's direction kept, one piece per edge of ``chain``), or why it could not be;
        None where the cut is drawn as it is: every edge is square to the sheet (:data:`SQUARE`), or it lies on
        flanges only and its wall's lines meet no bend's neutral layer (or cannot be followed), or no
        cylindrical bend is next to it.
    """
    touched = {i for _, i, _ in chain}
    if any(faces[i].kind not in ("plane", "cylinder") for i in touched):
        return None
    bend_of = {j: k for k, g in enumerate(bends) if g.kind == "cylinder" for j in g.faces}
    crossing = any(i in bend_of for i in touched)  # else a cut on flanges, whose wall may reach a bend
    near = touched | {b for i in touched for b, _ in sheet.neighbours[i]}
    groups = {bend_of[j] for j in near if j in bend_of}
    # every flange of those bends bounded by all its bends: a line may leave the layer past one of them
    flanges = {b for k in groups for j in bends[k].faces for b, _ in sheet.neighbours[j] if faces[b].kind == "plane"}
    groups |= {bend_of[j] for b in flanges for j, _ in sheet.neighbours[b] if j in bend_of}
    if not groups:
        return None
    walls = []
    for e, _, _ in chain:
        rims = [f for f in topology.edge_faces[e] if f not in sheet.skin]
        if len(rims) != 1:
            return None
        walls.append(rims[0])
    runs = _runs(walls)
    surfaces: dict = {}
    if all(_lines([(topology.edges[chain[k][0]], faces[chain[k][1]], chain[k][2]) for k in run],
                  [edge_parameters(topology.edges[chain[k][0]], LOOK, reverse=chain[k][2]) for k in run], walls[run[0]],
                  topology=topology, faces=faces, sheet=sheet, surfaces=surfaces) is None for run in runs):
        return None  # square to the sheet everywhere (a first look at a coarse sampling): drawn as it is
    layer = _Layer.of(sorted(groups), topology=topology, faces=faces, sheet=sheet, bends=bends, surfaces=surfaces)
    common = dict(chain=chain, topology=topology, faces=faces, sheet=sheet, layer=layer, maps=maps, motions=motions)
    if not crossing:  # on flanges only: redrawn where its wall is tilted and reaches a bend (a coarse look first)
        looks = [_traced(run, walls[run[0]], **common, deflection=LOOK, rounds=1) for run in runs]
        if not any(reached for got, reached in looks if not isinstance(got, str)) or \
                any(isinstance(got, str) for got, _ in looks):
            return None
    pieces: list = [None] * len(chain)  # (piece, square) per chain edge
    for run in runs:
        got, _ = _traced(run, walls[run[0]], **common)
        if isinstance(got, str):
            return None if not crossing else Oblique(None, (), got)
        for k, traced in zip(run, got):
            e, i, reverse = chain[k]
            pieces[k] = (edge_piece(topology.edges[e], i, maps, motions, reverse), True) if traced is None else \
                (Polyline(traced), False)
    if all(square for _, square in pieces):
        return None
    out = [piece for piece, _ in pieces]
    for k, (piece, square) in enumerate(pieces):  # a polyline ends where an exact piece after it starts
        if not square and pieces[(k + 1) % len(pieces)][1]:
            out[k] = Polyline(np.vstack([piece.points()[:-1], out[(k + 1) % len(out)].points()[:1]]))
    for k, (piece, square) in enumerate(pieces):  # and starts where the piece before it ends
        if not square:
            out[k] = Polyline(np.vstack([out[k - 1].points()[-1:], out[k].points()[1:]]))
    return Oblique(Loop(tuple(out)), tuple(i for _, i, _ in chain))


@dataclass(frozen=True)
class _Layer:
    """The neutral layer of the bends next to a cut (and those of their flanges' other bends) and of their
    flanges, each flange's bounded by all its bends."""

    faces: tuple
    bends: tuple
    groups: tuple
    junctions: dict  # {flange: its junctions}
    spans: dict
    bend_faces: frozenset  # the faces of its bends
    topology: Topology = field(compare=False)  # the part's: its flanges' wires, for reach
    surfaces: dict = field(default_factory=dict, compare=False)  # each face's projector, made once (_uv)
    reaches: dict = field(default_factory=dict, compare=False)  # {flange: reach(flange)}, each found once

    def reach(self, b: int) -> tuple:
        """How far flange ``b`` reaches from each of its junctions (:func:`_reach`, mm), found the first time a
        line meets its plane (most flanges of a part never are: sampling all their edges was half an unfold)."""
        if b not in self.reaches:
            self.reaches[b] = _reach(self.topology, b, self.junctions[b])
        return self.reaches[b]

    @classmethod
    def of(cls, groups: list, *, topology, faces: tuple, sheet: SheetModel, bends: tuple, surfaces: dict) -> _Layer:
        from OCP.BRepTools import BRepTools

        junctions, spans = [], {}
        for k in groups:
            for j in bends[k].faces:
                f = faces[j]
                u0, u1, _, _ = BRepTools.UVBounds_s(f.face)
                spans[j] = (u0, u1)
                for b, _ in sheet.neighbours[j]:
                    if b in sheet.skin and faces[b].kind == "plane" and b not in {x.flange for x in junctions
                                                                                   if x.bend == k}:
                        uv = uv_mid(faces[b].face)
                        n, m = normal(faces[b], *uv), point(faces[b], *uv)
                        axis_point = np.asarray(f.origin, dtype=np.float64)
                        side = np.cross(f.axis, n)
                        side /= np.linalg.norm(side)
                        side = side if (m - axis_point) @ side > 0 else -side
                        depth = abs(f.radius - bends[k].neutral_radius)  # the bend's neutral layer under this skin
                        if not any(x.flange == b and float(x.side @ side) > 1 - 1e-9 and abs(float(
                                (axis_point - x.axis_point) @ side)) < 1e-6 and abs(x.depth - depth) < 1e-9
                                   for x in junctions):  # one bend cut in two by a hole: one junction
                            junctions.append(_Junction(k, b, axis_point, side, m, n, depth))
        by_flange: dict = {}
        for x in junctions:
            by_flange.setdefault(x.flange, []).append(x)
        by_flange = {b: tuple(xs) for b, xs in sorted(by_flange.items())}
        return cls(faces, bends, tuple(groups), by_flange, spans, frozenset(spans), topology, surfaces)

    def _on_bend(self, k: int, p: np.ndarray, d: np.ndarray) -> list:
        """``[(s, q, face), ...]``: where the line ``p + s d`` (s > 0) meets bend ``k``'s neutral cylinder
        within the bend's angle (``face`` the bend face whose angles hold it)."""
        f, rn = self.faces[self.bends[k].faces[0]], self.bends[k].neutral_radius
        a = f.axis
        r0, dd = p - f.origin, d - (d @ a) * a
        r0 = r0 - (r0 @ a) * a
        qa, qb, qc = dd @ dd, r0 @ dd, r0 @ r0 - rn * rn
        disc = qb * qb - qa * qc
        if qa <= 1e-24 or disc < 0:
            return []
        found = []
        for s in sorted(((-qb - np.sqrt(disc)) / qa, (-qb + np.sqrt(disc)) / qa)):
            if s > -1e-9:
                q = p + s * d
                on = next((j for j in self.bends[k].faces
                           if self.spans[j][0] - 1e-9 <= _uv(self.faces[j], q, self.surfaces)[0] <= self.spans[j][1]
                           + 1e-9), None)
                if on is not None:
                    found.append((float(s), q, on))
        return found

    def _on_flange(self, b: int, p: np.ndarray, d: np.ndarray) -> list:
        """``[(s, q, b)]``: where the line ``p + s d`` (s > 0) meets flange ``b``'s neutral plane on the flange's
        side of each of its junctions.  Under a flange between two bends whose neutral layers lie at different
        depths under its skin (a jog's web at K other than 0.5), the depth goes from one to the other evenly
        across the flange: the layer is continuous with both bends'."""
        xs = self.junctions[b]
        x = xs[0]
        slope = np.zeros(3)
        if len(xs) == 2 and float(xs[0].side @ xs[1].side) < -0.999 and abs(xs[1].depth - x.depth) > 1e-12:
            width = float((xs[1].axis_point - x.axis_point) @ x.side)
            if width > 1e-9:
                slope = (xs[1].depth - x.depth) / width * x.side  # depth(q) = x.depth + slope @ (q - x.axis_point)
        elif len({round(y.depth, 12) for y in xs}) > 1:  # bends of other depths round it: the nearest bend's
            x = min(xs, key=lambda y: (abs(float((p - y.axis_point) @ y.side)), y.bend))
        m = x.normal + slope
        across = -(d @ m)
        if across <= 1e-12:
            return []
        s = ((p - x.origin) @ x.normal + x.depth + slope @ (p - x.axis_point)) / across
        q = p + s * d
        if s <= -1e-9 or not all(y.on_flange(q) for y in xs):
            return []
        if any(float((q - y.axis_point) @ y.side) > reach + 1e-6 for y, reach in zip(xs, self.reach(b))):
            return []  # past the flange's free end: under no skin of it
        return [(float(s), q, b)]

    def neutral(self, p: np.ndarray, d: np.ndarray, reach: float) -> tuple | None:
        """``(q, face)``: the first point of the neutral layer on the line from ``p`` (on the skin) along ``d``
        (into the sheet), not further than ``reach`` mm, and the skin face it develops with; None if none."""
        found = [hit for k in self.groups for hit in self._on_bend(k, p, d)]
        found += [hit for b in self.junctions for hit in self._on_flange(b, p, d)]
        found = [hit for hit in found if hit[0] <= reach]
        if not found:
            return None
        _, q, face = min(found, key=lambda hit: (hit[0], hit[2]))  # ties (a junction): the lower face number
        return q, face

    def developed(self, q: np.ndarray, face: int, *, maps: dict, motions: dict) -> np.ndarray:
        """(2,) the blank position of the neutral-layer point ``q`` (3,) over skin face ``face``, mm."""
        return flat(maps, motions, face, _uv(self.faces[face], q, self.surfaces)[None, :])[0]
