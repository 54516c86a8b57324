"""The relaxation's energies (patterns.flattening.energy) against independent computations."""

import numpy as np
import pytest

import patterns
from patterns import surfaces
from patterns.flattening.energy import Arap, EdgeLengths, Hybrid, InverseTerm, SymmetricDirichlet, frames
from patterns.mesh import validate_mesh


def _svd_stretches(v, f, uv):
    """Singular values of each triangle's map, by numpy's SVD of a Jacobian built from scratch."""
    out = []
    for tri in f:
        p = v[tri]
        e1, e2 = p[1] - p[0], p[2] - p[0]
        x = e1 / np.linalg.norm(e1)
        n = np.cross(e1, e2)
        y = np.cross(n / np.linalg.norm(n), x)
        r = np.array([[e1 @ x, e2 @ x], [e1 @ y, e2 @ y]])  # 3D sides in an orthonormal frame
        q = uv[tri]
        flat = np.column_stack([q[1] - q[0], q[2] - q[0]])
        out.append(np.linalg.svd(flat @ np.linalg.inv(r), compute_uv=False))
    return np.array(out)


@pytest.fixture(scope="module")
def cap():
    """A 120-degree cap laid flat by the grower, moved at random (fold-free, strains of several %)."""
    v, f = surfaces.spherical_cap(radius=100.0, half_angle=60.0, n_faces=300)
    v, f, conn = validate_mesh(v, f)
    uv = np.array(patterns.flatten_mesh(v, f, method="isometric").uv)
    rng = np.random.default_rng(3)
    uv += rng.normal(scale=0.6, size=uv.shape)
    assert np.all(patterns.measure.signed_areas(uv, f) > 0)
    return v, f, conn, uv


def test_energies_are_the_area_weighted_sums_of_their_definitions(cap):
    v, f, conn, uv = cap
    s = _svd_stretches(v, f, uv)
    area = patterns.mesh.face_areas(v, f)
    w = area / area.mean()
    fr = frames(v, f)
    arap = np.sum(w * ((s - 1) ** 2).sum(axis=1))
    sd = np.sum(w * (s**2 + s**-2).sum(axis=1)) - 4 * w.sum()
    assert Arap(fr)(uv)[0] == pytest.approx(arap, rel=1e-10)
    assert SymmetricDirichlet(fr)(uv)[0] == pytest.approx(sd, rel=1e-10)
    assert Hybrid(fr)(uv)[0] == pytest.approx(0.5 * arap + 0.125 * sd, rel=1e-10)
    assert InverseTerm(fr)(uv)[0] == pytest.approx(np.sum(w * (s**-2).sum(axis=1)), rel=1e-10)
    floor = 2.02
    excess = np.maximum((s**-2).sum(axis=1) - floor, 0.0)
    assert excess.any() and not excess.all()  # the guard is active on some triangles only
    assert InverseTerm(fr, floor)(uv)[0] == pytest.approx(np.sum(w * excess**2), rel=1e-10)


def test_an_isometry_has_no_energy_down_to_round_off():
    """Strains of 1e-12 must still be seen (no cancellation in the energies): a
    flat part laid down as it is, then stretched by 1e-9."""
    p, f = surfaces.disk_mesh(300)
    v, f, conn = validate_mesh(np.column_stack([p * 50.0, np.zeros(len(p))]), f)
    fr = frames(v, f)
    exact = np.array(v[:, :2])
    for energy in (Arap(fr), SymmetricDirichlet(fr), Hybrid(fr)):
        assert energy(exact)[0] < 1e-24 * len(f)
    stretched = exact * (1 + 1e-9)
    # Two principal strains of 1e-9 per triangle, summed with weights averaging 1.
    assert Arap(fr)(stretched)[0] == pytest.approx(2e-18 * len(f), rel=1e-5)
    assert SymmetricDirichlet(fr)(stretched)[0] == pytest.approx(8e-18 * len(f), rel=1e-5)


@pytest.mark.parametrize("make", [Arap, SymmetricDirichlet, Hybrid, InverseTerm, lambda fr: InverseTerm(fr, 2.02)])
def test_gradients_match_finite_differences(cap, make):
    v, f, conn, uv = cap
    energy = make(frames(v, f))
    rng = np.random.default_rng(7)
    value, grad = energy(uv)
    for _ in range(3):
        d = rng.normal(size=uv.shape)
        h = 1e-6
        numeric = (energy(uv + h * d)[0] - energy(uv - h * d)[0]) / (2 * h)
        assert numeric == pytest.approx(float(np.sum(grad * d)), rel=1e-6)


def test_folded_triangles_make_barrier_energies_infinite(cap):
    v, f, conn, uv = cap
    folded = uv.copy()
    a, b, c = f[0]
    folded[a], folded[b] = uv[b], uv[a]  # turn one triangle over
    fr = frames(v, f)
    for energy in (SymmetricDirichlet(fr), Hybrid(fr), InverseTerm(fr)):
        assert energy(folded) == (np.inf, None)
    assert np.isfinite(Arap(fr)(folded)[0])  # ARAP is bounded: the line search keeps it fold-free


def test_edge_lengths_term_and_its_multipliers(cap):
    v, f, conn, uv = cap
    e = conn.edges[conn.boundary_edges][:12]
    target = np.linalg.norm(v[e[:, 1]] - v[e[:, 0]], axis=1) * 1.01
    group = np.repeat(np.arange(3), 4)  # three runs of four edges, held in total
    term = EdgeLengths(len(v), e, target, group, np.array([1.0, 2.0, 3.0]), 30.0)
    flat = np.linalg.norm(uv[e[:, 1]] - uv[e[:, 0]], axis=1)
    c = np.bincount(group, flat) / np.bincount(group, target) - 1
    np.testing.assert_allclose(term.residual(uv), c, rtol=1e-12)
    assert term(uv)[0] == pytest.approx(np.sum(np.array([1.0, 2.0, 3.0]) * 15.0 * c**2), rel=1e-12)
    assert term.update(uv) == pytest.approx(np.abs(c).max())
    np.testing.assert_allclose(term.lam, 30.0 * c)
    rng = np.random.default_rng(1)
    value, grad = term(uv)
    d = rng.normal(size=uv.shape)
    numeric = (term(uv + 1e-6 * d)[0] - term(uv - 1e-6 * d)[0]) / 2e-6
    assert numeric == pytest.approx(float(np.sum(grad * d)), rel=1e-6)


def test_the_dirichlet_weights_are_the_cotangent_laplacian(cap):
    """The preconditioner's edge weights summed per edge: (cot a + cot b) / 2, the classic formula."""
    v, f, conn, uv = cap
    coef = frames(v, f).dirichlet_weights()
    weight = np.bincount(conn.face_edges.ravel(), coef.ravel(), len(conn.edges))
    area = patterns.mesh.face_areas(v, f)
    expected = np.zeros(len(conn.edges))
    for t, tri in enumerate(f):
        for k in range(3):
            i, j, o = tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]
            a, b = v[i] - v[o], v[j] - v[o]
            cot = (a @ b) / np.linalg.norm(np.cross(a, b))
            expected[conn.face_edges[t, k]] += 0.5 * cot / area.mean()
    np.testing.assert_allclose(weight, expected, rtol=1e-9, atol=1e-12 * np.abs(expected).max())


def test_a_value_without_its_gradient_is_the_same_to_the_last_bit(cap):
    """The line search tests most steps by their value alone (``grad=False``; the relaxation's
    ``_Objective.value``): the value must be the one the full evaluation gives, bit for bit, or a step taken
    would change with the order of the tests.  Every energy, the guard, the seam term and the barrier at
    ``mu`` 0 and 0.1, on the cap moved at random and with a triangle turned over (inf)."""
    from patterns.flattening.relax import _Objective

    v, f, conn, uv = cap
    fr = frames(v, f)
    e = conn.edges[conn.boundary_edges][:12]
    target = np.linalg.norm(v[e[:, 1]] - v[e[:, 0]], axis=1) * 1.01
    folded = uv.copy()
    folded[f[0][0]], folded[f[0][1]] = uv[f[0][1]], uv[f[0][0]]
    for make in (Arap, SymmetricDirichlet, Hybrid):
        for guard in (None, InverseTerm(fr, 1.5)):
            seam = EdgeLengths(len(v), e, target, np.repeat(np.arange(3), 4), np.array([1.0, 2.0, 3.0]), 30.0)
            seam.lam = np.array([0.3, -0.2, 0.1])
            objective = _Objective(make(fr), InverseTerm(fr), guard, seam)
            for layout in (uv, folded):
                for mu in (0.0, 0.1):
                    f_value, f_grad, b_value, b_grad = objective.parts(layout, mu)
                    full = np.inf if f_grad is None or (mu > 0 and b_grad is None) else \
                        f_value if mu == 0 else f_value + mu * b_value
                    assert objective.value(layout, mu) == full
                jac = fr.jacobian(layout)
                alone, both = make(fr).terms(jac, grad=False), make(fr).terms(jac)
                assert (alone is None and both is None) or (alone[0] == both[0] and alone[1] is None)
