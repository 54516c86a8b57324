"""Mesh validation: every way a mesh can be unusable gets its own clear error."""

import numpy as np
import pytest

import patterns
from patterns import surfaces
from patterns.errors import InputError, MeshTopologyError
from patterns.mesh import validate_mesh

SQUARE_V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=float)
SQUARE_F = np.array([[0, 1, 2], [0, 2, 3]])


def test_square_is_valid_and_its_loop_runs_counter_clockwise():
    _, _, conn = validate_mesh(SQUARE_V, SQUARE_F)
    assert len(conn.edges) == 5
    assert len(conn.loops) == 1
    assert conn.loops[0].tolist() in ([0, 1, 2, 3], [1, 2, 3, 0], [2, 3, 0, 1], [3, 0, 1, 2])
    assert (conn.edge_faces[:, 1] < 0).sum() == 4


@pytest.mark.parametrize(
    ("vertices", "faces", "error", "words"),
    [
        (SQUARE_V[:, :2], SQUARE_F, InputError, "shape (n, 3)"),
        (SQUARE_V, SQUARE_F[:, :2], InputError, "shape (m, 3)"),
        (np.where(np.arange(12).reshape(4, 3) == 4, np.nan, SQUARE_V), SQUARE_F, InputError, "NaN or infinite"),
        (np.where(np.arange(12).reshape(4, 3) == 7, np.inf, SQUARE_V), SQUARE_F, InputError, "vertex 2"),
        (SQUARE_V, np.array([[0, 1, 2], [0, 2, 4]]), InputError, "outside [0, 4)"),
        (SQUARE_V, np.array([[0, 1, 2], [0, 2, -1]]), InputError, "outside [0, 4)"),
        (SQUARE_V, np.array([[0, 1, 2], [0, 2, 2]]), InputError, "degenerate"),
        (np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0]], float), np.array([[0, 1, 2], [0, 1, 3]]),
         InputError, "degenerate"),
        (np.vstack([SQUARE_V, [[5, 5, 5]]]), SQUARE_F, InputError, "used by no face"),
        (SQUARE_V, np.array([[0, 1, 2], [0, 3, 2]]), MeshTopologyError, "consistently wound"),
        (SQUARE_V, np.zeros((0, 3), int), InputError, "no faces"),
        (SQUARE_V, np.array([[0, 1, 2], [0, 2, 3.5]]), InputError, "integers"),
    ],
)
def test_bad_arrays_raise_one_clear_error(vertices, faces, error, words):
    with pytest.raises(error, match=None) as info:
        validate_mesh(vertices, faces, name="part.obj")
    assert words in str(info.value)
    assert str(info.value).startswith("part.obj: ") or "faces" in str(info.value)


def test_errors_are_builtin_value_errors_too():
    with pytest.raises(ValueError):
        validate_mesh(SQUARE_V[:, :2], SQUARE_F)
    assert issubclass(MeshTopologyError, patterns.PatternsError)


def test_non_manifold_edge():
    v = np.vstack([SQUARE_V, [[0.5, 0.5, 1.0]]])
    f = np.array([[0, 1, 2], [0, 2, 3], [0, 4, 2]])  # edge 0-2 in three faces
    with pytest.raises(MeshTopologyError, match="non-manifold edges"):
        validate_mesh(v, f)


def test_disconnected_pieces():
    v = np.vstack([SQUARE_V, SQUARE_V + [3, 0, 0]])
    f = np.vstack([SQUARE_F, SQUARE_F + 4])
    with pytest.raises(MeshTopologyError, match="2 disconnected pieces"):
        validate_mesh(v, f)


def test_two_triangles_touching_at_a_vertex_are_two_pieces():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0]], float)
    f = np.array([[0, 1, 2], [0, 3, 4]])
    with pytest.raises(MeshTopologyError, match="disconnected"):
        validate_mesh(v, f)


def test_pinched_vertex_is_non_manifold():
    # Glue two opposite rim vertices of a disk: the boundary passes twice through one vertex.
    p, f = surfaces.disk_mesh(100)
    v = np.column_stack([p, np.zeros(len(p))])
    rim = np.flatnonzero(np.isclose(np.linalg.norm(p, axis=1), 1.0))
    a, b = rim[0], rim[len(rim) // 2]
    f = np.where(f == b, a, f)
    f = np.where(f > b, f - 1, f)
    v = np.delete(v, b, axis=0)
    with pytest.raises(MeshTopologyError, match=f"non-manifold vertex {a}"):
        validate_mesh(v, f)


def test_closed_surface():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    f = np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]])
    with pytest.raises(MeshTopologyError, match="closed"):
        validate_mesh(v, f)


def test_handle_is_refused():
    # A torus with one face removed: genus 1, one boundary loop.
    n, k = 8, 6
    i, j = np.meshgrid(np.arange(n), np.arange(k), indexing="ij")
    a = 2 * np.pi * i.ravel() / n
    b = 2 * np.pi * j.ravel() / k
    v = np.column_stack([(3 + np.cos(b)) * np.cos(a), (3 + np.cos(b)) * np.sin(a), np.sin(b)])
    idx = (i * k + j)
    p, q = idx, np.roll(idx, -1, axis=0)
    r, s = np.roll(idx, -1, axis=1), np.roll(np.roll(idx, -1, axis=0), -1, axis=1)
    f = np.concatenate([np.stack([p.ravel(), q.ravel(), s.ravel()], 1), np.stack([p.ravel(), s.ravel(), r.ravel()], 1)])
    with pytest.raises(MeshTopologyError, match="handles"):
        validate_mesh(v, f[1:])


def test_holes_give_one_loop_each_with_the_outer_loop_first():
    v, f = surfaces.disk_mesh(3000)
    v3 = np.column_stack([v, np.zeros(len(v))])
    # Cut two holes: drop the faces whose centroid lies in two small disks.
    c = v[f].mean(axis=1)
    keep = (np.linalg.norm(c - [0.4, 0], axis=1) > 0.15) & (np.linalg.norm(c - [-0.4, 0.1], axis=1) > 0.2)
    f = f[keep]
    used = np.unique(f)
    remap = np.full(len(v3), -1)
    remap[used] = np.arange(len(used))
    _, _, conn = validate_mesh(v3[used], remap[f])
    assert len(conn.loops) == 3
    assert len(conn.loops[0]) == 6 * round(np.sqrt(3000 / 6))  # the rim ring


def test_column_helpers_match_the_row_formulas():
    from patterns.measure import local_coordinates
    from patterns.mesh import edge_lengths, face_areas, side_vectors

    v, f = surfaces.ellipsoid_cup(n_faces=600)
    v, f, conn = validate_mesh(v, f)
    e = conn.edges
    assert np.allclose(edge_lengths(v, e), np.linalg.norm(v[e[:, 1]] - v[e[:, 0]], axis=1), rtol=1e-14, atol=0)
    a, b = side_vectors(v, f)
    assert np.array_equal(np.column_stack(a), v[f[:, 1]] - v[f[:, 0]])
    assert np.array_equal(np.column_stack(b), v[f[:, 2]] - v[f[:, 0]])
    cross = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    assert np.allclose(face_areas(v, f), 0.5 * np.linalg.norm(cross, axis=1), rtol=1e-13, atol=0)
    # The local frames are isometric copies: the same three side lengths, counter-clockwise.
    z = local_coordinates(v, f)
    for i, j in ((0, 1), (1, 2), (2, 0)):
        assert np.allclose(np.abs(z[:, j] - z[:, i]), np.linalg.norm(v[f[:, j]] - v[f[:, i]], axis=1),
                           rtol=1e-12, atol=0)
    assert np.all((np.conj(z[:, 1]) * z[:, 2]).imag > 0)
    assert np.allclose(0.5 * (np.conj(z[:, 1]) * z[:, 2]).imag, face_areas(v, f), rtol=1e-12, atol=0)


def test_sort_based_unique_matches_numpy():
    from patterns.mesh import unique_edges, unique_ints
    from patterns.reading import _unique_rows

    rng = np.random.default_rng(2)
    for size in (0, 1, 7, 5000):
        a = rng.integers(-3, 400, size)
        ours = unique_ints(a, return_index=True, return_inverse=True)
        theirs = np.unique(a, return_index=True, return_inverse=True)
        for x, y in zip(ours, theirs):
            assert np.array_equal(x, np.ravel(y))
    # Rows (vertex welding): a triangle soup with every corner repeated.
    v, f = surfaces.ellipsoid_cup(n_faces=2000)
    soup = v[f.ravel()]
    first, inverse = _unique_rows(soup)
    _, first2, inverse2 = np.unique(soup, axis=0, return_index=True, return_inverse=True)
    assert np.array_equal(first, first2) and np.array_equal(inverse, inverse2.ravel())
    assert len(first) == len(v)
    # Edges: the sorted unique (low, high) pairs.
    e = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    assert np.array_equal(unique_edges(f), np.unique(e, axis=0))


def test_exported_functions_take_plain_lists():
    """array_like everywhere: lists give the same answers as arrays (vertices first, then faces)."""
    import trimesh

    v, f = surfaces.spherical_cap(radius=50.0, half_angle=50.0, n_faces=200)
    r = patterns.flatten_mesh(v.tolist(), f.tolist())
    np.testing.assert_array_equal(r.uv, patterns.flatten_mesh(v, f).uv)
    loops = [loop.tolist() for loop in r.loops]
    assert patterns.overlap_verdict(r.uv.tolist(), f.tolist(), loops).one_to_one
    assert patterns.distortion(v.tolist(), f.tolist(), r.uv.tolist()).strain_rms == r.distortion.strain_rms
    ball = trimesh.creation.icosphere(subdivisions=2, radius=10.0)
    cut = patterns.cut_to_disk(ball.vertices.tolist(), ball.faces.tolist())
    assert len(cut.paths) == 1 and cut.faces.shape == ball.faces.shape
    vv, ff, _ = patterns.validate_mesh(v.tolist(), f.tolist())
    np.testing.assert_array_equal(ff, f)
