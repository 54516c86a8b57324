"""The projected Hessian and the 2n x 2n systems of :mod:`patterns.flattening.hessian` (issue 37)."""

import numpy as np
import pytest
import scipy.sparse as sp

from patterns.flattening.energy import Arap, Hybrid, Jacobian, SymmetricDirichlet, frames
from patterns.flattening.hessian import PAIRS, PairSystem, corner_columns, projected_hessian
from patterns.mesh import validate_mesh
from patterns.surfaces import spherical_cap


def _cap():
    v, f = spherical_cap(radius=100.0, half_angle=40.0, n_faces=400)
    return validate_mesh(v, f, name="cap")


def _apply(blocks, fr, d):
    """``H d`` for the triangles' blocks ``(m, 6, 6)`` and a displacement ``d`` ``(n, 2)``, as ``(2 n,)``."""
    n = len(d)
    corners = np.column_stack(fr.corners)
    local = np.concatenate([d[:, 0][corners], d[:, 1][corners]], axis=1)
    out = np.zeros(2 * n)
    np.add.at(out, np.concatenate([corners, corners + n], axis=1).ravel(), np.einsum("mij,mj->mi", blocks, local).ravel())
    return out


@pytest.mark.parametrize("energy", [Arap, Hybrid, SymmetricDirichlet])
def test_where_no_triangle_is_squeezed_the_projected_hessian_is_the_energys_own(energy):
    """On a layout stretched by 1.3 (every twist eigenvalue positive, nothing clamped), ``H d`` equals the
    central difference of the energy's own gradient along random ``d`` (the reference: :mod:`.energy`)."""
    v, f, _ = _cap()
    fr = frames(v, f)
    rng = np.random.default_rng(3)
    uv = 1.3 * v[:, :2] + rng.normal(scale=0.05, size=(len(v), 2))
    e = energy(fr)
    blocks = projected_hessian(fr, fr.jacobian(uv), e.stretch)
    d = rng.normal(size=uv.shape)
    h = 1e-6
    difference = (e(uv + h * d)[1] - e(uv - h * d)[1]) / (2 * h)
    np.testing.assert_allclose(_apply(blocks, fr, d), np.concatenate([difference[:, 0], difference[:, 1]]),
                               rtol=1e-6, atol=1e-7 * np.abs(difference).max())


@pytest.mark.parametrize("energy", [Arap, Hybrid])
def test_a_squeezed_triangles_negative_curvature_is_clamped_to_zero_and_nothing_else_changes(energy):
    """A single triangle pressed to 0.3 of its size one way.  Its Hessian in ``J`` (4 x 4, by central
    differences of the energy's own ``dE/dJ``) has one negative eigenvalue (the twist); the projected
    block is that Hessian with the negative eigenvalue set to 0, carried to the corners by ``J = x C``."""
    v = np.array([[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [3.0, 8.0, 0.0]])
    f = np.array([[0, 1, 2]])
    fr = frames(v, f)
    uv = np.array([[0.0, 0.0], [3.0, 0.0], [0.9, 8.0]])  # x pressed to 0.3
    e = energy(fr)
    j = np.array([getattr(fr.jacobian(uv), name)[0] for name in ("j11", "j12", "j21", "j22")])
    h = 1e-6
    curvature = np.empty((4, 4))
    for k in range(4):
        step = np.zeros(4)
        step[k] = h
        plus, minus = (e.terms(Jacobian(*(x[None] for x in j + s)))[1] for s in (step, -step))
        curvature[:, k] = (np.concatenate(plus) - np.concatenate(minus)) / (2 * h)
    values, vectors = np.linalg.eigh(0.5 * (curvature + curvature.T))
    assert values[0] < -1e-3 * values[-1]  # the twist: negative where the triangle is squeezed
    clamped = (vectors * np.maximum(values, 0.0)) @ vectors.T  # in (j11, j12, j21, j22) = (k, j) at 2 k + j
    c = corner_columns(fr)[0]  # J[k, j] = sum_c x[k, c] C[c, j]
    expected = np.einsum("kjlJ,cj,CJ->kclC", clamped.reshape(2, 2, 2, 2), c, c).reshape(6, 6)
    np.testing.assert_allclose(projected_hessian(fr, fr.jacobian(uv), e.stretch)[0], expected,
                               rtol=1e-6, atol=1e-7 * np.abs(expected).max())


def test_a_pair_systems_laplacian_and_blocks_land_where_they_belong():
    """``PairSystem.laplacian`` is ``L (x) I`` of scipy's graph Laplacian; assembled blocks, factorised and
    solved, give what scipy's solve of the same sparse matrix gives."""
    v, f, conn = _cap()
    fr = frames(v, f)
    n = len(v)
    system = PairSystem(fr, n)
    rng = np.random.default_rng(5)
    w = rng.uniform(0.5, 2.0, size=len(conn.edges))
    a = sp.coo_matrix((w, (conn.edges[:, 0], conn.edges[:, 1])), shape=(n, n))
    graph = sp.csgraph.laplacian((a + a.T).tocsr())
    reference = sp.kron(sp.eye(2), graph).toarray()
    np.testing.assert_allclose(system.matrix(system.laplacian(conn.edges, w)).toarray(), reference, atol=1e-12)
    blocks = projected_hessian(fr, fr.jacobian(1.1 * v[:, :2]), Hybrid.stretch)
    packed = projected_hessian(fr, fr.jacobian(1.1 * v[:, :2]), Hybrid.stretch, packed=True)
    np.testing.assert_allclose(packed, blocks[:, PAIRS[:, 0], PAIRS[:, 1]], rtol=1e-12, atol=1e-12 * np.abs(blocks).max())
    np.testing.assert_allclose(system.assemble(packed), system.assemble(blocks), rtol=1e-12, atol=1e-12)
    dense = np.zeros((2 * n, 2 * n))  # the blocks scattered by hand, each triangle's unknowns (u0, u1, u2, v0, v1, v2)
    for block, (a, b, c) in zip(blocks, f):
        idx = np.array([a, b, c, a + n, b + n, c + n])
        dense[np.ix_(idx, idx)] += block
    np.testing.assert_allclose(system.matrix(system.assemble(blocks)).toarray(), dense, atol=1e-12 * np.abs(dense).max())
    values = system.assemble(blocks) + system.laplacian(conn.edges, w)
    values[system.diagonal[[0, n]]] += 1.0  # vertex 0 held: neither part sees a translation
    b = rng.normal(size=(n, 2))
    matrix = system.matrix(values)
    expected = sp.linalg.spsolve(matrix.tocsc(), np.concatenate([b[:, 0], b[:, 1]]))
    np.testing.assert_allclose(system.factorize(values).solve(b), np.column_stack([expected[:n], expected[n:]]),
                               rtol=1e-8, atol=1e-10 * np.abs(expected).max())
