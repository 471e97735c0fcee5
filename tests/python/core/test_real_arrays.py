# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Arrays of real numbers: complex ones lost their imaginary part in a float cast (numpy only
warned) in the trajectory metrics, the GP's fit and the linear magnetic map as in the map
builders; each caller now refuses them naming its argument, and takes None in a list as NaN."""

from __future__ import annotations

import numpy as np
import pytest

from kiseki._support.real_arrays import real_array
from kiseki.gp import ExactGP, SquaredExponential
from kiseki.magnetic import build_linear_map
from kiseki.metrics import ape

PATH_ID = "0" * 40
POSES = np.column_stack([np.linspace(0.0, 2.0, 5), np.zeros(5), np.zeros(5)])


@pytest.mark.parametrize(
    ("values", "message"),
    [
        ([1.0 + 2j], "x: expected real numbers, got dtype complex128"),
        ([True, False], "x: expected real numbers, got dtype bool"),
        (["1_0"], "x: expected real numbers, got dtype <U3"),
        ([1.0, "2"], "x: expected real numbers, got dtype <U32"),
        ([[1.0], [2.0, 3.0]], "x: expected real numbers in an array of one shape"),
    ],
)
def test_what_is_not_an_array_of_real_numbers_is_refused(values, message):
    with pytest.raises(ValueError) as caught:
        real_array(values, "x")
    assert str(caught.value) == message


def test_integers_floats_and_none_are_real():
    np.testing.assert_array_equal(real_array([1, 2], "x"), [1, 2])
    assert np.isnan(real_array([1.0, None], "x")[1])
    floats = np.zeros(3, np.float32)
    assert real_array(floats, "x") is floats  # not copied


def test_complex_input_is_refused_by_each_caller():
    with pytest.raises(ValueError, match=r"^poses: expected real numbers, got dtype complex128$"):
        ape(POSES + 0j, POSES)
    x = np.linspace(0.0, 1.0, 6)[:, None]
    with pytest.raises(ValueError, match=r"^X: expected real numbers, got dtype complex128$"):
        ExactGP.fit(x + 0j, np.sin(x), SquaredExponential(0.3, 1.0, 0.1))
    with pytest.raises(ValueError, match=r"readings: expected real numbers, got dtype complex"):
        build_linear_map([0.0, 0.1], np.ones((2, 3)) + 0j, [0.0, 0.0], path_id=PATH_ID)
    assert ape(POSES, POSES).rmse == 0.0  # the same poses as reals: taken
