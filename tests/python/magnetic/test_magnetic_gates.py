# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""kiseki's gate from the sensor's noise: the noise read back from a map of known noise, the
gate's pass rate on an unchanged field against the normal distribution's, and the navigator
using it in place of the thesis' r_z gate."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kiseki.magnetic import build_linear_map, path_identity
from kiseki.magnetic.gates import gate_limits, reading_noise_sd
from kiseki.magnetic.navigators import MultiNavigator


def smooth_field(s: np.ndarray) -> np.ndarray:
    """G: a field varying over metres, with a sharp 0.3 G anomaly every 10 m (buried pipes)."""
    pipes = sum(0.3 * np.exp(-0.5 * ((s - c) / 0.15) ** 2) for c in np.arange(5.0, s[-1], 10.0))
    return -0.45 + 0.02 * np.sin(s / 3.0) + 0.01 * np.cos(s / 1.3) + pipes


@pytest.mark.parametrize("sigma", [0.002, 0.01, 0.03])
@pytest.mark.parametrize("pipes", [False, True])
def test_noise_is_read_back_from_a_map_of_known_noise(sigma, pipes):
    rng = np.random.default_rng(11)
    s = np.arange(0.0, 200.0, 0.1)
    counts = rng.integers(0, 4, len(s))  # 0: an interpolated node
    noise = sigma * rng.standard_normal(len(s)) / np.sqrt(np.maximum(counts, 1))
    field = smooth_field(s) if pipes else -0.45 + 0.02 * np.sin(s / 3.0)
    got = reading_noise_sd(field + noise, counts)
    # about 1,000 runs of three measured nodes: the median's relative SD is about 5 %
    assert got == pytest.approx(sigma, rel=0.12) if not pipes else 0.9 * sigma < got < 1.3 * sigma
    # the pipes' curvature (about 6 % of the nodes) can only lift the estimate: a wider gate


def test_gate_passes_an_unchanged_field_at_the_normal_rate_and_stops_a_change():
    rng = np.random.default_rng(5)
    sigma, n = 0.01, 200_000
    counts = rng.integers(1, 5, n)
    limits = gate_limits(sigma, counts)
    np.testing.assert_allclose(limits, 3.0 * sigma * np.sqrt(1.0 + 1.0 / counts))
    node = sigma * rng.standard_normal(n) / np.sqrt(counts)
    reading = sigma * rng.standard_normal(n)
    passed = np.mean(np.abs(node - reading) <= limits)
    want = math.erf(3.0 / math.sqrt(2.0))  # 0.9973
    assert abs(passed - want) < 4 * math.sqrt(want * (1 - want) / n)
    # a change of 6 sigma is stopped on nearly every step; the thesis' 0.002 G gate would
    # stop the unchanged field on most of them
    assert np.mean(np.abs(node - (reading + 6 * sigma)) <= limits) < 0.05
    assert np.mean(np.abs(node - reading) <= 0.002) < 0.2


def test_navigator_uses_the_limits_in_place_of_the_thesis_gate():
    s = np.arange(0.0, 5.0, 0.1)
    field = np.column_stack([np.full_like(s, 0.2), np.zeros_like(s), np.full_like(s, -0.4)])
    xy = np.column_stack([s, np.zeros_like(s)])
    lmap = build_linear_map(s, field, np.zeros_like(s), position=xy, path_id=path_identity(xy))
    limits = np.full(len(lmap), 0.03)
    sensor = MultiNavigator(lmap, ("magnetic", "odometry"), mz_limits=limits)
    thesis = MultiNavigator(lmap, ("magnetic", "odometry"))
    for dz, sensor_ok, thesis_ok in (
        (0.001, True, True),
        (0.02, True, False),
        (0.05, False, False),
    ):
        reading = np.array([0.2, 0.0, -0.4 + dz])
        assert sensor.proposals(3, 0.0, reading, (np.nan, np.nan))["magnetic"][1] is sensor_ok
        assert thesis.proposals(3, 0.0, reading, (np.nan, np.nan))["magnetic"][1] is thesis_ok
    with pytest.raises(ValueError, match="one per node"):
        MultiNavigator(lmap, ("magnetic",), mz_limits=limits[:-1])


def test_bad_inputs():
    with pytest.raises(ValueError, match="at least 10 are needed"):
        reading_noise_sd(np.zeros(8), np.ones(8))
    with pytest.raises(ValueError, match="counts >= 0"):
        reading_noise_sd(np.zeros(30), -np.ones(30))
    with pytest.raises(ValueError, match=r"^gates: noise_sd must be a finite number > 0, got 0.0$"):
        gate_limits(0.0, [1, 2])
    with pytest.raises(ValueError, match="^gates: z must be a finite number > 0, got '3'$"):
        gate_limits(0.01, [1], z="3")
