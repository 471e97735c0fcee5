# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""A numpy scalar (float32 from a float32 array, int64 from an index) is taken wherever the
Python number is, with the same result: float32 values were refused with "must be a positive
number, got 5.0", which named a value that looked right."""

from __future__ import annotations

import numpy as np
import pytest

from kiseki.control import PriorityArbiter
from kiseki.filters import MclConfig
from kiseki.gp import CurlFreeKernel, SquaredExponential
from kiseki.magnetic import build_linear_map, geometric_features
from kiseki.magnetic.loop_travel_distance import LoopTravelConfig
from kiseki.magnetic.navigators import r_z
from kiseki.magnetic.rahok_navigation import moving_average, taught_peaks
from kiseki.terrain import attitude_matrix

F32 = np.float32

# a float32 compared with a Python bound is cast to float32 first (1e50 overflowed to inf with a
# RuntimeWarning, 1e-50 to 0): the checks compare Python floats, and warn about nothing
pytestmark = pytest.mark.filterwarnings("error::RuntimeWarning")


def _same(a, b) -> None:
    if isinstance(a, np.ndarray):
        np.testing.assert_array_equal(a, b)
    else:
        assert a == b


@pytest.mark.parametrize(
    ("call", "numpy_args", "python_args"),
    [
        (SquaredExponential, (F32(1.5), F32(0.5), F32(0.25)), (1.5, 0.5, 0.25)),
        (CurlFreeKernel, (F32(1.5), F32(0.5), F32(40.0), F32(0.25)), (1.5, 0.5, 40.0, 0.25)),
        (attitude_matrix, (np.int64(0), F32(0.5), np.float64(1.0)), (0, 0.5, 1.0)),
        (
            lambda m: geometric_features(np.full(9, 2.0), np.linspace(-1.5, 1.5, 9), m),
            (F32(5.0),),
            (5.0,),
        ),
        (
            lambda s: (
                build_linear_map(
                    np.arange(0.0, 2.0, 0.05),
                    np.ones((40, 3)),
                    np.zeros(40),
                    spacing=s,
                    path_id="0" * 40,
                ).s
            ),
            (F32(0.25),),
            (0.25,),
        ),
        (lambda p: PriorityArbiter({"a": p, "b": 1.0}).priorities["a"], (np.int64(3),), (3,)),
        # int64 was refused by checks written as int | float | np.floating
        (lambda n: MclConfig(particles=n).to_core().particles, (np.int64(500),), (500,)),
        (lambda n: LoopTravelConfig(particles=n).particles, (np.int64(500),), (500,)),
        (r_z, (np.int64(1), np.int64(0), np.int64(2)), (1, 0, 2)),
        (lambda c: moving_average(np.arange(7.0), c), (np.int64(3),), (3,)),
        (
            lambda w: [p.s for p in taught_peaks(np.arange(9.0), np.cos(np.arange(9.0)), 0.04, w)],
            (np.int64(2),),
            (2,),
        ),
    ],
)
def test_numpy_scalars_are_taken_as_their_numbers(call, numpy_args, python_args):
    _same(call(*numpy_args), call(*python_args))
