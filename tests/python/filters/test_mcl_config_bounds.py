# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The engine's numbers have upper bounds: alphas of 1e300 put the particles 1e148 m off, a
likelihood power of 1e300 overflowed the weights, and ints past a C++ int were a pybind11 list
of signatures; each of these was taken by MclConfig without a word."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kiseki.filters import GlobalConfig, LocalizeConfig, MclConfig
from kiseki.filters.odometry_noise import motion_alphas
from kiseki.magnetic import MagneticMclConfig
from kiseki.scans import LaserScans

ABSURD = [
    ({"alphas": (1e300, 0.0, 0.0, 0.0)}, "alphas must lie in \\[0, 1000\\]"),
    ({"kld": True, "kld_err": 1e300}, "^kld_err must be a finite number in \\(0, 1\\]"),
    ({"kld": True, "kld_z": 1e300}, "^kld_z must be a finite number in \\[0, 10\\]"),
    ({"resample_threshold": 1e300}, "resample_threshold must lie in \\[0, 1\\]"),
    ({"likelihood_power": 1e300}, "likelihood_power must lie in \\(0, 1000\\]"),
    ({"reset_evidence": 1e300}, "reset_evidence must lie in \\[0, 1e6\\]"),
    ({"expansion_position": 1e300}, "^expansion_position must be a finite number in \\[0, 10\\] m"),
    ({"update_min_a": 1e300}, "update_min_a must be <= 2 pi"),
    ({"min_particles": 10**300}, "min_particles must be an integer in 1..10,000,000"),
    ({"reset_after": -(10**300)}, "reset_after must be a C\\+\\+ int"),
    ({"sensor_reset_candidates": 10**300}, "sensor_reset_candidates must be a C\\+\\+ int"),
]
# just past each bound: the bounds are where they are said to be, not somewhere beyond
JUST_PAST = [
    ({"alphas": (1000.01, 0.0, 0.0, 0.0)}, "alphas must lie in \\[0, 1000\\]"),
    ({"kld": True, "kld_err": 1.0001}, "^kld_err must be a finite number in \\(0, 1\\]"),
    ({"kld": True, "kld_z": 10.001}, "^kld_z must be a finite number in \\[0, 10\\]"),
    ({"resample_threshold": 1.0001}, "resample_threshold must lie in \\[0, 1\\]"),
    ({"likelihood_power": 1000.1}, "likelihood_power must lie in \\(0, 1000\\]"),
    ({"reset_evidence": 1e6 + 1}, "reset_evidence must lie in \\[0, 1e6\\]"),
    ({"expansion_position": 10.01}, "^expansion_position must be a finite number in \\[0, 10\\] m"),
    (
        {"expansion_orientation": math.pi + 1e-9},
        "^expansion_orientation must be a finite number in \\[0, pi\\] rad",
    ),
    ({"update_min_a": 2 * math.pi + 1e-9}, "update_min_a must be <= 2 pi"),
    ({"sensor_reset_after": 1_000_001}, "sensor_reset_after <= 1,000,000"),
    ({"min_particles": 10_000_001}, "min_particles must be an integer in 1..10,000,000, got"),
]


@pytest.mark.parametrize(("fields", "match"), ABSURD + JUST_PAST)
def test_absurd_engine_numbers_are_refused(fields, match):
    with pytest.raises(ValueError, match=match):
        MclConfig(**fields)


def test_the_bounds_themselves_are_taken():
    config = MclConfig(
        alphas=(1000.0, 0.0, 1000.0, 0.0),
        kld=True,
        kld_err=1.0,
        kld_z=10.0,
        resample_threshold=1.0,
        likelihood_power=1000.0,
        reset_evidence=1e6,
        expansion_position=10.0,
        expansion_orientation=math.pi,
        update_min_a=2 * math.pi,
        sensor_reset_after=1_000_000,
    )
    assert config.to_core().likelihood_power == 1000.0


@pytest.mark.parametrize("sd", [(1e300, 0.1, 0.05), (0.1, math.nan, 0.05), (0.1, 0.1, -1.0)])
def test_a_start_spread_is_bounded_where_it_is_given(sd):
    """1e300 was taken by the configs and refused later by initialize, naming its own argument,
    not the config's field; the three configs check it with one function."""
    with pytest.raises(ValueError, match="^initial_sd must be 3 numbers in \\[0, 1e\\+09\\]"):
        LocalizeConfig(initial_sd=sd)
    with pytest.raises(ValueError, match="^initial_sd must be 3 numbers in \\[0, 1e\\+09\\]"):
        MagneticMclConfig(initial_sd=sd)


def test_localize_config_checks_the_alphas_it_is_given():
    """LocalizeConfig checked the default alphas, not the ones given: 1e300 was taken and the
    run refused them after loading the log and the map."""
    with pytest.raises(ValueError, match="alphas must lie in \\[0, 1000\\]"):
        LocalizeConfig(alphas=(1e300, 0.0, 0.0, 0.0))
    # the largest odometry noise a config takes, on a log whose odometry is not its reference
    # (the real odometry's alphas added), gives alphas the engine takes
    config = LocalizeConfig(odometry_noise=9.999)
    poses = np.zeros((2, 3))
    scans = LaserScans(
        times=np.array([0.0, 0.1]),
        poses=poses,
        odometry=poses + 0.01,
        ranges=np.ones((2, 3), np.float32),
        angles=np.array([-0.1, 0.0, 0.1]),
        max_range=5.0,
    )
    alphas = motion_alphas(config, scans)
    assert max(alphas) > 99.9
    assert config.mcl(alphas).alphas == alphas


UNITS = [
    (LocalizeConfig, "sigma_hit", "sigma_hit must be a finite number > 0 m, got nan"),
    (LocalizeConfig, "lambda_short", "lambda_short must be a finite number > 0 1/m, got nan"),
    (
        LocalizeConfig,
        "beam_skip_distance",
        "beam_skip_distance must be a finite number >= 0 m, got nan",
    ),
    (MclConfig, "update_min_d", "update_min_d must be a finite number >= 0 m, got nan"),
    (MclConfig, "update_min_a", "update_min_a must be a finite number >= 0 rad, got nan"),
    (GlobalConfig, "sigma_hit", "sigma_hit must be a finite number > 0 m, got nan"),
    (GlobalConfig, "shrink_radius", "shrink_radius must be a finite number > 0 m, got nan"),
    (GlobalConfig, "converged_radius", "converged_radius must be a finite number > 0 m, got nan"),
    (GlobalConfig, "update_min_d", "update_min_d must be a finite number >= 0 m, got nan"),
    (GlobalConfig, "update_min_a", "update_min_a must be a finite number >= 0 rad, got nan"),
]


@pytest.mark.parametrize(("config", "name", "message"), UNITS)
def test_a_length_or_an_angle_is_refused_in_its_unit(config, name, message):
    """The filters' lengths and angles read bare ('sigma_hit must be a finite number > 0')
    where the other areas name theirs."""
    with pytest.raises(ValueError) as caught:
        config(**{name: math.nan})
    assert str(caught.value) == message
