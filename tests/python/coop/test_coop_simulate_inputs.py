# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What the cooperative-positioning runs are given, checked first: a plan of another kind was
an AttributeError ('NoneType' object has no attribute 'nominal_positions'), a string angle
SD a TypeError from math.isfinite, and numpy's integers were refused as run counts."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kiseki.coop import plan, simulate, simulate_3d


def _flat(x, y):
    return np.zeros_like(x)


@pytest.mark.parametrize("bad", [None, "form 2", (2, 7)])
def test_a_plan_of_another_kind_is_refused_naming_it(bad):
    needle = f"the_plan must be a Plan (see plan()), got {type(bad).__name__}"
    with pytest.raises(TypeError) as caught:
        simulate(bad, 3)
    assert str(caught.value) == needle
    with pytest.raises(TypeError) as caught:
        simulate_3d(bad, _flat, 3)
    assert str(caught.value) == needle


def test_numbers_of_the_wrong_kind_are_refused_and_numpy_numbers_taken():
    p = plan(2, 7)
    for sigma in ("0.1", None, True, np.nan, 0.5):
        with pytest.raises(ValueError, match=r"angle_sigma must lie in \[0, 10 deg\), got "):
            simulate(p, 3, angle_sigma=sigma)
        if sigma is not None:  # no elevation_sigma: angle_sigma's
            with pytest.raises(ValueError, match=r"elevation_sigma must lie in \[0, 10 deg\)"):
                simulate_3d(p, _flat, 3, elevation_sigma=sigma)
    for runs in (True, 2.0, 0, "3"):
        with pytest.raises(ValueError, match=r"runs must be an integer in 1\.\.1,000,000, got "):
            simulate(p, runs)
    with pytest.raises(
        ValueError, match=r"marker_height must be a finite number in \[0, 10\) m, got True"
    ):
        simulate_3d(p, _flat, 3, marker_height=True)
    with pytest.raises(TypeError, match="ground must be a function z\\(x, y\\), got NoneType"):
        simulate_3d(p, None, 3)
    # numpy integers and floats are numbers: the same runs as Python's
    same = simulate(p, np.int64(4), angle_sigma=np.float32(0.002), seed=np.uint8(5))
    plain = simulate(p, 4, angle_sigma=float(np.float32(0.002)), seed=5)
    np.testing.assert_array_equal(same.goal_errors, plain.goal_errors)
    assert simulate_3d(p, _flat, np.int32(2), seed=1).goal_errors.shape == (2,)


def test_a_negative_zero_sd_is_no_noise():
    """-0.0 passed the check (0 <= -0.0) and numpy's normal refused it: 'scale < 0'."""
    p = plan(2, 7)
    run = simulate(p, 3, angle_sigma=-0.0)
    assert run.goal_errors.max() < 1e-9 and math.copysign(1.0, run.angle_sigma) == 1.0
    run = simulate_3d(p, _flat, 3, angle_sigma=np.float32(-0.0), elevation_sigma=-0.0)
    assert run.goal_errors.max() < 1e-9
    assert [math.copysign(1.0, v) for v in (run.angle_sigma, run.elevation_sigma)] == [1.0, 1.0]


@pytest.mark.parametrize(
    ("angle", "message"),
    [
        (True, "the representative angle must be a finite number (rad), got True"),  # was 57 deg
        (np.nan, "the representative angle must be a finite number (rad), got nan"),
        (np.radians(90.0), "the representative angle must lie in 5..85 deg, got 90.0"),
    ],
)
def test_a_representative_angle_is_a_number_in_its_range(angle, message):
    with pytest.raises(ValueError) as caught:
        plan(2, 7, angle)
    assert str(caught.value) == message
