# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The filters' helpers against their definitions, and what they are given checked: zero
weights gave a NaN spread with a numpy warning, a fraction of -0.5 or NaN added no odometry
noise without a word, and an (x, y) start was taken with theta = 0."""

from __future__ import annotations

import math

import numpy as np
import pytest

from _helpers.room_log import ANGLES, room
from kiseki.filters import LocalizeConfig, MclConfig, MonteCarloLocalizer, scan_model
from kiseki.filters.convergence import elapsed_time, scan_fit, spread_radius
from kiseki.filters.odometry_noise import noisy_odometry


def test_spread_radius_is_the_smallest_radius_holding_the_share():
    rng = np.random.default_rng(4)
    poses = np.column_stack([rng.normal(size=(200, 2)), np.zeros(200)])
    weights = rng.uniform(0.1, 1.0, 200)
    radius = spread_radius(poses, weights, 0.9)
    w = weights / weights.sum()
    d = np.hypot(*(poses[:, :2] - w @ poses[:, :2]).T)
    assert w[d <= radius].sum() >= 0.9 > w[d < radius].sum()  # by brute force
    for bad in (np.zeros(200), np.full(200, np.nan), -weights):
        with pytest.raises(ValueError, match="spread_radius: weights must be finite"):
            spread_radius(poses, bad)
    for bad in (1.5, 0.0, math.nan, True):  # True was taken as the share 1
        with pytest.raises(
            ValueError, match=r"^spread_radius: share must be a finite number in \(0, 1\], got "
        ):
            spread_radius(poses, weights, bad)


def test_noisy_odometry_without_noise_is_the_path_and_bad_fractions_are_refused():
    path = np.column_stack([np.linspace(0, 3, 20), np.sin(np.linspace(0, 3, 20)), np.zeros(20)])
    path[:, 2] = np.arctan2(np.gradient(path[:, 1]), np.gradient(path[:, 0]))
    np.testing.assert_allclose(noisy_odometry(path, 0.0, 1), path, atol=1e-12)
    assert not np.allclose(noisy_odometry(path, 0.1, 1), path)
    for bad in (-0.5, math.nan, True, 10.0):
        with pytest.raises(
            ValueError,
            match=r"^noisy_odometry: fraction must be a finite number in \[0, 10\), got ",
        ):
            noisy_odometry(path, bad, 1)


def test_a_start_without_a_heading_is_refused():
    loc = MonteCarloLocalizer(MclConfig(particles=10), 1)
    with pytest.raises(ValueError, match=r"pose and sd must be \(x, y, theta\) triples"):
        loc.initialize((1.0, 1.0), (0.1, 0.1, 0.1))
    loc.initialize((1.0, 1.0, 0.5), (0.0, 0.0, 0.0))
    np.testing.assert_allclose(loc.estimate, [1.0, 1.0, 0.5])


@pytest.mark.parametrize("method", ["likelihood-field", "beam", "ray-space-observation"])
def test_a_sigma_hit_below_a_micrometre_is_refused(method):
    """sigma_hit 1e-300 squared is 0: the range models gave NaN log-likelihoods."""
    grid = room()
    pose = np.array([[1.0, 0.0, 0.0]])
    ranges = grid.cast_scans(pose, ANGLES, max_range=8.0)[0]
    with pytest.raises(ValueError, match="sigma_hit must be at least 1e-6 m"):
        scan_model(method, grid, LocalizeConfig(method=method, sigma_hit=1e-300))
    model = scan_model(method, grid, LocalizeConfig(method=method, sigma_hit=1e-6))
    model.set_scan(ANGLES, ranges, 8.0)
    assert np.isfinite(model.log_likelihoods(pose)).all()


def test_elapsed_time_counts_the_clock_forward_only():
    """A log whose clock steps back gave a negative convergence time (times[k] - times[0])."""
    times = np.array([10.0, 11.0, 5.0, 6.0, 7.5])
    assert elapsed_time(times, 4) == pytest.approx(1.0 + 1.0 + 1.5)
    assert elapsed_time(times, 0) == 0.0
    forward = np.cumsum(np.random.default_rng(2).uniform(0.05, 0.2, 50))
    for k in (1, 17, 49):  # bit for bit the plain difference, as before
        assert elapsed_time(forward, k) == forward[k] - forward[0]
    for k in (5, -1, 2.0, True):
        with pytest.raises(
            ValueError, match=r"elapsed_time: k must be an integer in 0\.\.4 \(a scan"
        ):
            elapsed_time(times, k)


def test_scan_fit_refuses_a_max_range_that_is_no_length():
    """A NaN max range made every reading an endpoint (endpoint_agreement's defect, which
    scan_fit shared); all readings at or below zero said 'below max range'."""
    grid = room()
    pose = np.array([[1.0, 0.0, 0.0]])
    ranges = grid.cast_scans(pose, ANGLES, max_range=8.0)
    assert scan_fit(grid, pose, ranges, ANGLES, 8.0).within_1_cell > 0.9  # a scan of the map
    for bad in (math.nan, math.inf, 0.0, "8"):
        with pytest.raises(
            ValueError, match=r"scan_fit: max_range must be a finite number in \(0, 1e\+09\] m"
        ):
            scan_fit(grid, pose, ranges, ANGLES, bad)
    with pytest.raises(ValueError, match=r"scan_fit: no scan endpoint \(a reading > 0"):
        scan_fit(grid, pose, -np.asarray(ranges), ANGLES, 8.0)
