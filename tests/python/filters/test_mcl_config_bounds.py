# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The engine's numbers have upper bounds: alphas of 1e300 put the particles 1e148 m off, a
likelihood power of 1e300 overflowed the weights, and ints past a C++ int were a pybind11 list
of signatures; each of these was taken by MclConfig without a word."""

from __future__ import annotations

import math

import pytest

from kiseki.filters import LocalizeConfig, MclConfig

ABSURD = [
    ({"alphas": (1e300, 0.0, 0.0, 0.0)}, "alphas must lie in \\[0, 100\\]"),
    ({"kld": True, "kld_err": 1e300}, "err must lie in \\(0, 1\\]"),
    ({"kld": True, "kld_z": 1e300}, "z in \\[0, 10\\]"),
    ({"resample_threshold": 1e300}, "resample_threshold must lie in \\[0, 1\\]"),
    ({"likelihood_power": 1e300}, "likelihood_power must lie in \\(0, 1000\\]"),
    ({"reset_evidence": 1e300}, "reset_evidence must lie in \\[0, 1e6\\]"),
    ({"expansion_position": 1e300}, "expansion radii must lie in \\[0, 10 m\\]"),
    ({"expansion_orientation": 4.0}, "expansion radii .* and \\[0, pi\\]"),
    ({"update_min_a": 1e300}, "update_min_a must be <= pi"),
    ({"min_particles": 10**300}, "min_particles must be an integer below 2\\*\\*31"),
    ({"reset_after": 10**300}, "reset_after must be an integer below 2\\*\\*31"),
    ({"sensor_reset_after": 2_000_000}, "sensor_reset_after <= 1,000,000"),
    ({"sensor_reset_candidates": 10**300}, "sensor_reset_candidates must be an integer below"),
]


@pytest.mark.parametrize(("fields", "match"), ABSURD)
def test_absurd_engine_numbers_are_refused(fields, match):
    with pytest.raises(ValueError, match=match):
        MclConfig(**fields)


def test_the_bounds_themselves_are_taken():
    config = MclConfig(
        alphas=(100.0, 0.0, 100.0, 0.0),
        kld=True,
        kld_err=1.0,
        kld_z=10.0,
        resample_threshold=1.0,
        likelihood_power=1000.0,
        reset_evidence=1e6,
        expansion_position=10.0,
        expansion_orientation=math.pi,
        update_min_a=math.pi,
        sensor_reset_after=1_000_000,
    )
    assert config.to_core().likelihood_power == 1000.0


@pytest.mark.parametrize("sd", [(1e300, 0.1, 0.05), (0.1, math.nan, 0.05), (0.1, 0.1, -1.0)])
def test_localize_configs_start_spread_is_bounded_where_it_is_given(sd):
    """1e300 was taken by LocalizeConfig and refused later by initialize, naming its own
    argument, not the config's field."""
    with pytest.raises(ValueError, match="initial_sd must be three numbers in \\[0, 1e\\+09\\]"):
        LocalizeConfig(initial_sd=sd)
