"""Edge division: every CAD edge divided once, at equal arc length, its points shared by both faces."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import CadError
from .sizes import Sizes
from .topology import Topology

__all__ = ["EdgeDivision", "divide_edges", "divide_finer"]


@dataclass(frozen=True, eq=False)
class EdgeDivision:
    """The points on every edge.

    Attributes
    ----------
    points : (g, 3) float64, mm
        Every point on an edge (CAD vertices first met, then each edge's inner
        points), numbered globally (``gid``).
    params : tuple of (k + 1,) float64
        Per edge, the curve parameters of its points, first to last vertex
        (one point for a degenerate edge).
    gids : tuple of (k + 1,) int64
        Per edge, its points as indices into ``points``.
    lengths : tuple of float
        Per edge, its exact length, mm (0 for a degenerate edge).
    """

    points: np.ndarray
    params: tuple
    gids: tuple
    lengths: tuple

    def count(self, e: int) -> int:
        """Segments on edge ``e``."""
        return len(self.gids[e]) - 1


MOST_SEGMENTS = 1_000_000
"""The most pieces one edge is cut into; more means a face of no area (its target edge length is ~0)."""


def divide_edges(topology: Topology, sizes: Sizes, *, chord_tolerance: float, angular_tolerance: float
                 ) -> EdgeDivision:
    """Divide every edge at the finest edge length of its faces (shorter where it curves)."""
    points, vertex_gid = [], {}
    params, gids, lengths = [], [], []
    for e, edge in enumerate(topology.edges):
        hs = [sizes.face_h[k] for k in topology.edge_faces[e]] or [sizes.h]
        first, last, curve = _ends(edge, points, vertex_gid)
        if topology.degenerate[e]:
            params.append(np.zeros(1))
            gids.append(np.array([first], dtype=np.int64))
            lengths.append(0.0)
            continue
        count = _count(curve, min(hs), chord_tolerance, angular_tolerance)
        if count > MOST_SEGMENTS:  # a face of no area asks for edges of no length: never a real part
            faces = ", ".join(str(k) for k in topology.edge_faces[e])
            raise CadError(f"{topology.name}: edge {e} (of face {faces}) would be cut into {count:.3g} pieces: the "
                           f"face has almost no area for its size (an invalid face); repair it in the CAD program")
        if first == last:
            count = max(count, 3)  # a closed edge: at least a triangle
        t, g, length = _divided(curve, count, first, last, points)
        params.append(t)
        gids.append(g)
        lengths.append(length)
    return EdgeDivision(points=_frozen(points), params=tuple(params), gids=tuple(gids), lengths=tuple(lengths))


def divide_finer(topology: Topology, division: EdgeDivision, edges) -> EdgeDivision:
    """The division with each edge of ``edges`` in twice as many segments (its CAD vertices kept)."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.TopAbs import TopAbs_FORWARD
    from OCP.TopoDS import TopoDS

    points = [tuple(p) for p in division.points]
    params, gids, lengths = list(division.params), list(division.gids), list(division.lengths)
    for e in sorted(edges):
        curve = BRepAdaptor_Curve(TopoDS.Edge(topology.edges[e].Oriented(TopAbs_FORWARD)))
        first, last = int(gids[e][0]), int(gids[e][-1])
        params[e], gids[e], lengths[e] = _divided(curve, 2 * division.count(e), first, last, points)
    return EdgeDivision(points=_frozen(points), params=tuple(params), gids=tuple(gids), lengths=tuple(lengths))


def _ends(edge, points: list, vertex_gid: dict):
    """``(first gid, last gid, curve)`` of an edge; new CAD vertices appended to ``points``."""
    from OCP.BRep import BRep_Tool
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.TopAbs import TopAbs_FORWARD
    from OCP.TopExp import TopExp
    from OCP.TopoDS import TopoDS

    edge = TopoDS.Edge(edge.Oriented(TopAbs_FORWARD))
    ends = []
    for vertex in (TopExp.FirstVertex_s(edge), TopExp.LastVertex_s(edge)):
        key = next((k for k in vertex_gid.get(hash(vertex), ()) if k[0].IsSame(vertex)), None)
        if key is None:
            p = BRep_Tool.Pnt_s(vertex)
            points.append((p.X(), p.Y(), p.Z()))
            key = (vertex, len(points) - 1)
            vertex_gid.setdefault(hash(vertex), []).append(key)
        ends.append(key[1])
    return ends[0], ends[1], BRepAdaptor_Curve(edge)


def _count(curve, h: float, chord_tolerance: float, angular_tolerance: float) -> int:
    """Segments for a curve: edge length ``h``, shorter where it curves (sampled at 65 points)."""
    from OCP.GCPnts import GCPnts_AbscissaPoint

    t0, t1 = curve.FirstParameter(), curve.LastParameter()
    length = GCPnts_AbscissaPoint.Length_s(curve)
    t = np.linspace(t0, t1, 65)
    p = np.array([(q.X(), q.Y(), q.Z()) for q in (curve.Value(x) for x in t)])
    seg = np.diff(p, axis=0)
    seglen = np.linalg.norm(seg, axis=1)
    ok = seglen > 0
    kappa = 0.0
    if ok.sum() > 1:
        d = seg[ok] / seglen[ok, None]
        turn = np.arccos(np.clip(np.einsum("ij,ij->i", d[1:], d[:-1]), -1, 1))
        kappa = float(np.max(turn / (0.5 * (seglen[ok][1:] + seglen[ok][:-1]))))
    he = h
    if kappa > 0:
        he = min(he, np.sqrt(8 * chord_tolerance / kappa), angular_tolerance / kappa)
    return max(int(np.ceil(length / he - 1e-9)), 1)


def _divided(curve, count: int, first: int, last: int, points: list):
    """``(params (count + 1,), gids (count + 1,), length)``: the curve at equal arc length; inner points appended."""
    from OCP.GCPnts import GCPnts_AbscissaPoint, GCPnts_UniformAbscissa

    t0, t1 = curve.FirstParameter(), curve.LastParameter()
    length = GCPnts_AbscissaPoint.Length_s(curve)
    params = np.linspace(t0, t1, count + 1)
    if count > 1:
        ua = GCPnts_UniformAbscissa(curve, count + 1, t0, t1)
        if ua.IsDone() and ua.NbPoints() == count + 1:
            params = np.array([ua.Parameter(i + 1) for i in range(count + 1)])
    gids = np.empty(count + 1, dtype=np.int64)
    gids[0], gids[-1] = first, last
    for i in range(1, count):
        q = curve.Value(params[i])
        points.append((q.X(), q.Y(), q.Z()))
        gids[i] = len(points) - 1
    return params, gids, float(length)


def _frozen(points: list) -> np.ndarray:
    out = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    out.setflags(write=False)
    return out
