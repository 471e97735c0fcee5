# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The thesis' travel-distance filter (sec. 4.4.1) and azimuth heading correction (sec. 4.4.2):
against a brute-force eq. 4.7-4.9, the ESS rule, closed-form gates, and a synthetic path whose
field peaks and true travel distance are known."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kiseki.magnetic.linear_map import build_linear_map
from kiseki.magnetic.travel_distance import (
    TravelDistanceConfig,
    TravelDistanceLocalizer,
    azimuth_heading,
    heading_from_map,
)

PEAKS = np.arange(5.0, 40.0, 8.0)


def field(x):
    """mz (G) along the path: 0.45 G with 0.1 G peaks (the thesis' pipes, sec. 2.3)."""
    x = np.asarray(x, dtype=float)
    return 0.45 + sum(0.1 * np.exp(-0.5 * ((x - p) / 0.4) ** 2) for p in PEAKS)


def linear_map(length=40.0, mz=field):
    s = np.arange(0.0, length, 0.05)
    readings = np.column_stack([np.full_like(s, 0.2), np.zeros_like(s), mz(s)])
    return build_linear_map(s, readings, np.zeros_like(s), path_id="0" * 40)


def test_localization_beats_odometry_with_a_scale_error():
    rng = np.random.default_rng(3)
    true = np.arange(0.0, 38.0, 0.06)  # 0.6 m/s at 10 Hz (sec. 4.5.1)
    increments = np.diff(true, prepend=0.0) * 1.05  # odometry 5 % long
    readings = field(true) + rng.normal(0.0, 0.01, len(true))  # 0.01 G sensor noise
    loc = TravelDistanceLocalizer(linear_map(), TravelDistanceConfig(seed=1))
    est = loc.run(increments, readings)
    odom = np.cumsum(increments)
    err_filter = np.sqrt(np.mean((est - true) ** 2))
    err_odom = np.sqrt(np.mean((odom - true) ** 2))
    assert err_odom > 0.9
    assert err_filter < 0.35 * err_odom
    assert abs(est[-1] - true[-1]) < 0.5  # past the last peak: corrected, not drifting


def brute_force_weights(node_s, node_mz, particles, history, a, window, spacing=0.1):
    """Eqs. 4.7-4.9 written out with loops: history = [(odometry distance, mz)]."""
    now = history[-1][0]
    bins = {}
    for u, m in history:
        k = math.floor((now - u) / spacing + 0.5)
        if 0 <= k < round(window / spacing):
            bins.setdefault(k, []).append(m)
    w = []
    for d in particles:
        s = 0.0
        for k, values in bins.items():
            expected = np.interp(d - k * spacing, node_s, node_mz)
            s += abs(expected - sum(values) / len(values)) * spacing
        w.append(1.0 / (a * s + 1.0))
    w = np.array(w)
    return w / w.sum()


def test_weights_equal_a_brute_force_eq_4_7_to_4_9():
    m = linear_map(length=8.0)
    config = TravelDistanceConfig(
        particles=7, window=0.6, initial_sd=0.5, resample_threshold=0.0, seed=4
    )
    loc = TravelDistanceLocalizer(m, config, start=2.0)
    rng = np.random.default_rng(0)
    history, odometry = [], 0.0
    for step in range(12):
        distance = 0.07 if step else 0.0
        mz = float(field(2.0 + 0.07 * step) + rng.normal(0, 0.01))
        odometry += distance
        history.append((odometry, mz))
        loc.step(distance, mz)
        expected = brute_force_weights(m.s, m.field[:, 2], loc.particles, history, 50.0, 0.6)
        np.testing.assert_allclose(loc.weights, expected, rtol=1e-12)
        # the engine holds the same weights: eq. 4.8 replaces them, it does not multiply
        np.testing.assert_allclose(loc._filter.weights, expected, rtol=1e-12)
        assert loc.estimate == pytest.approx(float(np.dot(expected, loc.particles)), rel=1e-12)


def test_no_resampling_while_ess_is_above_nine_tenths():
    slope = linear_map(length=20.0, mz=lambda x: 0.45 + 0.15 * np.asarray(x, float))
    config = TravelDistanceConfig(particles=200, initial_sd=1.0, odometry_noise=0.0, seed=2)
    loc = TravelDistanceLocalizer(slope, config, start=10.0)
    before = loc.particles.copy()
    for _ in range(5):
        loc.step(0.0, 0.45 + 0.15 * 10.0)  # unequal weights, but ESS stays above 9n/10
        assert 0.9 * 200 < loc.effective_sample_size < 0.95 * 200
        assert not loc.resampled
        np.testing.assert_array_equal(loc.particles, before)


def test_resampling_when_ess_drops_below_nine_tenths():
    m = linear_map()
    config = TravelDistanceConfig(particles=300, initial_sd=1.0, odometry_noise=0.0, seed=2)
    loc = TravelDistanceLocalizer(m, config, start=PEAKS[1] - 2.0)
    seen = {True: 0, False: 0}
    for k in range(40):  # through a peak: the particles off it weigh less and less
        moved = loc.particles + 0.1  # the motion is exact (no noise)
        loc.step(0.1, float(field(PEAKS[1] - 2.0 + 0.1 * (k + 1))))
        low = loc.effective_sample_size < 0.9 * 300
        seen[low] += 1
        if low:  # resampled: copies of the heavy particles
            assert len(np.unique(loc.particles)) < len(np.unique(moved))
            assert np.all(np.isclose(loc.particles[:, None], moved[None, :]).any(axis=1))
        else:
            np.testing.assert_allclose(loc.particles, moved, rtol=0, atol=1e-12)
        assert loc.resampled == low
    assert seen[True] >= 3 and seen[False] >= 3
    assert abs(loc.estimate - (PEAKS[1] + 2.0)) < 0.2


def test_same_seed_same_result_other_seed_another():
    true = np.arange(0.0, 12.0, 0.06)
    inc, mz = np.diff(true, prepend=0.0) * 1.03, field(true)
    runs = [
        TravelDistanceLocalizer(linear_map(), TravelDistanceConfig(seed=s)).run(inc, mz)
        for s in (5, 5, 6)
    ]
    np.testing.assert_array_equal(runs[0], runs[1])
    assert not np.array_equal(runs[0], runs[2])


def test_heading_gate_closed_form():
    # r_z = 1 - 0.005 = 0.995, r_theta = 1 - 0.02 / pi = 0.99363: corrected (eq. 4.14)
    c = azimuth_heading(0.3, 0.5, 0.40, 1.0, 0.52, 0.405)
    assert c.applied
    assert c.r_z == pytest.approx(0.995)
    assert c.r_theta == pytest.approx(1 - 0.02 / math.pi)
    assert c.theta == pytest.approx(1.0 - 0.52 + 0.5)
    # r_z = 0.99 < 0.992: unchanged
    c = azimuth_heading(0.3, 0.5, 0.40, 1.0, 0.52, 0.41)
    assert not c.applied and c.theta == pytest.approx(0.3)
    # r_theta = 1 - 0.04 / pi = 0.98727 < 0.990: unchanged
    c = azimuth_heading(0.3, 0.5, 0.40, 1.0, 0.54, 0.40)
    assert not c.applied and c.r_theta == pytest.approx(1 - 0.04 / math.pi)
    # the azimuth difference is wrapped: pi - 0.01 against -pi + 0.01 is 0.02 apart
    c = azimuth_heading(0.0, -math.pi + 0.01, 0.4, 0.0, math.pi - 0.01, 0.4)
    assert c.applied and c.r_theta == pytest.approx(1 - 0.02 / math.pi)
    assert c.theta == pytest.approx(-(math.pi - 0.01) + (-math.pi + 0.01) + 2 * math.pi)


def test_heading_from_map_uses_the_nearest_node():
    s = np.arange(0.0, 3.0, 0.1)
    heading = np.where(s < 1.5, 0.2, 1.2)
    readings = np.column_stack(
        [np.cos(-0.4) * np.ones_like(s), np.sin(-0.4) * np.ones_like(s), np.full_like(s, 0.4)]
    )
    m = build_linear_map(s, readings, heading, path_id="1" * 40)
    # the reading's azimuth is 0.02 rad more than the map's (r_theta 0.9936): node's + 0.02
    reading = [math.cos(-0.38), math.sin(-0.38), 0.401]
    assert heading_from_map(m, 2.0, 0.0, reading).theta == pytest.approx(1.22)
    assert heading_from_map(m, 0.5, 0.0, reading).theta == pytest.approx(0.22)
    assert not heading_from_map(m, 0.5, 0.0, [1.0, 0.0, 0.5]).applied


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"particles": 0}, "particles must be an integer in 1..10,000,000, got 0"),
        ({"particles": 2.5}, "particles must be an integer"),
        ({"window": -1.0}, r"^travel distance: window l must be a finite number > 0 m, got -1\.0$"),
        ({"gain": float("nan")}, r"^travel distance: gain a must be a finite number > 0, got nan$"),
        ({"odometry_noise": -0.1}, r"odometry_noise must be a finite number >= 0, got -0\.1$"),
        ({"initial_sd": float("inf")}, r"initial_sd must be a finite number >= 0 m, got inf$"),
        ({"resample_threshold": 1.5}, r"resample_threshold must be a finite number in \[0, 1\]"),
        ({"seed": -1}, r"seed must be an integer in \[0, 2\*\*64\), got -1"),
    ],
)
def test_bad_config(kwargs, message):
    with pytest.raises(ValueError, match=message):
        TravelDistanceConfig(**kwargs)


def test_a_config_holds_minus_zero_as_zero():
    """-0.0 was held as given (and passed on to the engine as a spread)."""
    config = TravelDistanceConfig(odometry_noise=-0.0, initial_sd=-0.0, resample_threshold=-0.0)
    for value in (config.odometry_noise, config.initial_sd, config.resample_threshold):
        assert value == 0.0 and math.copysign(1.0, value) == 1.0


def _step(x):
    loc = TravelDistanceLocalizer(linear_map(length=5.0), TravelDistanceConfig(particles=20))
    return loc.step(x, x), loc.particles


def _start(x):
    config = TravelDistanceConfig(particles=20, initial_sd=0.1, seed=3)
    loc = TravelDistanceLocalizer(linear_map(length=5.0), config, start=x)
    return loc.estimate, loc.particles


def _heading_from_map(x):
    return heading_from_map(linear_map(length=5.0), x, x, [0.2, 0.0, 0.45])


@pytest.mark.parametrize(
    "call",
    [_step, _start, lambda x: azimuth_heading(*[x] * 8), _heading_from_map],
    ids=["step", "start", "azimuth_heading", "heading_from_map"],
)
@pytest.mark.parametrize(
    ("numpy_value", "python_value"),
    [(np.float32(0.5), 0.5), (np.int64(1), 1.0)],  # 0.5 is exact in a float32
    ids=["float32", "int64"],
)
def test_numpy_numbers_are_taken_as_their_python_floats(call, numpy_value, python_value):
    """The filter's increment, reading and start, azimuth_heading's values and heading_from_map's
    d and theta refused np.float32 and numpy integers ('must be a number'; they took int, float
    and np.float64): each now gives what the Python float of its value gives."""
    got, want = call(numpy_value), call(python_value)
    for a, b in zip(got, want, strict=True):
        np.testing.assert_array_equal(a, b)


def test_bad_input():
    m = linear_map(length=5.0)
    with pytest.raises(ValueError, match="1 node"):
        TravelDistanceLocalizer(build_linear_map([0.0], [[0, 0, 0.4]], [0.0], path_id="0" * 40))
    with pytest.raises(ValueError, match="must be a LinearMagneticMap"):
        TravelDistanceLocalizer({"s": [0, 1]})
    with pytest.raises(ValueError, match="shorter than the map's"):
        TravelDistanceLocalizer(m, TravelDistanceConfig(window=0.01))
    # its padding took 15 GiB at l = 1e6 m
    with pytest.raises(
        ValueError,
        match="window l 1e\\+06 m is longer than twice the map \\(51 nodes, 5.1 m\\) or 100 m",
    ):
        TravelDistanceLocalizer(m, TravelDistanceConfig(window=1e6))
    loc = TravelDistanceLocalizer(m, TravelDistanceConfig(particles=10))
    with pytest.raises(
        ValueError,
        match=r"^travel distance: the mz reading must be a finite number \(G\), got nan$",
    ):
        loc.step(0.1, float("nan"))
    with pytest.raises(
        ValueError,
        match=r"^travel distance: the odometry increment must be a finite number \(m\), "
        r"got '0\.1'$",
    ):
        loc.step("0.1", 0.4)
    with pytest.raises(
        ValueError, match=r"^travel distance: d must be a finite number \(m\), got nan$"
    ):
        heading_from_map(m, float("nan"), 0.0, [0.1, 0.2, 0.3])
    with pytest.raises(
        ValueError, match=r"^travel distance: node_m_z must be a finite number, got inf$"
    ):
        azimuth_heading(0.0, 0.0, 0.4, 0.0, 0.0, float("inf"))
    with pytest.raises(ValueError, match=r"mz readings\[2\] is NaN"):
        loc.run([0.1, 0.1, 0.1], [0.4, 0.4, float("nan")])
    with pytest.raises(ValueError, match="3 odometry increments but 2 mz"):
        loc.run([0.1, 0.1, 0.1], [0.4, 0.4])
    with pytest.raises(ValueError, match=r"reading must be \(mx, my, mz\)"):
        heading_from_map(m, 1.0, 0.0, [0.1, 0.2])
