"""Reweighted local-global steps (SLIM's proxy) for far starts with crushed parts (issue 37)."""

import gzip
import hashlib
from pathlib import Path

import numpy as np
import pytest

import patterns
from patterns.flattening.energy import Jacobian, SymmetricDirichlet, frames
from patterns.flattening.relax import relax
from patterns.flattening.slim import _proxy, crushed_start, reweighted
from patterns.measure import signed_areas
from patterns.mesh import edge_lengths, validate_mesh

LIMBS = Path(__file__).resolve().parent.parent / "benchmarks" / "data" / "limbs"


def test_the_proxy_is_slims_from_the_singular_value_decomposition():
    """``A^2 = U diag(a^2) U^T`` and ``A^2 R``, ``R = U V^T``, with ``a^2 = (1 - t) + t (s + 1)(s^2 + 1) / (4 s^3)``
    per singular value ``s`` (SLIM's ``f'(s) / (2 (s - 1))`` of ``(1 - t)(s - 1)^2 + t (s^2 + s^-2 - 2) / 4``),
    against numpy's SVD of each Jacobian."""
    rng = np.random.default_rng(7)
    j = rng.normal(size=(500, 2, 2))
    j[np.linalg.det(j) < 0, :, 0] *= -1.0  # one-to-one: det > 0
    j[0] = [[0.3, 0.0], [0.0, 0.3]]  # conformal: no principal direction (beta = 0)
    u, s, vt = np.linalg.svd(j)
    jac = Jacobian(j[:, 0, 0], j[:, 0, 1], j[:, 1, 0], j[:, 1, 1])
    for share in (0.0, 0.5, 1.0):
        a2 = (1.0 - share) + share * (s + 1.0) * (s * s + 1.0) / (4.0 * s ** 3)
        expected = np.einsum("mik,mk,mjk->mij", u, a2, u)
        weight, target = _proxy(jac, (1.0 - share, 0.25 * share))
        np.testing.assert_allclose(weight, expected, rtol=1e-9, atol=1e-12 * np.abs(expected).max())
        np.testing.assert_allclose(target, expected @ (u @ vt), rtol=1e-9, atol=1e-12 * np.abs(expected).max())


def _hand(fingers=4, length=24, width=2, palm=12):
    """A flat hand: a palm of ``palm x palm`` unit cells and ``fingers`` fingers ``width`` cells wide and
    ``length`` long, every cell two triangles, in the plane z = 0 (so its true layout is itself)."""
    cells = {(i, j) for i in range(palm) for j in range(palm)}
    gap = (palm - fingers * width) // (fingers + 1)
    for k in range(fingers):
        left = gap + k * (width + gap)
        cells |= {(left + i, palm + j) for i in range(width) for j in range(length)}
    points = sorted({(i + a, j + b) for i, j in cells for a in (0, 1) for b in (0, 1)})
    index = {p: k for k, p in enumerate(points)}
    faces = []
    for i, j in sorted(cells):
        a, b, c, d = index[(i, j)], index[(i + 1, j)], index[(i + 1, j + 1)], index[(i, j + 1)]
        faces += [(a, b, c), (a, c, d)]
    v = np.array([(x, y, 0.0) for x, y in points], dtype=np.float64) * 10.0  # 10 mm cells
    return v, np.array(faces, dtype=np.int64)


def test_reweighted_steps_carry_a_crushed_start_of_a_flat_hand_to_its_true_shape():
    """A flat hand laid out with its fingers pressed to 1e-4 of their length (one-to-one: y is squeezed
    beyond the palm, monotonically): a crushed start, where the hand itself is not.  The reweighted
    steps alone take its symmetric Dirichlet energy down by orders of magnitude in at most 20 steps,
    one-to-one; relaxed on (``"auto"``: the hybrid at once), the layout is the hand itself, every edge
    at its length (a plane flattens exactly, so the reference is the mesh), no triangle folded."""
    v, f = _hand()
    v, f, conn = validate_mesh(v, f, name="hand")
    palm = 120.0
    start = v[:, :2].copy()
    beyond = start[:, 1] > palm
    start[beyond, 1] = palm + (start[beyond, 1] - palm) * 1e-4
    fr = frames(v, f)
    assert np.all(signed_areas(start, f) > 0)
    assert crushed_start(fr, start) and not crushed_start(fr, v[:, :2])
    sd = SymmetricDirichlet(fr)
    before = sd.terms(fr.jacobian(start))[0]
    carried, used, blocked = reweighted(fr, start, conn.loops)
    assert not blocked
    after = sd.terms(fr.jacobian(carried))[0]
    assert 1 <= used <= 20 and after < 1e-3 * before
    assert np.all(signed_areas(carried, f) > 0) and patterns.overlap_verdict(carried, f, conn.loops).one_to_one
    e = conn.edges
    outline = conn.loops[0]
    seam = np.column_stack([outline, np.roll(outline, -1)])  # the outline held at its 3D length, edge by edge
    for lengths in (None, (seam, edge_lengths(v, seam))):
        result = relax(v, f, conn, start, barrier=0.1, tolerance=1e-9, max_iterations=2000, lengths=lengths)
        assert result.energy == "hybrid" and np.all(signed_areas(result.uv, f) > 0)
        flat = np.linalg.norm(result.uv[e[:, 1]] - result.uv[e[:, 0]], axis=1)
        np.testing.assert_allclose(flat, edge_lengths(v, e), rtol=1e-4)


def test_a_reweighted_step_that_would_run_the_outline_into_itself_stops_the_steps():
    """The flat hand with two fingers, everything above the palm pressed towards the hand's middle line to
    1e-3 of its width: the fingers lie 0.002 mm apart.  SLIM's proxy inflates each finger about itself,
    into the other: the first step that lowers the energy crosses the outline, so the steps stop there
    (``blocked``), the layout one-to-one and its energy no higher than the start's; ``relax`` then takes
    the barrier path from the start (energy "arap" or the hybrid it falls back on, never a crossing)."""
    v, f = _hand(fingers=2, length=16, width=2, palm=8)
    v, f, conn = validate_mesh(v, f, name="hand")
    start = v[:, :2].copy()
    above = start[:, 1] > 80.0
    middle = 40.0
    start[above, 0] = middle + (start[above, 0] - middle) * 1e-3
    fr = frames(v, f)
    assert np.all(signed_areas(start, f) > 0) and patterns.overlap_verdict(start, f, conn.loops).one_to_one
    assert crushed_start(fr, start)
    sd = SymmetricDirichlet(fr)
    carried, used, blocked = reweighted(fr, start, conn.loops)
    assert blocked and used >= 1
    assert np.all(signed_areas(carried, f) > 0) and patterns.overlap_verdict(carried, f, conn.loops).one_to_one
    assert sd.terms(fr.jacobian(carried))[0] <= sd.terms(fr.jacobian(start))[0]
    result = relax(v, f, conn, start, barrier=0.1)
    assert np.all(signed_areas(result.uv, f) > 0) and patterns.overlap_verdict(result.uv, f, conn.loops).one_to_one


def test_the_bundled_thin_limbed_meshes_are_the_bytes_their_readme_names():
    """Every ``*.obj.gz`` of ``benchmarks/data/limbs`` decompresses to the sha256 its README's table gives."""
    readme = (LIMBS / "README.md").read_text()
    files = sorted(LIMBS.glob("*.obj.gz"))
    assert len(files) == 5
    for path in files:
        row = next(line for line in readme.splitlines() if f"`{path.name}`" in line)
        assert hashlib.sha256(gzip.decompress(path.read_bytes())).hexdigest() in row


@pytest.mark.slow
@pytest.mark.parametrize("name", ["optcuts_hand_1_i_f5000.obj.gz", "optcuts_armadillo_i_f10000.obj.gz",
                                  "optcuts_dilo_o_f10000.obj.gz", "optcuts_hand_2_i_f10000.obj.gz"])
def test_thin_limbed_meshes_flatten_one_to_one_and_uncrushed(name):
    """Issue 37's quality criteria on OptCuts' hands, armadillo and dinosaur (the speed is the
    benchmark's): no fold, one-to-one, the 1st-percentile smallest stretch at least 0.1."""
    import trimesh

    with gzip.open(LIMBS / name) as stream:
        mesh = trimesh.load(stream, file_type="obj", process=False)
    v, f = np.asarray(mesh.vertices, dtype=np.float64), np.asarray(mesh.faces, dtype=np.int64)
    result = patterns.flatten_mesh(v, f, name=name)
    measured = patterns.distortion(v, f, result.uv)
    assert result.n_folded == 0 and result.one_to_one and measured.n_folded == 0
    assert measured.stretch_p1 >= 0.1
