"""Assembly: face meshes into panels (faces of a group merged, tubes cut open) and seams (shared edges)."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse import csgraph

from ..cut import cut_to_disk
from ..mesh import polyline_length, unique_ints
from ..model import Bookkeeping, Model, Seam, panel_from_mesh
from .edges import EdgeDivision
from .recognise import surface_of
from .sizes import Sizes
from .topology import Topology

__all__ = ["assemble"]


def assemble(topology: Topology, sizes: Sizes, division: EdgeDivision, meshes: tuple, groups: tuple) -> Model:
    """The model: one panel per group of faces, one seam per edge between two panels (and per cut made).

    Face-vertices are merged along edges shared by two faces of one panel, and
    along the seam line of a freeform face with itself (OpenCascade's seam of a
    sphere or a surface of revolution, from the rim to the pole): that line is
    the parametrisation's, not the part's, and cutting along it would slit a
    cap to its pole.  A panel that closes into a tube is cut open again, along
    a path of its own choosing (:func:`patterns.cut_to_disk`).  Developable
    faces keep their seam line: their exact development unrolls them from it.
    """
    offsets = np.cumsum([0] + [len(m.slot_gid) + len(m.interior) for m in meshes])
    panel_of_face = np.empty(len(topology.faces), dtype=np.int64)
    for p, (_, members) in enumerate(groups):
        panel_of_face[members] = p
    occ_of_edge = [[] for _ in topology.edges]  # (face, face-vertex ids in the edge's order)
    for k, m in enumerate(meshes):
        for (e, _), slots in zip(m.occurrences, m.occ_slots):
            occ_of_edge[e].append((k, offsets[k] + slots))
    surfaces = tuple(surface_of(sizes.surfaces[k], topology.faces[k], sizes.developments[k])
                     for k in range(len(meshes)))
    root, self_merged = _merged(occ_of_edge, panel_of_face, [s is None for s in surfaces], int(offsets[-1]))
    coords = np.concatenate([np.concatenate([division.points[m.slot_gid], m.interior]) for m in meshes])
    panels, local_of, cuts = [], [], []
    for p, (label, members) in enumerate(groups):
        panel, local, made = _panel(topology.name, label, members, meshes, offsets, root, coords, surfaces,
                                    closes=len(members) > 1 or any(e in self_merged
                                                                   for e, _ in meshes[members[0]].occurrences))
        panels.append(panel)
        local_of.append(local)
        cuts.extend((p, sides) for sides in made)
    seams = _edge_seams(topology, division, occ_of_edge, panel_of_face, self_merged, local_of)
    for p, (_, (left, right)) in cuts:
        pts = panels[p].vertices[left]
        seams.append(Seam(id=len(seams), panels=(p, p), points=pts, vertices=(left, right),
                          length=polyline_length(pts)))
    return Model(name=topology.name, panels=tuple(panels), seams=tuple(seams), max_edge=sizes.h,
                 bookkeeping=Bookkeeping(cuts=len(cuts)))


def _merged(occ_of_edge, panel_of_face, freeform, total: int):
    """``(root (total,), self-merged edges)``: one root per distinct panel vertex among the face-vertices."""
    rows, cols, self_merged = [], [], set()
    for e, occ in enumerate(occ_of_edge):
        for (ka, va), (kb, vb) in zip(occ[:-1], occ[1:]):
            if panel_of_face[ka] != panel_of_face[kb] or len(va) != len(vb):
                continue
            if ka == kb and not freeform[ka]:
                continue
            if ka == kb:
                self_merged.add(e)
            rows.append(va)
            cols.append(vb)
    rows = np.concatenate(rows) if rows else np.zeros(0, dtype=np.int64)
    cols = np.concatenate(cols) if cols else np.zeros(0, dtype=np.int64)
    graph = sp.coo_matrix((np.ones(len(rows), dtype=np.int8), (rows, cols)), shape=(total, total))
    _, root = csgraph.connected_components(graph, directed=False)
    return root, self_merged


def _panel(name, label, members, meshes, offsets, root, coords, surfaces, *, closes: bool):
    """``(Panel, local, cuts made [(path, sides)])``: ``local`` is a :class:`_Local`, the panel's own face-vertices
    and their panel vertices (the panel's, not the whole part's: an array of every face-vertex per panel was
    quadratic in the faces, 22 GB for a plate with 5,000 holes)."""
    tri = np.concatenate([offsets[k] + meshes[k].triangles for k in members])
    fv = np.concatenate([np.arange(offsets[k], offsets[k + 1]) for k in members])
    roots, first = unique_ints(root[fv], return_index=True)
    order = np.argsort(first)
    rank = np.empty(len(roots), dtype=np.int64)
    rank[order] = np.arange(len(roots))  # the panel vertex of each root (sorted), numbered by first appearance
    local = _Local(fv, rank[np.searchsorted(roots, root[fv])])
    vertices, faces = coords[fv[first[order]]], local[tri]
    pname = f"{name}: panel {label}"
    made = []
    if closes:  # a group, or a freeform face sewn along its own seam line, may close up: cut it open
        cut = cut_to_disk(vertices, faces, name=pname)
        vertices, faces = cut.vertices, cut.faces
        made = list(zip(cut.paths, cut.sides))
    surface = param = None
    if len(members) == 1 and surfaces[members[0]] is not None:
        k = members[0]
        surface, param = surfaces[k], meshes[k].param[fv[first[order]] - offsets[k]]
    panel = panel_from_mesh(label, vertices, faces, name=pname, cad_faces=members, surface=surface, param=param)
    return panel, local, made


class _Local:
    """One panel's map from face-vertex ids (of the whole part) to its own vertex numbers."""

    def __init__(self, face_vertices: np.ndarray, panel_vertices: np.ndarray):
        order = np.argsort(face_vertices, kind="stable")
        self.keys, self.values = face_vertices[order], panel_vertices[order]

    def __getitem__(self, ids: np.ndarray) -> np.ndarray:
        """The panel vertices of face-vertex ``ids`` (any shape, each one of the panel's)."""
        ids = np.asarray(ids)
        return self.values[np.searchsorted(self.keys, ids)]


def _edge_seams(topology, division, occ_of_edge, panel_of_face, self_merged, local_of) -> list:
    """A seam for every (non-degenerate) edge whose two uses lie on two panels, or open one panel."""
    seams = []
    for e, occ in enumerate(occ_of_edge):
        if topology.degenerate[e] or len(occ) < 2:
            continue
        ka, va = occ[0]
        for kb, vb in occ[1:]:
            pa, pb = int(panel_of_face[ka]), int(panel_of_face[kb])
            if (ka != kb or e in self_merged) and pa == pb:
                continue  # inside one panel
            seams.append(Seam(id=len(seams), panels=(pa, pb), points=division.points[division.gids[e]],
                              vertices=(local_of[pa][va], local_of[pb][vb]), length=division.lengths[e],
                              cad_edge=e))
    return seams
