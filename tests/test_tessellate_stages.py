"""The CAD mesher's stages (patterns.tessellate), each on a box, a cylinder or a cone, against
analytic values: topology counts, edge lengths and divisions, face areas, surface recognition,
assembly into panels and seams."""

import re

import build123d as bd
import numpy as np
import pytest

from patterns.errors import CadError, InputError
from patterns.model import SurfaceKind
from patterns.tessellate import faces as face_stage
from patterns.tessellate.assemble import assemble
from patterns.tessellate.edges import divide_edges, divide_finer
from patterns.tessellate.faces import FaceMesh, RefineEdges, mesh_face
from patterns.tessellate.recognise import surface_of
from patterns.tessellate.sizes import MAX_TRIANGLES, face_sizes
from patterns.tessellate.topology import panel_groups, read_topology


def _stages(shape, *, max_edge, chord_tolerance=0.05, angular_tolerance=0.2):
    topo = read_topology(shape.wrapped, name="part")
    sizes = face_sizes(topo, max_edge=max_edge, chord_tolerance=chord_tolerance,
                       angular_tolerance=angular_tolerance)
    division = divide_edges(topo, sizes, chord_tolerance=chord_tolerance, angular_tolerance=angular_tolerance)
    return topo, sizes, division


@pytest.fixture(scope="module")
def box():
    return _stages(bd.Box(100, 60, 40), max_edge=10.0)


@pytest.fixture(scope="module")
def cylinder():
    return _stages(bd.Cylinder(30, 80), max_edge=5.0)


def test_topology_of_a_box(box):
    topo, _, _ = box
    assert (len(topo.faces), len(topo.edges)) == (6, 12) and not any(topo.degenerate)
    assert all(len(walks) == 1 and len(walks[0]) == 4 for walks in topo.wires)  # one wire of four edges per face
    assert all(len(faces) == 2 for faces in topo.edge_faces)  # every edge between two faces


def test_topology_of_a_cylinder_and_a_sphere(cylinder):
    topo, _, _ = cylinder
    assert len(topo.faces) == 3
    lateral = next(k for k in range(3) if len(topo.wires[k][0]) == 4)  # rim, seam line, rim, seam line
    seam_line = [e for e, faces in enumerate(topo.edge_faces) if faces == (lateral, lateral)]
    assert len(seam_line) == 1  # the lateral face meets itself along one edge
    sphere = read_topology(bd.Sphere(50).wrapped, name="ball")
    assert sum(sphere.degenerate) == 2  # the poles


def test_panel_groups_are_checked(box):
    topo, _, _ = box
    assert panel_groups(topo, {"wrap": [0, 1, 2, 3]}) == (("wrap", [0, 1, 2, 3]), ("face4", [4]), ("face5", [5]))
    with pytest.raises(InputError, match="names CAD face 9; the shape has faces 0..5"):
        panel_groups(topo, {"a": [9]})
    with pytest.raises(InputError, match="face 1 is in two groups"):
        panel_groups(topo, {"a": [0, 1], "b": [1]})


def test_sizes_follow_max_edge_and_curvature(box):
    _, sizes, _ = box
    assert sizes.h == 10.0 and sizes.face_h == (10.0,) * 6  # planes: no curvature
    thin = _stages(bd.Cylinder(2, 20), max_edge=10.0, chord_tolerance=0.01)[1]
    kappa = 1 / 2.0  # the lateral face: 1 / R
    assert min(thin.face_h) == pytest.approx(min(np.sqrt(8 * 0.01 / kappa), 0.2 / kappa), rel=0.02)
    with pytest.raises(CadError, match=re.escape(f"over the limit of {MAX_TRIANGLES:.0e}")):
        _stages(bd.Box(1000, 1000, 1000), max_edge=0.1)


@pytest.mark.parametrize("radius, height", [(0.5, 100.0), (20.0, 30.0)])
def test_a_cones_curvature_is_taken_by_area_not_by_sample(radius, height):
    """A cone's normal curvature is 0 along its lines and cos(a) / r around, unbounded at the apex.
    By area (s^2 of the area lies within slant distance s of the apex, half the weight on the lines),
    the 95th percentile is the curvature around at the circle holding a tenth of the area:
    cos(a) / (sqrt(0.1) R).  By sample it would be near the apex, several times larger."""
    _, sizes, _ = _stages(bd.Cone(radius, 0, height), max_edge=None, chord_tolerance=0.05)
    lateral = max(range(len(sizes.face_h)), key=lambda k: sizes.developments[k].curvature())
    cos_a = height / np.hypot(radius, height)
    assert sizes.developments[lateral].curvature() == pytest.approx(cos_a / (np.sqrt(0.1) * radius), rel=0.05)


def test_edges_are_divided_at_equal_arc_length(box, cylinder):
    topo, _, division = box
    for e in range(12):
        pts = division.points[division.gids[e]]
        seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
        assert division.lengths[e] in (100.0, 60.0, 40.0) or np.isclose(division.lengths[e], (100, 60, 40)).any()
        assert division.count(e) == int(np.ceil(division.lengths[e] / 10.0 - 1e-9))
        np.testing.assert_allclose(seg, division.lengths[e] / division.count(e), rtol=1e-9)
    assert len(division.points) == 8 + sum(division.count(e) - 1 for e in range(12))  # corners shared
    ctopo, _, cdiv = cylinder
    rims = [e for e in range(len(ctopo.edges)) if np.isclose(cdiv.lengths[e], 2 * np.pi * 30)]
    assert len(rims) == 2  # the exact circumference, not the polygon's


def test_divide_finer_doubles_and_keeps_the_vertices(cylinder):
    topo, _, division = cylinder
    rim = next(e for e in range(len(topo.edges)) if np.isclose(division.lengths[e], 2 * np.pi * 30))
    finer = divide_finer(topo, division, {rim})
    assert finer.count(rim) == 2 * division.count(rim)
    assert finer.gids[rim][0] == division.gids[rim][0] and finer.gids[rim][-1] == division.gids[rim][-1]
    pts = finer.points[finer.gids[rim]]
    np.testing.assert_allclose(np.hypot(pts[:, 0], pts[:, 1]), 30.0, rtol=1e-12)  # on the circle
    others = [e for e in range(len(topo.edges)) if e != rim]
    assert all(np.array_equal(finer.gids[e], division.gids[e]) for e in others)
    assert finer.lengths == division.lengths


def test_a_face_mesh_covers_the_face(box):
    topo, sizes, division = box
    for k, expected in enumerate(_box_face_areas(topo)):
        mesh = mesh_face(topo, sizes, division, k)
        assert isinstance(mesh, FaceMesh)
        xyz = np.concatenate([division.points[mesh.slot_gid], mesh.interior])
        p = xyz[mesh.triangles]
        area = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1).sum()
        assert area == pytest.approx(expected, rel=1e-12)
        # the boundary is exactly the edges' points, each once
        edge_points = {int(g) for e, _ in mesh.occurrences for g in division.gids[e]}
        assert set(mesh.slot_gid.tolist()) == edge_points


def _box_face_areas(topo):
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    out = []
    for face in topo.faces:
        props = GProp_GProps()
        BRepGProp.SurfaceProperties_s(face, props)
        out.append(props.Mass())
    return out


def test_a_lost_boundary_segment_asks_for_finer_edges(box):
    """A triangulation that lost a boundary segment names the CAD edge it lies on (RefineEdges)."""
    topo, sizes, division = box
    k = 0
    mesh = mesh_face(topo, sizes, division, k)
    bnd = face_stage._boundary(topo, division, k, sizes.developments[k], sizes.face_h[k])
    segs = np.stack([np.concatenate(bnd.rings), np.concatenate([np.roll(r, -1) for r in bnd.rings])], axis=1)
    assert face_stage._lost_edges(mesh.triangles, segs, bnd, topo.degenerate, 10**6) is None
    uses = np.bincount(np.concatenate(bnd.occ_slots), minlength=len(bnd.xy))
    a, b = next(seg for seg in segs if uses[seg].max() == 1)  # both ends inside one edge (no corner)
    touching = np.isin(mesh.triangles, [a]).any(axis=1) & np.isin(mesh.triangles, [b]).any(axis=1)
    lost = face_stage._lost_edges(mesh.triangles[~touching], segs, bnd, topo.degenerate, 10**6)
    owner = next(e for (e, _), slots in zip(bnd.occurrences, bnd.occ_slots) if a in slots and b in slots)
    assert lost == {owner}
    assert RefineEdges(frozenset(lost)).edges == {owner}


@pytest.mark.parametrize(("shape", "kinds"), [
    (bd.Box(10, 20, 30), {SurfaceKind.PLANE}),
    (bd.Cylinder(30, 80), {SurfaceKind.PLANE, SurfaceKind.CYLINDER}),
    (bd.Cone(40, 10, 60), {SurfaceKind.PLANE, SurfaceKind.CONE}),
    (bd.Sphere(50), {None}),
])
def test_surfaces_are_recognised(shape, kinds):
    topo, sizes, _ = _stages(shape, max_edge=20.0)
    found = [surface_of(sizes.surfaces[k], topo.faces[k], sizes.developments[k]) for k in range(len(topo.faces))]
    assert {None if s is None else s.kind for s in found} == kinds
    for s in found:
        if s is not None and s.kind is SurfaceKind.CYLINDER:
            assert s.radius == pytest.approx(30.0, rel=1e-12)
        if s is not None and s.kind is SurfaceKind.CONE:
            assert abs(np.tan(s.semi_angle)) == pytest.approx(30.0 / 60.0, rel=1e-12)  # (40 - 10) / 60


def test_assembly_of_a_box(box):
    topo, sizes, division = box
    meshes = tuple(mesh_face(topo, sizes, division, k) for k in range(6))
    model = assemble(topo, sizes, division, meshes, panel_groups(topo, None))
    assert len(model.panels) == 6 and len(model.seams) == 12 and model.bookkeeping.cuts == 0
    assert sorted(round(s.length, 9) for s in model.seams) == sorted([100.0, 60.0, 40.0] * 4)
    wrapped = assemble(topo, sizes, division, meshes, panel_groups(topo, {"wrap": [0, 1, 2, 3]}))
    assert len(wrapped.panels) == 3 and wrapped.bookkeeping.cuts == 1  # the wrap closes into a tube: one cut
    cut = next(s for s in wrapped.seams if s.cad_edge is None)
    assert cut.length == pytest.approx(40.0, rel=1e-12)  # the shortest way from rim to rim: straight down a side
    assert wrapped.panels[0].area == pytest.approx(sum(_box_face_areas(topo)[:4]), rel=1e-12)


def test_a_planes_and_a_cylinders_development_table_is_opencascades_point_for_point():
    """Planes and cylinders are tabulated in closed form (one numpy pass, not 1,681 calls a face): the points
    and unit normals are OpenCascade's own ``D1`` at every sample, on a part moved and turned off its axes."""
    from OCP.BRepAdaptor import BRepAdaptor_Surface
    from OCP.BRepTools import BRepTools
    from OCP.gp import gp_Pnt, gp_Vec

    from patterns.tessellate.sizes import _table

    part = bd.Pos(3, -7, 11) * bd.Rot(20, 35, -50) * (bd.Cylinder(12, 40) - bd.Box(5, 5, 50) + bd.Box(30, 8, 8))
    kinds = set()
    for face in part.faces():
        surface = BRepAdaptor_Surface(face.wrapped)
        kinds.add(face.geom_type)
        u0, u1, v0, v1 = BRepTools.UVBounds_s(face.wrapped)
        us, vs = np.linspace(u0, u1, 7), np.linspace(v0, v1, 5)
        points, normals = _table(surface, us, vs)
        p, du, dv = gp_Pnt(), gp_Vec(), gp_Vec()
        for j, v in enumerate(vs):
            for i, u in enumerate(us):
                surface.D1(u, v, p, du, dv)
                n = du.Crossed(dv)
                n.Normalize()
                assert np.abs(points[j, i] - (p.X(), p.Y(), p.Z())).max() < 1e-12
                assert np.abs(normals[j, i] - (n.X(), n.Y(), n.Z())).max() < 1e-12
    assert kinds == {bd.GeomType.PLANE, bd.GeomType.CYLINDER}
