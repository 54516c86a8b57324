"""One validator for every numeric option: numpy numbers taken, bools, NaN and infinities refused."""

import numpy as np
import pytest

import patterns
from patterns import surfaces
from patterns.errors import InputError
from patterns.options import check_number, is_number

from .conftest import SAMPLES


@pytest.mark.parametrize("value", [3, 3.5, np.float32(3.5), np.float64(3.5), np.int64(3)])
def test_python_and_numpy_numbers_are_numbers(value):
    assert is_number(value) and check_number(value, "x", low=0) == pytest.approx(float(value))


@pytest.mark.parametrize("value", [True, np.bool_(True), "3", None, [3], float("nan"), float("inf")])
def test_bools_strings_and_non_finite_values_are_refused(value):
    with pytest.raises(InputError, match="x must be"):
        check_number(value, "x", name="part")


def test_bounds_and_messages():
    assert check_number(0.0, "tolerance", low=0) == 0.0
    with pytest.raises(InputError, match="part: max_strain must be a positive number, got 0"):
        check_number(0, "max_strain", low=0, low_open=True, name="part")
    with pytest.raises(InputError, match="between 0 and 1"):
        check_number(1.0, "min_stretch", low=0, high=1, low_open=True, high_open=True)
    with pytest.raises(InputError, match="an integer >= 0"):
        check_number(2.5, "max_darts", low=0, integer=True)


def test_the_same_number_types_everywhere():
    """np.float32 limits are taken by check as by flatten_mesh (they were refused by one and
    taken by the other); infinite text heights and spacings are refused before a file is written."""
    v, f = surfaces.spherical_cap(radius=100.0, half_angle=30.0, n_faces=300)
    assert patterns.flatten_mesh(v, f, min_stretch=np.float32(0.3)).one_to_one
    pattern = patterns.flatten(patterns.load(SAMPLES / "hopper.step"))
    assert patterns.check(pattern, max_strain=np.float32(0.03)).ok
    with pytest.raises(InputError, match="max_strain"):
        patterns.check(pattern, max_strain=True)


@pytest.mark.parametrize("option", ["text_height", "notch_spacing", "bend_spacing", "arc_tolerance"])
def test_dxf_lengths_must_be_finite(tmp_path, option):
    pattern = patterns.flatten(patterns.load(SAMPLES / "hopper.step"))
    out = tmp_path / "x.dxf"
    with pytest.raises(InputError, match=option):
        pattern.to_dxf(out, **{option: float("inf")})
    assert not out.exists()
