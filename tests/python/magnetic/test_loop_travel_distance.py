# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""kiseki's loop filter: the likelihood against its closed form, the profile's reading around
the loop, the engine's scaled motion and resampling of pairs and its likelihood_power bound (the
MCL's), and the scale estimated on a synthetic loop whose odometry is 10 % long (against the same
filter without readings)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.stats import norm

from kiseki import _core
from kiseki.gp import SquaredExponential
from kiseki.magnetic.loop_profile import LoopProfile, fit_loop_profile, heading_invariant_channels
from kiseki.magnetic.loop_travel_distance import (
    LoopTravelConfig,
    LoopTravelDistanceLocalizer,
    loop_log_likelihood,
)

LOOP = 30.0  # m


def field(s: np.ndarray) -> np.ndarray:
    """Two channels along a 30 m loop (G): smooth anomalies of about 0.05 G, periodic."""
    u = 2 * np.pi * np.asarray(s) / LOOP
    a = 0.04 * np.sin(3 * u) + 0.03 * np.cos(7 * u + 1.0) + 0.02 * np.sin(11 * u)
    b = 0.03 * np.cos(5 * u) + 0.02 * np.sin(13 * u + 0.5)
    return np.column_stack([-0.45 + a, 0.15 + b])


def table_profile(values: np.ndarray, sigma_n: float, var: float = 0.0) -> LoopProfile:
    grid = np.arange(0.0, LOOP, 0.02)
    return LoopProfile(
        LOOP, 0.02, values, np.full(len(grid), var), SquaredExponential(1.0, 0.5, sigma_n)
    )


def test_likelihood_is_the_tempered_gaussian_sum_by_hand():
    grid = np.arange(0.0, LOOP, 0.02)
    truth = field(grid)
    profiles = [table_profile(truth[:, c], 0.01 + 0.01 * c, 1e-5) for c in range(2)]
    d = np.array([0.0, 1.01, 7.3, 29.99, 31.01, -0.99])  # beyond L and below 0: modulo L
    reading = np.array([-0.44, 0.16])
    travelled = 0.2  # tau = 0.2 / 0.5
    got = loop_log_likelihood(profiles, d, reading, travelled)
    want = np.zeros(len(d))
    for c in range(2):
        mean = np.interp(np.mod(d, LOOP), grid, truth[:, c], period=LOOP)
        sd = math.sqrt((0.01 + 0.01 * c) ** 2 + 1e-5)
        want += 0.4 * norm.logpdf(reading[c], mean, sd)
    np.testing.assert_allclose(got, want, rtol=1e-10, atol=1e-10)
    # standing still says nothing; a long step counts once (tau capped at 1)
    assert np.all(loop_log_likelihood(profiles, d, reading, 0.0) == 0.0)
    np.testing.assert_allclose(
        loop_log_likelihood(profiles, d, reading, 5.0), want / 0.4, rtol=1e-10
    )


def test_profile_recovers_a_known_field_and_reads_around_the_seam():
    rng = np.random.default_rng(3)
    s = np.sort(rng.uniform(0.0, LOOP, 300))
    noise = 0.003
    values = field(s)[:, 0] + noise * rng.standard_normal(len(s))
    p = fit_loop_profile(s, values, LOOP)
    probe = np.linspace(0.0, LOOP, 997)
    mean, var = p.at(probe)
    error = mean - field(probe)[:, 0]
    # 10 readings per metre against a field varying over ~0.4 m: the GP's mean is well inside
    # the noise, its predicted SD covers the error, and the fitted noise is the one drawn
    assert np.sqrt(np.mean(error**2)) < noise
    assert np.mean(np.abs(error) <= 3 * np.sqrt(var)) > 0.95
    assert 0.5 * noise < p.kernel.sigma_n < 2 * noise
    a, _ = p.at(np.array([0.3, 12.0]))
    b, _ = p.at(np.array([0.3 + LOOP, 12.0 - 2 * LOOP]))
    np.testing.assert_allclose(a, b, rtol=1e-12)


def test_heading_invariant_channels_do_not_turn_with_the_heading():
    rng = np.random.default_rng(0)
    f = rng.normal(size=(50, 3))
    turn = rng.uniform(-np.pi, np.pi, 50)
    c, s = np.cos(turn), np.sin(turn)
    turned = np.column_stack([c * f[:, 0] - s * f[:, 1], s * f[:, 0] + c * f[:, 1], f[:, 2]])
    np.testing.assert_allclose(
        heading_invariant_channels(turned), heading_invariant_channels(f), atol=1e-12
    )


def test_engine_moves_each_particle_by_its_own_scale_and_resamples_pairs():
    params = _core.TravelDistanceParams()
    params.particles = 4
    f = _core.TravelDistanceFilter(params, 1)
    f.set_particles(np.zeros(4))
    f.set_scales([0.5, 1.0, 2.0, 3.0])
    f.predict_scaled(2.0, 0.0, 0.0)
    np.testing.assert_array_equal(f.particles, [1.0, 2.0, 4.0, 6.0])
    f.update(np.log([1e-12, 1e-12, 1.0, 1e-12]))  # ESS < n/2: resampled to the third
    np.testing.assert_array_equal(f.particles, [4.0] * 4)
    np.testing.assert_array_equal(f.scales, [2.0] * 4)
    with pytest.raises(ValueError, match="scales must be finite and > 0"):
        f.set_scales([1.0, 0.0, 1.0, 1.0])


@pytest.mark.parametrize("power", [0.0, -1.0, 1000.0001, 1e300, math.inf, math.nan])
def test_engine_refuses_a_likelihood_power_outside_the_mcls_bound(power):
    params = _core.TravelDistanceParams()
    params.likelihood_power = 1000.0  # the bound itself is taken, as the MCL engine takes it
    _core.TravelDistanceFilter(params, 1)
    params.likelihood_power = power
    with pytest.raises(ValueError, match=r"likelihood_power must lie in \(0, 1000\]"):
        _core.TravelDistanceFilter(params, 1)


def synthetic_run(scale: float, seed: int, profiles, steps: int = 900):
    """A walk of 0.1 m steps around the loop (2.7 laps); odometry reports ``scale`` times the
    truth; readings = field + N(0, 0.003^2)."""
    rng = np.random.default_rng(1000 + seed)
    true_s = 0.1 * np.arange(steps)
    readings = field(true_s) + 0.003 * rng.standard_normal((steps, 2))
    odo = np.concatenate([[0.0], np.full(steps - 1, 0.1 * scale)])
    loc = LoopTravelDistanceLocalizer(
        profiles, LoopTravelConfig(seed=seed, particles=500), 0.0, length=LOOP
    )
    est, k = loc.run(odo, readings[:, : len(profiles)])
    err = (est - np.mod(true_s, LOOP) + LOOP / 2) % LOOP - LOOP / 2
    return float(np.sqrt(np.mean(err[300:] ** 2))), k


@pytest.fixture(scope="module")
def mapped_loop():
    """The loop's two profiles from a mapping lap of 300 readings (one per 0.1 m)."""
    rng = np.random.default_rng(7)
    s = np.sort(rng.uniform(0.0, LOOP, 300))
    values = field(s) + 0.003 * rng.standard_normal((300, 2))
    return [fit_loop_profile(s, values[:, c], LOOP) for c in range(2)]


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_scale_of_a_10_percent_long_odometry_is_estimated(seed, mapped_loop):
    rmse, k = synthetic_run(1.1, seed, mapped_loop)
    # the travel is k times the odometry's: k -> 1 / 1.1
    assert abs(k[-1] - 1 / 1.1) < 0.01
    assert rmse < 0.1
    # without readings the same filter keeps the prior's scale and drifts 10 % of the travel
    rmse_blind, k_blind = synthetic_run(1.1, seed, [])
    assert abs(k_blind[-1] - 1.0) < 0.05
    assert rmse_blind > 3.0


def test_bad_inputs_are_refused_with_one_line():
    grid_values = field(np.arange(0.0, LOOP, 0.02))[:, 0]
    p = table_profile(grid_values, 0.01)
    with pytest.raises(ValueError, match="start must be one of"):
        LoopTravelConfig(start="somewhere")
    for scale_sd, shown in ((0.7, r"0\.7"), (-0.1, r"-0\.1"), (math.nan, "nan")):  # one rule
        with pytest.raises(
            ValueError,
            match=rf"^loop filter: scale_sd must be a finite number in \[0, 0\.5\), got {shown}$",
        ):
            LoopTravelConfig(scale_sd=scale_sd)
    with pytest.raises(ValueError, match=r"scale_walk must be a finite number >= 0, got -0.1$"):
        LoopTravelConfig(scale_walk=-0.1)
    with pytest.raises(ValueError, match=r"resample_threshold must be a finite number in \[0, 1\]"):
        LoopTravelConfig(resample_threshold=math.nan)
    with pytest.raises(ValueError, match="alpha_slow < alpha_fast"):
        LoopTravelConfig(alpha_slow=0.2, alpha_fast=0.1)
    with pytest.raises(ValueError, match="reentry must be True or False"):
        LoopTravelConfig(reentry="yes")
    with pytest.raises(ValueError, match="length must be given"):
        LoopTravelDistanceLocalizer([])
    with pytest.raises(ValueError, match="disagree"):
        LoopTravelDistanceLocalizer([p], length=LOOP + 1)
    for length in (0.0, math.inf, True, str(LOOP)):  # True was a 1 m loop, text parsed
        with pytest.raises(
            ValueError, match=r"^loop filter: the loop's length must be a finite number > 0 m, got "
        ):
            LoopTravelDistanceLocalizer([], length=length)
    with pytest.raises(
        ValueError, match=r"^loop filter: start must be a finite number \(m\), got nan$"
    ):
        LoopTravelDistanceLocalizer([p], start=math.nan)
    loc = LoopTravelDistanceLocalizer([p])
    with pytest.raises(ValueError, match="reading for 1 channel"):
        loc.step(0.1, [0.1, 0.2])
    with pytest.raises(
        ValueError,
        match=r"^loop filter: the odometry increment must be a finite number \(m\), got nan$",
    ):
        loc.step(math.nan, [0.1])
    with pytest.raises(ValueError, match=r"^loop filter: the reading must be finite$"):
        loc.step(0.1, [math.inf])
    with pytest.raises(ValueError, match="do not match"):
        loc.run(np.zeros(3), np.zeros((4, 1)))
    with pytest.raises(ValueError, match="at least 4"):
        fit_loop_profile([0.0, 1.0], [0.0, 1.0], LOOP)
    with pytest.raises(
        ValueError,
        match=r"^loop profile: the loop's length must be a finite number > 0 m, got -1.0$",
    ):
        fit_loop_profile([0.0, 1.0, 2.0, 3.0], [0.0, 1.0, 2.0, 3.0], -1.0)
    # True passed the old check but was no floor of 1: where the fitted sigma_n was below 1 (as
    # here) the kernel refused it, naming sigma_n (sigma_f when that was below 1 too), and where
    # sigma_n was 1 or more it changed nothing
    for floor in (-0.1, math.nan, True):
        with pytest.raises(
            ValueError, match=r"^loop profile: noise_floor must be a finite number >= 0, got "
        ):
            fit_loop_profile([0.0, 1.0, 2.0, 3.0], [0.0, 1.0, 2.0, 3.0], LOOP, noise_floor=floor)
    with pytest.raises(ValueError, match=r"s must lie in \[0"):
        fit_loop_profile([0.0, 1.0, 2.0, 40.0], [0.0, 1.0, 2.0, 3.0], LOOP)
    # a 1e-9 m grid asked for 149 GiB
    for resolution in (1e-9, LOOP, True):
        with pytest.raises(ValueError, match=r"resolution must be in \[length / 100000"):
            fit_loop_profile(
                [0.0, 1.0, 2.0, 3.0], [0.0, 1.0, 2.0, 3.0], LOOP, resolution=resolution
            )


def test_reentry_finds_a_walker_carried_11_m_without_odometry(mapped_loop):
    """The walker is carried 11 m along the loop while the odometry says 0.1 m (a kidnapping,
    or a stretch off the loop): with re-entry the filter is back within 3 m of travel in every
    one of 10 seeds; without it (the control) it is still lost 30 m later in most of them.
    Without re-entry a filter sometimes finds its way back by chance (4 of seeds 0-19), so the
    control is a share over seeds, not one seed's outcome."""
    steps = 900
    true_s = 0.1 * np.arange(steps)
    true_s[300:] += 11.0
    odo = np.concatenate([[0.0], np.full(steps - 1, 0.1)])
    still_lost = 0
    for seed in range(10):
        noise = 0.003 * np.random.default_rng(100 + seed).standard_normal((steps, 2))
        readings = field(true_s) + noise
        errors = {}
        for reentry in (True, False):
            config = LoopTravelConfig(seed=seed, particles=500, reentry=reentry)
            loc = LoopTravelDistanceLocalizer(mapped_loop, config, 0.0)
            est, _ = loc.run(odo, readings)
            errors[reentry] = (est - np.mod(true_s, LOOP) + LOOP / 2) % LOOP - LOOP / 2
            assert (loc.injected > 0) is reentry
        back = int(np.argmax(np.abs(errors[True][300:]) < 0.3))
        assert back < 30 and np.sqrt(np.mean(errors[True][330:] ** 2)) < 0.1, seed
        assert np.sqrt(np.mean(errors[True][100:300] ** 2)) < 0.05, seed  # no harm before
        still_lost += bool(np.sqrt(np.mean(errors[False][600:] ** 2)) > 1.0)
    assert still_lost >= 5
