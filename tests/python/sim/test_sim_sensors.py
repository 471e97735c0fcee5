# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The bearing sensor: geometry against closed forms, noise statistics, and line of sight
(range, obstacles of the world, other robots' bodies)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kiseki.sim.scene import load_scene
from kiseki.sim.sensors import BearingParams, BearingSensor

EXACT = BearingParams(noise_sd_deg=0.0, elevation_noise_sd_deg=0.0)


def test_bearing_and_elevation_match_the_geometry() -> None:
    s = BearingSensor(EXACT)
    r = s.observe((1.0, 1.0, 0.5, math.pi / 2), [[1.0, 3.0, 0.5], [0.0, 1.0, 1.5], [2.0, 0.0, 0.5]])
    np.testing.assert_allclose(r.bearings, [0.0, math.pi / 2, -3 * math.pi / 4])
    np.testing.assert_allclose(r.elevations, [0.0, math.pi / 4, 0.0], atol=1e-12)
    assert r.visible.all()
    behind = s.observe((0.0, 0.0, 0.0, 0.0), [[-1.0, 0.0, 0.0]]).bearings[0]
    assert -math.pi <= behind < math.pi  # wrapped


def test_noise_statistics_and_seeds() -> None:
    n = 20000
    s = BearingSensor(BearingParams(noise_sd_deg=0.1, elevation_noise_sd_deg=0.2), seed=3)
    target = np.tile([4.0, 5.0, 1.5], (n, 1))
    r = s.observe((1.0, 1.0, 0.5, 0.4), target)
    truth_b = math.atan2(4.0, 3.0) - 0.4
    truth_e = math.atan2(1.0, 5.0)
    assert np.degrees(r.bearings.std(ddof=1)) == pytest.approx(0.1, rel=0.03)
    assert np.degrees(r.elevations.std(ddof=1)) == pytest.approx(0.2, rel=0.03)
    assert abs(r.bearings.mean() - truth_b) < 4 * math.radians(0.1) / math.sqrt(n)
    assert abs(r.elevations.mean() - truth_e) < 4 * math.radians(0.2) / math.sqrt(n)
    again = BearingSensor(s.params, seed=3).observe((1.0, 1.0, 0.5, 0.4), target)
    np.testing.assert_array_equal(again.bearings, r.bearings)
    other = BearingSensor(s.params, seed=4).observe((1.0, 1.0, 0.5, 0.4), target)
    assert not np.array_equal(other.bearings, r.bearings)


def test_range_limit_and_robots_hide_targets() -> None:
    s = BearingSensor(BearingParams(max_range=5.0, robot_radius=0.3))
    targets = [[3.0, 0.0, 0.5], [6.0, 0.0, 0.5], [0.0, 3.0, 0.5]]
    blockers = [[0.0, 0.0], [1.5, 0.2], [3.0, 0.0], [0.0, 3.0], [-2.0, 2.0]]  # me, r, t, t, far
    r = s.observe((0.0, 0.0, 0.5, 0.0), targets, blockers=blockers)
    # (3, 0): a robot 0.2 m beside the line hides it; (6, 0): beyond 5 m; (0, 3): clear
    assert r.visible.tolist() == [False, False, True]
    assert np.isnan(r.bearings[:2]).all() and np.isfinite(r.bearings[2])
    clear = s.observe((0.0, 0.0, 0.5, 0.0), targets, blockers=[[1.5, 0.4]])
    assert clear.visible.tolist() == [True, False, True]  # 0.4 m off the line: not in the way


def test_walls_of_the_world_hide_targets(tmp_path) -> None:
    (tmp_path / "s.yaml").write_text(
        "name: wall\ndescription: one wall\nsource: test\n"
        "bounds: {min: [-5, -5, -0.1], max: [5, 5, 2]}\nfloor: true\n"
        "objects:\n  - {type: wall, from: [2.0, -1.0], to: [2.0, 1.0]}\n"
        "robot: {type: omni, start: [0, 0, 0]}\n"
    )
    world = load_scene(tmp_path / "s.yaml").world
    s = BearingSensor(EXACT)
    r = s.observe((0.0, 0.0, 0.5, 0.0), [[4.0, 0.0, 0.5], [4.0, 3.0, 0.5], [1.5, 0.0, 0.5]], world)
    assert r.visible.tolist() == [False, True, True]


def test_bad_input() -> None:
    with pytest.raises(ValueError, match="noise_sd_deg"):
        BearingParams(noise_sd_deg=-0.1)
    with pytest.raises(ValueError, match="max_range"):
        BearingParams(max_range=0.0)
    with pytest.raises(ValueError, match="seed"):
        BearingSensor(seed=-1)
    s = BearingSensor()
    with pytest.raises(ValueError, match="sensor"):
        s.observe((0.0, float("nan"), 0.0, 0.0), [[1.0, 1.0, 0.0]])
    with pytest.raises(ValueError, match="targets"):
        s.observe((0.0, 0.0, 0.0, 0.0), [[1.0, 1.0]])
    with pytest.raises(ValueError, match="coincides"):
        s.observe((1.0, 1.0, 0.0, 0.0), [[1.0, 1.0, 0.0]])
