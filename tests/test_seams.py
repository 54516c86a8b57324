"""Seam-true flattening: seams as long flat as in 3D, both sides equal, ease on purpose."""

import numpy as np
import pytest

import patterns
from patterns import Ease
from patterns.audit import Code
from patterns.errors import InputError
from patterns.samples import bowl_segment, sphere_gores

from .conftest import SAMPLES
from .helpers import independent_one_to_one


@pytest.fixture(scope="module")
def cup_model():
    return patterns.load(SAMPLES / "cup.step")


def _assert_seams_true(pattern, *, rel=2e-3, mm=0.2):
    for s in pattern.seams:
        target = s.seam.polyline_length
        for flat in s.flat_lengths:
            assert flat == pytest.approx(target, rel=rel)
            assert flat == pytest.approx(s.seam.length, rel=rel)  # the exact CAD length too
        assert abs(s.mismatch) <= mm
    for flat in pattern.panels:
        assert flat.flattening.one_to_one and independent_one_to_one(flat.faces, flat.uv)


def test_cup_seams_are_true_on_both_sides(cup_model):
    free = patterns.flatten(cup_model, seams="free")
    true = patterns.flatten(cup_model)  # seams="true" is the default
    _assert_seams_true(true, rel=2e-4, mm=0.01)
    # Edge by edge: every seam edge of each side at its 3D length.
    for s in true.seams:
        for p, idx in zip(s.seam.panels, s.seam.vertices):
            flat = true.panels[p]
            l3 = np.linalg.norm(np.diff(flat.vertices[idx], axis=0), axis=1)
            l2 = np.linalg.norm(np.diff(flat.uv[idx], axis=0), axis=1)
            np.testing.assert_allclose(l2, l3, rtol=2e-4)
    # Free, the least-strain layout of a gore stretches its edges (4.9 % here).
    for s in free.seams:
        assert min(s.flat_lengths) > 1.03 * s.seam.length
    # "total" holds each side's length only: true in length, less strain than edge by edge.
    total = patterns.flatten(cup_model, seams="total")
    _assert_seams_true(total, rel=2e-4, mm=0.02)
    rms = [[p.flattening.distortion.strain_rms for p in x.panels] for x in (free, total, true)]
    for a, b, c in zip(*rms):
        assert a < b < c  # measured 2.31 %, 3.02 %, 3.69 %: the price of seams that sew true


def test_a_freeform_panel_against_an_exact_one():
    """The bowl: where the freeform face meets a plane developed exactly, the two sides
    of the seam end equal (free, they differ by 7 mm on the 235.6 mm rim)."""
    model = patterns.load(bowl_segment())
    kinds = [p.surface.kind.value if p.surface else "freeform" for p in model.panels]
    assert kinds.count("freeform") == 1 and kinds.count("plane") == 3
    free = patterns.flatten(model, seams="free")
    rim = max(free.seams, key=lambda s: s.seam.length)
    assert rim.seam.length == pytest.approx(150 * np.pi / 2, rel=1e-6)  # the rim: a quarter circle of 150 mm
    assert abs(rim.mismatch) > 5.0
    true = patterns.flatten(model)
    _assert_seams_true(true)
    assert patterns.check(true, max_seam_mismatch=0.2).ok


def test_a_sphere_in_four_gores():
    model = patterns.load(sphere_gores())
    assert len(model.panels) == 4 and len(model.seams) == 4
    pattern = patterns.flatten(model)
    _assert_seams_true(pattern)
    for s in pattern.seams:
        assert s.seam.length == pytest.approx(100 * np.pi, rel=1e-4)  # pole to pole


@pytest.mark.parametrize(("ease", "extra"), [(Ease(0, "face0", mm=5.0), 5.0), (Ease(0, "face0", ratio=0.02), None)])
def test_ease_lengthens_one_side_on_purpose(cup_model, ease, extra):
    pattern = patterns.flatten(cup_model, ease=ease)
    seam = pattern.seams[0]
    side = seam.seam.panels.index(pattern.panels.index(next(p for p in pattern.panels if p.name == "face0")))
    base = seam.seam.polyline_length
    want = base + (extra if extra is not None else 0.02 * base)
    assert seam.flat_lengths[side] == pytest.approx(want, rel=2e-4)
    assert seam.flat_lengths[1 - side] == pytest.approx(base, rel=2e-4)
    assert seam.held_lengths[side] == pytest.approx(want, rel=1e-12)
    report = patterns.check(pattern)
    assert not [f for f in report.findings if f.code is Code.SEAM_LENGTH_NOT_KEPT]
    # The other seams stay true.
    for s in pattern.seams[1:]:
        assert s.flat_lengths == pytest.approx((s.seam.polyline_length,) * 2, rel=2e-4)


def test_ease_on_a_planar_panel_sends_it_through_the_engine():
    model = patterns.load(bowl_segment())
    rim = max(model.seams, key=lambda s: s.length)
    plane = next(model.panels[p].name for p in rim.panels if model.panels[p].surface is not None)
    pattern = patterns.flatten(model, ease=Ease(rim.id, plane, mm=3.0))
    flat = next(p for p in pattern.panels if p.name == plane)
    assert flat.flattening.method == "relaxed"
    fs = pattern.seams[rim.id]
    side = [model.panels[p].name for p in rim.panels].index(plane)
    assert fs.flat_lengths[side] == pytest.approx(rim.polyline_length + 3.0, rel=2e-4)


@pytest.mark.parametrize(
    ("kwargs", "words"),
    [
        ({"seams": "loose"}, "seams must be one of true, total, free, got 'loose'"),
        ({"ease": Ease(99, "face0", mm=1)}, "seam 99"),
        ({"ease": Ease(0, "nope", mm=1)}, "names panel 'nope'"),
        ({"ease": Ease(0, "face0", ratio=2.0)}, "ease takes 0.5 to 2"),
        ({"ease": Ease(0, "face0", mm=float("nan"))}, "finite number"),
        ({"ease": (Ease(0, "face0", mm=1), Ease(0, "face0", mm=2))}, "given twice"),
        ({"ease": "0:face0:5"}, "patterns.Ease"),
        ({"ease": Ease(0, "face0", mm=1), "seams": "free"}, "ease needs"),
    ],
)
def test_bad_seam_options(cup_model, kwargs, words):
    with pytest.raises(InputError) as info:
        patterns.flatten(cup_model, **kwargs)
    assert words in str(info.value)


def test_held_lengths_through_flatten_mesh():
    """The engine option itself: edges held at given lengths, one by one or in groups."""
    from patterns import surfaces

    v, f = surfaces.spherical_cap(radius=100.0, half_angle=60.0, n_faces=2000)
    free = patterns.flatten_mesh(v, f)
    loop = free.loops[0]
    edges = np.column_stack([loop, np.roll(loop, -1)])
    l3 = np.linalg.norm(v[edges[:, 1]] - v[edges[:, 0]], axis=1)
    held = patterns.flatten_mesh(v, f, lengths=(edges, l3))
    l2 = np.linalg.norm(held.uv[edges[:, 1]] - held.uv[edges[:, 0]], axis=1)
    np.testing.assert_allclose(l2, l3, rtol=1.1e-4)
    assert held.length_error <= 1e-4 and held.converged and held.one_to_one
    # In one group: only the total is held.
    total = patterns.flatten_mesh(v, f, lengths=(edges, l3, np.zeros(len(edges), dtype=int)))
    l2 = np.linalg.norm(total.uv[edges[:, 1]] - total.uv[edges[:, 0]], axis=1)
    assert l2.sum() == pytest.approx(l3.sum(), rel=1.1e-4)
    assert np.abs(l2 / l3 - 1).max() > 1e-3  # the edges themselves are free
    free_total = np.linalg.norm(free.uv[edges[:, 1]] - free.uv[edges[:, 0]], axis=1).sum()
    assert free_total > 1.01 * l3.sum()  # free, the rim of a cap comes out long
    with pytest.raises(InputError, match="not an edge"):
        patterns.flatten_mesh(v, f, lengths=(np.array([[0, loop[len(loop) // 2]]]), np.array([1.0])))
    with pytest.raises(InputError, match="positive finite"):
        patterns.flatten_mesh(v, f, lengths=(edges, -l3))
    with pytest.raises(InputError, match="relaxed"):
        patterns.flatten_mesh(v, f, method="isometric", lengths=(edges, l3))
