# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""magnetic-walks on the synthetic circular walk of the walk command's tests (a known field, so
the truth is known) and on a recorded walk: the loop filter's scoring against the thesis' own
walk code, which computes the restarted dead reckoning independently, and the loop filter
against a walk whose true travel is the circle's arc."""

from __future__ import annotations

import numpy as np
import pytest

from _helpers.synthetic_walk import RADIUS, write_walk
from kiseki.datasets.kok import read_kok_walk
from kiseki.magnetic.loop_walk import localize_walk_loop, map_walk_loop, wrap_around
from kiseki.magnetic.travel_distance_walk import WalkOdometry, localize_walk
from kiseki_experiments.magnav.magnav_walks import WalksConfig, trial


def test_loop_filter_on_a_synthetic_circle_follows_the_arc(tmp_path):
    write_walk(tmp_path / "loop.mat", laps=4.0)
    walk = read_kok_walk(tmp_path / "loop.mat")
    wm = map_walk_loop(walk)
    assert wm.length == pytest.approx(2 * np.pi * RADIUS, abs=0.2)
    result = localize_walk_loop(wm, 0, WalkOdometry(scale_error=0.1))
    # the truth of a circle: its arc from the start, modulo the loop
    angle = np.arctan2(walk.positions[:, 1], walk.positions[:, 0] + RADIUS)
    arc = np.mod(angle, 2 * np.pi) * RADIUS
    rows = np.searchsorted(walk.times - walk.times[0], result.t)
    err = wrap_around(result.s_est - arc[rows], wm.length)
    assert np.sqrt(np.mean(err[50:] ** 2)) < 0.25
    # 10 % long odometry: its dead reckoning drifts by 10 % of the 75 m travelled; the filter
    # finds the scale the travel needs
    assert result.rmse("s_dr") > 2.0
    half = len(result.scale) // 2
    assert np.mean(result.scale[half:]) == pytest.approx(1 / 1.1, abs=0.03)


def test_trial_scores_as_the_thesis_walk_code_does(shared_data):
    folder = shared_data / "magnetic" / "kok_1d"
    if not (folder / "eight.mat").is_file():
        pytest.skip(f"{folder}/eight.mat not found")
    config = WalksConfig(data_dir=str(folder), walks=["eight"])
    record = trial(config, 0, 3).record
    thesis = localize_walk(read_kok_walk(folder / "eight.mat"), 3, WalkOdometry())
    assert record["thesis"] == pytest.approx(thesis.rmse("s_est"), rel=1e-12)
    # the restarted dead reckoning: two independent code paths, one number
    assert record["dr_lap"] == pytest.approx(thesis.rmse("s_odom"), rel=1e-9)
    assert record["thesis_dr"] == pytest.approx(record["dr_lap"], rel=1e-9)
    assert record["scale_error_drawn"] == pytest.approx(thesis.scale_error, rel=1e-12)
    # the loop filter is told nothing of laps, yet beats continuous dead reckoning here
    assert record["kiseki"] < record["dr"]
