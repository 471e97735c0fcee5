# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""PCL's ICP and GICP through kiseki.terrain.register_pcl: a known rigid motion recovered (the
closed form is the motion itself), and what a user may give it refused in one line."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kiseki.terrain import register_pcl


def _cloud() -> np.ndarray:
    """A corner of three walls, 1,200 points: every motion is observable."""
    rng = np.random.default_rng(3)
    u, v = rng.uniform(0, 2, (2, 400))
    return np.vstack(
        [
            np.column_stack([u, v, 0 * u]),
            np.column_stack([u, 0 * u, v]),
            np.column_stack([0 * u, u, v]),
        ]
    )


def _motion(yaw: float, t) -> np.ndarray:
    m = np.eye(4)
    c, s = math.cos(yaw), math.sin(yaw)
    m[:2, :2] = [[c, -s], [s, c]]
    m[:3, 3] = t
    return m


@pytest.mark.parametrize("method", ["icp", "gicp"])
def test_a_known_motion_is_recovered(method):
    target = _cloud()
    motion = _motion(math.radians(3.0), [0.05, -0.04, 0.02])
    source = (target - motion[:3, 3]) @ motion[:3, :3]  # motion maps source onto target
    found = register_pcl(source, target, method=method)
    assert found.converged
    np.testing.assert_allclose(found.transform, motion, atol=2e-3)
    assert found.fitness < 1e-5


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        # PCL's search aborted the interpreter on these (an assertion on NaN / Inf coordinates)
        ({"source": _cloud() * 1e20}, "the source holds coordinates beyond \\+-1e6 m"),
        ({"target": _cloud() + 1e30}, "the target holds coordinates beyond \\+-1e6 m"),
        # a scaled guess was aligned from as if it were a motion
        ({"initial": np.diag([2.0, 2.0, 2.0, 1.0])}, "the initial guess is not a rigid motion"),
        ({"initial": _motion(0.0, [0, 0, 0]) * [[1], [1], [1], [2]]}, "last row is 0 0 0 1"),
        ({"initial": _motion(0.0, [2e6, 0, 0])}, "moves beyond \\+-1e6 m"),
        # 2.7 iterations were run as 2
        ({"max_iterations": 2.7}, "max_iterations must be an integer in 1..100,000, got 2.7"),
        ({"max_iterations": True}, "max_iterations must be an integer"),
        (
            {"max_iterations": 10**9},
            "max_iterations must be an integer in 1..100,000, got 1000000000",
        ),
    ],
)
def test_bad_input_is_refused_in_one_line(kwargs, message):
    args = {"source": _cloud(), "target": _cloud(), **kwargs}
    with pytest.raises(ValueError, match=message) as caught:
        register_pcl(**args)
    assert "\n" not in str(caught.value)
