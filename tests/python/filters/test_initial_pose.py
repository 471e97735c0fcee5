# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""A filter's start checked (kiseki.filters.initial_pose): standard deviations of 1e300 m drew
particles 1e299 m away without a word (every model weighing them then overflowed), True was
taken as a deviation of 1, and weights of 1e308 were said to 'sum to 0'."""

from __future__ import annotations

import numpy as np
import pytest

from _helpers.room_log import room, room_scans
from kiseki.filters import LocalizeConfig, MclConfig, MonteCarloLocalizer
from kiseki.filters.tracking import localize

SD = (0.1, 0.1, 0.05)


def _localizer() -> MonteCarloLocalizer:
    return MonteCarloLocalizer(MclConfig(particles=20), 1)


@pytest.mark.parametrize(
    "sd", [(1e300, 1e300, 0.1), (0.1, 0.1, 1e300), (2e9, 0.1, 0.1), (np.nan, 0, 0), (True, 0, 0)]
)
def test_a_spread_beyond_a_billion_or_not_a_number_is_refused(sd):
    with pytest.raises(ValueError, match=r"initialize: sd must be 3 numbers in \[0, 1e\+09\] \("):
        _localizer().initialize((1.0, 2.0, 0.0), sd)


@pytest.mark.parametrize("pose", [(1e300, 0.0, 0.0), (0.0, -2e9, 0.0), (0, 0, np.inf), ("1", 0, 0)])
def test_a_start_beyond_a_billion_or_not_a_number_is_refused(pose):
    with pytest.raises(ValueError, match=r"initialize: pose must be 3 numbers within \+-1e\+09 \("):
        _localizer().initialize(pose, SD)


def test_a_start_within_the_bound_is_drawn_around_it():
    loc = _localizer()
    loc.initialize(np.array([1e9, -1e9, 3.0]), (np.float32(0.5), 0.5, 0.0))
    assert np.all(np.abs(loc.poses[:, :2] - [1e9, -1e9]) < 5.0)


def test_localize_with_an_absurd_initial_spread_is_refused():
    """The estimates were 1e299 m from the log without a word; the config refuses the spread
    where it is given, and a config of the largest spread runs."""
    scans = room_scans(4, length=0.3)
    with pytest.raises(ValueError, match=r"initial_sd must be 3 numbers in \[0, 1e\+09\]"):
        LocalizeConfig(particles=50, initial_sd=(1e300, 1e300, 0.1))
    config = LocalizeConfig(particles=50, initial_sd=(1e9, 1e9, 0.1))
    assert np.isfinite(localize(scans, room(), config).estimates).all()


def test_particles_beyond_a_billion_or_weights_of_no_share_are_refused():
    loc = _localizer()
    far = np.zeros((5, 3))
    far[3] = (0.0, 1e300, 0.0)
    with pytest.raises(ValueError, match=r"poses must be finite and within \+-1e\+09 .* row 3 "):
        loc.initialize_particles(far)
    with pytest.raises(ValueError, match=r"poses must be numbers, an \(n, 3\) array$"):
        loc.initialize_particles([["a", "b", "c"]])  # was "got shape (0, 0)"
    for weights in (np.zeros(5), np.full(5, np.nan), -np.ones(5), np.ones(4), ["a"] * 5):
        with pytest.raises(ValueError, match="weights must be 5 finite numbers >= 0 .*not all 0"):
            loc.initialize_particles(np.zeros((5, 3)), weights)
    with pytest.raises(ValueError, match=r"poses must be an \(n, 3\) array, n >= 1"):
        loc.initialize_particles(np.zeros((0, 3)))


def test_weights_too_large_to_sum_are_the_same_share():
    """1e308 each overflowed their sum, which was then said to be 0."""
    poses = np.column_stack([np.arange(4.0), np.zeros(4), np.zeros(4)])
    huge, plain = _localizer(), _localizer()
    huge.initialize_particles(poses, np.array([1e308, 1e308, 1e308, 0.0]))
    plain.initialize_particles(poses, np.array([1.0, 1.0, 1.0, 0.0]))
    np.testing.assert_allclose(huge.weights, plain.weights)
    np.testing.assert_allclose(huge.estimate, plain.estimate)
    assert huge.estimate[0] == pytest.approx(1.0)
