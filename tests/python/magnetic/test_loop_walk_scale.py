# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The loop filter learns the odometry's scale on a synthetic walk whatever its start: the claim
over seeds 0-4 (one seed's estimate moves with the machine's floating-point kernels), and its
control, the same filter without the field's readings."""

from __future__ import annotations

import math

import numpy as np
import pytest

from _helpers.synthetic_walk import write_walk
from kiseki.datasets.kok import read_kok_walk
from kiseki.magnetic.loop_travel_distance import LoopTravelConfig
from kiseki.magnetic.loop_walk import localize_walk_loop, map_walk_loop
from kiseki.magnetic.travel_distance_walk import WalkOdometry, localize_walk, walk_odometry

SCALE_ERROR = 0.08  # the odometry 8 % long: the travel is 1 / 1.08 of it
SEEDS = range(5)


@pytest.fixture(scope="module")
def mapped(tmp_path_factory):
    """Four laps of the synthetic circle, the first one mapped once for every seed."""
    path = tmp_path_factory.mktemp("walk") / "loop.mat"
    write_walk(path, laps=4.0)
    walk = read_kok_walk(path)
    odometry = WalkOdometry(scale_error=SCALE_ERROR)
    return map_walk_loop(walk, odometry), odometry


def late_scale(mapped, start: str, seed: int, use_field: bool = True) -> float:
    """The filter's scale averaged over the second half of the localized samples."""
    walk_map, odometry = mapped
    config = LoopTravelConfig(start=start)
    result = localize_walk_loop(walk_map, seed, odometry, config, use_field=use_field)
    return float(np.mean(result.scale[len(result.scale) // 2 :]))


@pytest.mark.parametrize("start", ["known", "global"])
def test_the_scale_approaches_the_odometry_s_error_over_seeds(mapped, start):
    """Criterion (the walk command's test before, there on one seed): the mean over seeds 0-4
    of the late scale within 0.03 of 1 / 1.08. Control: without the field's readings the
    filter keeps its prior scale, 1, and misses the same bound."""
    scales = [late_scale(mapped, start, seed) for seed in SEEDS]
    assert np.mean(scales) == pytest.approx(1 / (1 + SCALE_ERROR), abs=0.03)
    blind = [late_scale(mapped, start, seed, use_field=False) for seed in SEEDS[:2]]
    assert abs(np.mean(blind) - 1 / (1 + SCALE_ERROR)) > 0.03


def test_a_walk_takes_a_numpy_seed_as_its_python_twin(mapped, tmp_path):
    """A seed from a numpy array (np.int64) was refused by both walks ("walk: seed must be an
    integer"): each gives the estimates of the same Python seed, and refuses a negative one in
    the library's seed words."""
    walk_map, odometry = mapped
    loop = [localize_walk_loop(walk_map, seed, odometry).scale for seed in (np.int64(3), 3)]
    np.testing.assert_array_equal(*loop)
    path = tmp_path / "loop.mat"
    write_walk(path, laps=2.5)
    walk = read_kok_walk(path)
    laps = [localize_walk(walk, seed, odometry).s_est for seed in (np.uint32(3), 3)]
    np.testing.assert_array_equal(*laps)
    for call in (lambda: localize_walk_loop(walk_map, -1), lambda: localize_walk(walk, -1)):
        with pytest.raises(ValueError, match=r"^walk: seed must be an integer in \[0, 2\*\*64\)"):
            call()


@pytest.mark.parametrize(
    ("kw", "message"),
    [
        ({"noise": -0.1}, r"^walk: noise must be a finite number >= 0, got -0\.1$"),
        ({"radius": float("nan")}, r"^walk: radius must be a finite number >= 0, got nan$"),
        ({"scale_error": -1.0}, r"^walk: scale_error must be a finite number > -1, got -1\.0$"),
        ({"scale_error": True}, r"^walk: scale_error must be a finite number > -1, got True$"),
    ],
)
def test_bad_walk_odometry_is_refused(kw, message):
    """A scale error of True was taken as an odometry 100 % long."""
    with pytest.raises(ValueError, match=message):
        WalkOdometry(**kw)


def test_a_walk_odometry_of_minus_zero_is_one_of_zero():
    """-0.0 is held as 0.0: numpy's normal refused a scale_sd of -0.0 ('scale < 0')."""
    odometry = WalkOdometry(scale_sd=-0.0, noise=-0.0, scale_error=None)
    assert math.copysign(1.0, odometry.scale_sd) == 1.0
    assert math.copysign(1.0, odometry.noise) == 1.0
    xy = np.column_stack([np.linspace(0.0, 5.0, 20), np.zeros(20)])
    e, steps = walk_odometry(xy, odometry, 0)
    e_zero, steps_zero = walk_odometry(xy, WalkOdometry(scale_sd=0.0, noise=0.0), 0)
    assert e == e_zero == 0.0
    np.testing.assert_array_equal(steps, steps_zero)
