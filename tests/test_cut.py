"""patterns.cut: cutting meshes open, on a closed sphere, a tube, a washer and along a path,
checked by Euler's formula, boundary counts and the lengths of the cuts."""

import numpy as np
import pytest
import trimesh

import patterns
from patterns import surfaces
from patterns.cut import components, cut_along
from patterns.errors import MeshTopologyError
from patterns.mesh import validate_mesh


def _euler(v, f):
    e = np.unique(np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1), axis=0)
    return len(v) - len(e) + len(f)


def test_pieces_are_the_connected_parts():
    f = np.array([[0, 1, 2], [3, 4, 5], [2, 1, 6]])
    groups = components(f, 7)
    assert sorted(sorted(g.tolist()) for g in groups) == [[0, 2], [1]]


def test_a_closed_sphere_is_slit_into_a_disk():
    ball = trimesh.creation.icosphere(subdivisions=2, radius=30.0)
    cut = patterns.cut_to_disk(ball.vertices, ball.faces)
    assert _euler(ball.vertices, ball.faces) == 2
    (path,) = cut.paths
    v, f, conn = validate_mesh(cut.vertices, cut.faces)  # a disk now: one boundary loop
    assert len(conn.loops) == 1 and _euler(v, f) == 1
    assert len(cut.vertices) == len(ball.vertices) + len(path) - 2  # the slit's inner vertices doubled
    left, right = cut.sides[0]
    np.testing.assert_array_equal(cut.source[left], cut.source[right])


def test_a_tube_is_cut_between_its_rims_and_a_washer_is_not():
    v, f = surfaces.cylinder_patch(radius=20.0, height=50.0, angle=360.0, n_around=40, n_along=10)
    _, index, inverse = np.unique(np.round(v, 9), axis=0, return_index=True, return_inverse=True)
    v, f = v[index], inverse.ravel()[f]
    cut = patterns.cut_to_disk(v, f)
    (path,) = cut.paths
    length = np.linalg.norm(np.diff(v[path], axis=0), axis=1).sum()
    assert length == pytest.approx(50.0, rel=1e-9)  # straight down a ruling: the shortest way
    assert len(validate_mesh(cut.vertices, cut.faces)[2].loops) == 1
    # a washer (a flat annulus): its hole turns by -2 pi, a real hole, kept
    t = np.linspace(0, 2 * np.pi, 24, endpoint=False)
    ring = np.concatenate([np.column_stack([10 * np.cos(t), 10 * np.sin(t), 0 * t]),
                           np.column_stack([20 * np.cos(t), 20 * np.sin(t), 0 * t])])
    i = np.arange(24)
    j = (i + 1) % 24
    wf = np.concatenate([np.column_stack([i, j, 24 + j]), np.column_stack([i, 24 + j, 24 + i])])
    washer = patterns.cut_to_disk(ring, wf)
    assert washer.paths == () and len(validate_mesh(washer.vertices, washer.faces)[2].loops) == 2


def test_a_torus_cannot_be_opened_by_one_cut():
    torus = trimesh.creation.torus(major_radius=30.0, minor_radius=8.0)
    with pytest.raises(MeshTopologyError, match="handles"):
        patterns.cut_to_disk(torus.vertices, torus.faces)


def test_a_dart_from_the_outline_stops_inside():
    v, f = surfaces.spherical_cap(radius=100.0, half_angle=60.0, n_faces=600)
    _, _, conn = validate_mesh(v, f)
    start = int(conn.loops[0][0])
    inner = int(np.argmin(np.linalg.norm(v[:, :2], axis=1)))  # the pole
    import scipy.sparse.csgraph as csgraph

    from patterns.mesh import edge_graph

    _, pred = csgraph.dijkstra(edge_graph(v, conn.edges), indices=start, return_predecessors=True)
    path = [inner]
    while path[-1] != start:
        path.append(int(pred[path[-1]]))
    path = np.array(path[::-1])
    cut = cut_along(v, f, path)
    left, right = cut.sides[0]
    assert left[0] != right[0] and left[-1] == right[-1]  # open at the outline, closed at the tip
    assert len(cut.vertices) == len(v) + len(path) - 1
    assert len(validate_mesh(cut.vertices, cut.faces)[2].loops) == 1


def _grid(n=12, size=100.0):
    """A square of (n x n) cells, two triangles each, in the plane z = 0 (counter-clockwise)."""
    xs = np.linspace(0.0, size, n + 1)
    x, y = np.meshgrid(xs, xs)
    v = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    k = np.arange(n * (n + 1)).reshape(n, n + 1)[:, :n].ravel()
    f = np.vstack([np.column_stack([k, k + 1, k + n + 2]), np.column_stack([k, k + n + 2, k + n + 1])])
    return v, f


def test_a_line_is_put_into_the_mesh_straight_and_nothing_moves():
    from patterns.cut import insert_line
    from patterns.measure import signed_areas
    from patterns.mesh import face_areas

    v, f = _grid()
    uv = v[:, :2]
    start, end = np.array([0.0, 100.0 / 12 * 5]), np.array([63.1, 77.7])  # from a boundary vertex, across cells
    out = insert_line(v, f, uv, start, end)
    # The surface is the same: same area, every new point on the plane, the old vertices kept in place.
    assert face_areas(out.vertices, out.faces).sum() == pytest.approx(100.0 * 100.0, rel=1e-12)
    assert np.array_equal(out.vertices[: len(v)], v) and np.all(out.vertices[:, 2] == 0)
    assert np.all(signed_areas(out.uv, out.faces) > 0)  # winding kept, nothing folded
    # The path is the straight line: every vertex on it (to round-off, or snapped within a quarter cell)...
    d = (end - start) / np.linalg.norm(end - start)
    rel = out.uv[out.path] - start
    off = np.abs(rel[:, 0] * d[1] - rel[:, 1] * d[0])
    new = out.path >= len(v)
    h = 100.0 / 12  # a cell; a vertex's edges average 1.14 h (four sides, two diagonals)
    assert new.sum() >= 2 and off[new].max() < 1e-9 and off.max() <= 0.1 * (4 + 2 * np.sqrt(2)) / 6 * h
    # ... in order from the start, each step an edge of the new mesh, ending by the end point.
    assert out.path[0] == int(np.flatnonzero(np.all(v[:, :2] == start, axis=1))[0])
    assert np.all(np.diff(rel @ d) > 0)
    edges = {tuple(sorted(e)) for e in np.concatenate([out.faces[:, [0, 1]], out.faces[:, [1, 2]],
                                                       out.faces[:, [2, 0]]]).tolist()}
    assert all(tuple(sorted(e)) in edges for e in zip(out.path[:-1].tolist(), out.path[1:].tolist()))
    assert np.linalg.norm(out.uv[out.path[-1]] - end) < h * np.sqrt(2)
    # Cut along it: a slit from the outline into the square, its two sides as long as the line.
    cut = cut_along(out.vertices, out.faces, out.path)
    left, right = cut.sides[0]
    length = np.linalg.norm(np.diff(out.uv[out.path], axis=0), axis=1).sum()
    assert length < 1.01 * np.linalg.norm(out.uv[out.path[-1]] - out.uv[out.path[0]])  # straight but for snapping
    for side in (left, right):
        assert np.array_equal(cut.source[side], out.path)
        assert np.linalg.norm(np.diff(cut.vertices[side], axis=0), axis=1).sum() == pytest.approx(length, rel=1e-12)
    # The input is never changed.
    assert np.array_equal(v, _grid()[0]) and np.array_equal(f, _grid()[1])


def test_several_paths_are_cut_at_once():
    v, f = _grid(6)
    a = np.array([1, 8, 15])  # two columns of vertices up from the bottom edge

    b = np.array([4, 11, 18])
    cut = cut_along(v, f, [a, b])
    assert len(cut.sides) == 2
    assert len(cut.vertices) == len(v) + (len(a) - 1) + (len(b) - 1)
    assert len(validate_mesh(cut.vertices, cut.faces)[2].loops) == 1


def test_a_closed_box_splits_at_its_creases_into_its_faces():
    """crease_regions on a box: six regions of two triangles, each flat; shared_chains: its twelve edges,
    each one straight segment between two regions, as long as the box edge."""
    import trimesh

    from patterns.cut import crease_regions, is_closed, shared_chains

    box = trimesh.creation.box((100.0, 60.0, 40.0))
    v, f = np.asarray(box.vertices), np.asarray(box.faces)
    assert is_closed(f, len(v))
    regions = crease_regions(v, f, angle=60.0)
    assert sorted(len(r) for r in regions) == [2] * 6
    for r in regions:  # each region flat: one normal
        p = v[f[r]]
        n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
        n /= np.linalg.norm(n, axis=1, keepdims=True)
        np.testing.assert_allclose(n, n[:1].repeat(len(n), axis=0), atol=1e-12)
    chains = shared_chains(f, regions)
    assert len(chains) == 12 and all(a < b for a, b, _ in chains)
    lengths = sorted(round(float(np.linalg.norm(v[path[-1]] - v[path[0]])), 9) for _, _, path in chains)
    assert lengths == [40.0] * 4 + [60.0] * 4 + [100.0] * 4
    (whole,) = crease_regions(v, f, angle=95.0)  # no edge sharper than 95 degrees: one region
    assert sorted(whole) == list(range(12))


def test_a_can_splits_into_caps_and_side_with_closed_rims():
    import trimesh

    from patterns.cut import crease_regions, shared_chains

    can = trimesh.creation.cylinder(radius=30.0, height=80.0, sections=32)
    v, f = np.asarray(can.vertices), np.asarray(can.faces)
    regions = crease_regions(v, f, angle=60.0)
    assert len(regions) == 3
    chains = shared_chains(f, regions)
    assert len(chains) == 2  # the two rims, between the side and each cap
    for _, _, path in chains:
        assert path[0] == path[-1] and len(path) == 33  # closed: 32 edges, the first vertex again
        assert np.ptp(v[path, 2]) == pytest.approx(0.0, abs=1e-9)  # each rim in one plane


def test_a_line_ending_on_a_vertex_ends_there_whatever_the_last_bit_of_the_sum():
    """A line drawn to a vertex ends on that vertex and crosses none of its edges, even where
    ``start + (end - start)`` misses ``end`` in the last bit and the vertex measures a hair past the end
    (a crossing at the vertex itself would put a point there twice, and two triangles of no area).
    The two points are those of a slash of :mod:`patterns.flattening.inserts` on the saddle that ended so."""
    from patterns.cut import insert_line
    from patterns.mesh import face_areas

    v, f = _grid(60, 240.0)  # a grid of 7,200 triangles, 4 mm cells, about (0, 0)
    v[:, :2] -= 120.0
    start = np.array([float.fromhex("-0x1.7ce7383e4bdf9p+4"), float.fromhex("0x1.a65b141235783p+6")])
    end = np.array([float.fromhex("-0x1.6095e63722d77p-1"), float.fromhex("0x1.5d56b396e6258p+4")])
    assert np.any(start + (end - start) != end)
    tip = int(np.argmin(np.linalg.norm(v[:, :2] - end, axis=1)))
    v[tip, :2] = end
    out = insert_line(v, f, v[:, :2], start, end)
    assert out.path[-1] == tip
    assert face_areas(out.vertices, out.faces).min() > 1e-3 * 16.0
