"""Nested-dissection numberings (patterns.flattening.numbering) and what they buy: a pattern
whose time and strain do not depend on how the input was numbered, nor on the thread count."""

import os
import subprocess
import sys

import numpy as np
import pytest
import scipy.sparse as sp

import patterns
from patterns import surfaces
from patterns.flattening.numbering import dissection_order, renumber, renumber_connectivity
from patterns.mesh import validate_mesh

from .helpers import rigid_fit_residual


def _shuffled(v, f, seed):
    """The same mesh with vertices and faces renumbered at random."""
    rng = np.random.default_rng(seed)
    p = rng.permutation(len(v))
    inv = np.empty_like(p)
    inv[p] = np.arange(len(v))
    return v[p], inv[f][rng.permutation(len(f))], p


def _fill(matrix, order):
    """Nonzeros of the Cholesky factor of ``matrix`` eliminated in ``order`` (symbolic, by scipy's SuperLU)."""
    import scipy.sparse.linalg as spla

    m = sp.csc_matrix(matrix[order][:, order])
    lu = spla.splu(m, permc_spec="NATURAL", options={"SymmetricMode": True}, diag_pivot_thresh=0.0)
    return lu.L.nnz


@pytest.mark.slow
def test_a_dissection_order_is_a_permutation_that_keeps_the_factor_thin():
    v, f = surfaces.paraboloid_dish(n_faces=20_000)
    v, f, conn = validate_mesh(v, f)
    order = dissection_order(v, conn.edges)
    assert np.array_equal(np.sort(order), np.arange(len(v)))
    n = len(v)
    e = conn.edges
    laplacian = sp.coo_matrix((np.ones(len(e)), (e[:, 0], e[:, 1])), shape=(n, n))
    laplacian = -(laplacian + laplacian.T) + sp.diags(np.full(n, 7.0))
    random = np.random.default_rng(0).permutation(n)
    # A 2D mesh: nested dissection's factor is O(n log n); a random order fills in most of it.
    assert _fill(laplacian, order) < 0.1 * _fill(laplacian, random)
    assert _fill(laplacian, order) < 40 * n


@pytest.mark.parametrize("bits", [1, 2, 20, 41, 53, 63, 64])
def test_the_highest_set_bit_is_python_s_bit_length_less_one(bits):
    """Both ways the dissection finds an edge's cut level: by the float exponent (codes under 2**53, every
    2D code) and bit by bit (a 3D code), checked against Python's own integers, powers of two and their
    neighbours included (where a float would round up)."""
    from patterns.flattening.numbering import _highest_bit

    rng = np.random.default_rng(bits)
    top = (1 << bits) - 1
    values = [1, top, 1 << (bits - 1), max(1, (1 << (bits - 1)) - 1), max(1, top - 1)]
    values += [int(x) for x in rng.integers(1, min(top, 2**63 - 1), size=200, dtype=np.uint64, endpoint=True)]
    x = np.array(values, dtype=np.uint64)
    assert np.asarray(_highest_bit(x)).tolist() == [v.bit_length() - 1 for v in values]


def test_the_last_vertices_numbered_cut_the_mesh_into_blocks_numbered_before_them():
    """Nested dissection's defining property: a short run of vertices numbered last
    (the top cut) separates the rest into pieces, each numbered as one block."""
    from scipy.sparse import csgraph
    from scipy.spatial import Delaunay

    rng = np.random.default_rng(3)
    points = rng.random((900, 2))
    tri = Delaunay(points).simplices
    e = np.unique(np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1), axis=0)
    order = dissection_order(points, e)
    n = len(points)
    rank = np.empty(n, dtype=int)
    rank[order] = np.arange(n)
    found = None
    for k in range(1, n // 5):
        keep = rank < n - k
        ee = e[keep[e[:, 0]] & keep[e[:, 1]]]
        graph = sp.coo_matrix((np.ones(len(ee)), (ee[:, 0], ee[:, 1])), shape=(n, n))
        _, label = csgraph.connected_components(graph, directed=False)
        pieces = [np.sort(rank[(label == c) & keep]) for c in np.unique(label[keep])]
        if len(pieces) >= 2 and all(p[-1] - p[0] == len(p) - 1 for p in pieces):
            found = k
            break
    # A square of 900 points: its cut is about a side long (30), not a fraction of the area.
    assert found is not None and found < 3 * np.sqrt(n)


def test_renumbered_connectivity_equals_a_fresh_validation():
    v, f = surfaces.spherical_cap(radius=100.0, half_angle=60.0, n_faces=3000)
    v, f, conn = validate_mesh(v, f)
    num = renumber(np.random.default_rng(0).permutation(len(v)), f)
    a = renumber_connectivity(conn, num)
    _, _, b = validate_mesh(v[num.vertex], num.faces)
    assert {tuple(x) for x in a.edges.tolist()} == {tuple(x) for x in b.edges.tolist()}
    faces = num.faces
    for t in range(0, len(faces), 5):
        for k in range(3):
            assert set(a.edges[a.face_edges[t, k]].tolist()) == {faces[t, k], faces[t, (k + 1) % 3]}
    for i in range(len(v)):
        fa = a.vertex_faces[a.vertex_faces_ptr[i]:a.vertex_faces_ptr[i + 1]]
        fb = b.vertex_faces[b.vertex_faces_ptr[i]:b.vertex_faces_ptr[i + 1]]
        assert sorted(fa.tolist()) == sorted(fb.tolist())
    assert sorted(map(sorted, (x.tolist() for x in a.loops))) == sorted(map(sorted, (x.tolist() for x in b.loops)))
    for row in range(len(a.edges)):
        faces_of = {x for x in a.edge_faces[row].tolist() if x >= 0}
        assert all(set(a.edges[row].tolist()) <= set(faces[t].tolist()) for t in faces_of)


@pytest.mark.parametrize("shape", ["cap", "cup"])
def test_renumbering_changes_neither_the_strain_nor_the_pattern(shape):
    v, f = (surfaces.spherical_cap(radius=100.0, half_angle=30.0, n_faces=10_000) if shape == "cap"
            else surfaces.ellipsoid_cup(n_faces=10_000))
    a = patterns.flatten_mesh(v, f)
    vs, fs, p = _shuffled(v, f, 1)
    b = patterns.flatten_mesh(vs, fs)
    assert b.distortion.strain_rms == pytest.approx(a.distortion.strain_rms, rel=5e-3)
    # The same pattern, up to where it lies: within the solver's tolerance.
    assert rigid_fit_residual(b.uv, a.uv[p]) < 1e-3 * np.ptp(a.uv, axis=0).max()


_THREADS_SCRIPT = """
import sys, numpy as np, patterns
from patterns import surfaces
v, f = surfaces.ellipsoid_cup(n_faces=6000)
head = patterns.load(sys.argv[1]).panels[0] if sys.argv[1] != "-" else None
out = [patterns.flatten_mesh(v, f).uv]
if head is not None:
    out.append(patterns.flatten_mesh(head.vertices, head.faces).uv)
sys.stdout.buffer.write(b"".join(np.ascontiguousarray(u).tobytes() for u in out))
"""


@pytest.mark.slow
def test_the_pattern_does_not_depend_on_the_blas_thread_count():
    """The same input gives the same pattern, bit for bit, with one BLAS thread or several:
    the engine sums without BLAS and holds BLAS to one thread (a head's relaxation is
    path-sensitive: with the thread count's rounding it once ended 4 % apart in area)."""
    from .conftest import CORPUS

    head = CORPUS / "bff_cowhead.obj"  # without the corpus, the generated cup alone
    arg = str(head) if head.is_file() else "-"
    results = []
    for threads in ("1", "2"):
        env = dict(os.environ, OPENBLAS_NUM_THREADS=threads, OMP_NUM_THREADS=threads, MKL_NUM_THREADS=threads)
        proc = subprocess.run([sys.executable, "-c", _THREADS_SCRIPT, arg], env=env, capture_output=True, timeout=600)
        assert proc.returncode == 0, proc.stderr.decode()
        results.append(proc.stdout)
    assert len(results[0]) > 0 and results[0] == results[1]


def test_a_mesh_numbered_at_random_is_worked_on_in_order_and_refused_in_its_own_numbers():
    """Large meshes numbered at random are renumbered along a space-filling curve first; a
    refusal still names the input's own vertex, and the result comes back in its order."""
    from patterns.errors import InputError

    v, f = surfaces.spherical_cap(radius=100.0, half_angle=30.0, n_faces=120_000)
    vs, fs, p = _shuffled(v, f, 2)
    r = patterns.flatten_mesh(vs, fs)
    np.testing.assert_array_equal(r.faces, fs)
    assert r.one_to_one and r.loops[0].max() < len(vs)
    assert rigid_fit_residual(r.uv, patterns.flatten_mesh(v, f).uv[p]) < 1e-4 * np.ptp(r.uv, axis=0).max()
    bad = vs.copy()
    bad[12_345] = np.nan
    with pytest.raises(InputError, match="first: vertex 12345"):
        patterns.flatten_mesh(bad, fs)
    flipped = fs.copy()
    flipped[777] = flipped[777, ::-1]
    with pytest.raises(patterns.PatternsError, match="wound"):
        patterns.flatten_mesh(vs, flipped)
