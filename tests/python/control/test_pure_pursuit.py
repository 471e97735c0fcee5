# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Pure pursuit: the closed form on a straight route (on the line and heading along it: no turn;
off it: the arc through the lookahead point, yaw rate 2 v y / L^2), and what it is given checked
(a NaN lookahead or pose gave NaN yaw rates, a negative max_accel "math domain error")."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kiseki.control import PurePursuit

ROUTE = [[0.0, 0.0], [10.0, 0.0]]


def test_the_arc_through_the_lookahead_point():
    v, w = PurePursuit(ROUTE, 0.5, 0.6, 0.1, 0.5).command((1.0, 0.0, 0.0))[::2]
    assert (v, w) == (0.5, 0.0)
    # 0.2 m to the right of the line, heading along it: the target (1.6, 0) lies at
    # (0.6, 0.2) in the body frame; the arc through it has curvature 2 y / d^2
    v, _, w = PurePursuit(ROUTE, 0.5, 0.6, 0.1, 0.5).command((1.0, -0.2, 0.0))
    assert w == pytest.approx(v * 2 * 0.2 / (0.6**2 + 0.2**2), rel=0.05)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        ((0.5, math.nan, 0.1, 0.5), r"lookahead must be a finite number > 0 m, got nan"),
        ((0.5, 0.6, 0.1, -0.5), r"max_accel must be a finite number > 0 m/s\^2, got -0.5"),
        ((0.5, 0.6, 0.0, 0.5), "tolerance must be a finite number > 0 m, got 0.0"),
        ((True, 0.6, 0.1, 0.5), "route speed must be a finite number > 0 m/s, got True"),
    ],
)
def test_bad_settings_are_refused(args, message):
    with pytest.raises(ValueError, match=message):
        PurePursuit(ROUTE, *args)


def test_waypoints_that_are_not_pairs_are_refused():
    """Three numbers were numpy's "cannot reshape array of size 3 into shape (2)", and (2, 3)
    poses were read as three pairs of numbers."""
    for bad, shape in (([0.0, 1.0, 2.0], r"\(3,\)"), (np.zeros((2, 3)), r"\(2, 3\)")):
        with pytest.raises(
            ValueError, match=rf"^a route's waypoints are \(x, y\) pairs, got shape {shape}$"
        ):
            PurePursuit(bad, 0.5, 0.6, 0.1, 0.5)
    flat = PurePursuit([0.0, 0.0, 2.0, 0.0], 0.5, 0.6, 0.1, 0.5)  # pairs given flat: taken
    np.testing.assert_array_equal(flat.points, [[0.0, 0.0], [2.0, 0.0]])


def test_a_nan_pose_is_refused():
    with pytest.raises(ValueError, match="pose must be three finite numbers"):
        PurePursuit(ROUTE, 0.5, 0.6, 0.1, 0.5).command((math.nan, 0.0, 0.0))


@pytest.mark.parametrize("bad", [-0.1, math.nan, True])  # True capped the speed at 1 m/s
def test_a_bad_speed_cap_is_refused(bad):
    with pytest.raises(ValueError) as e:
        PurePursuit(ROUTE, 0.5, 0.6, 0.1, 0.5).command((1.0, 0.0, 0.0), max_speed=bad)
    assert str(e.value) == f"max_speed must be a finite number >= 0 m/s, got {bad!r}"
