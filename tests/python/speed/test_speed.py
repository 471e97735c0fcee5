# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Paper 004's speed limit: eq. 1's ratio against a numpy count of the same definition and
closed forms, eq. 3 at w1, b and w2, the combined limit and its acceleration limit, bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

from _helpers.speed_reference import reference_ratio
from kiseki.control import SpeedLimit, SpeedLimitSource
from kiseki.core import Pose2
from kiseki.grid import FREE, OCCUPIED, OccupancyGrid
from kiseki.speed import (
    SpeedLimiter,
    SpeedLimiterConfig,
    occlusion_labels,
    occlusion_ratio,
    passage_width,
    width_factor,
)

ANGLES = np.linspace(-2 * math.pi / 3, 2 * math.pi / 3, 683)  # the paper's LRF: +-120 deg
ONES = np.ones_like(ANGLES)
MAX_RANGE = 4.0


def _field(fill=FREE) -> OccupancyGrid:
    return OccupancyGrid(200, 200, 0.05, Pose2(-5.0, -5.0, 0.0), fill)


def _scan(world: OccupancyGrid, pose) -> np.ndarray:
    return world.cast_scans(np.array([pose]), ANGLES, max_range=MAX_RANGE)[0]


def test_open_field_gives_one():
    grid = _field()
    pose = (0.0, 0.0, math.pi / 2)
    assert occlusion_ratio(grid, pose, ANGLES, _scan(grid, pose), MAX_RANGE, math.pi / 2) == 1.0


@pytest.mark.parametrize("d", [0.5, 1.5, 2.5, 3.5])
def test_known_wall_ahead_gives_the_area_in_front_of_it(d):
    grid = _field()
    row = round((d + 5.0) / 0.05)  # the wall's near face d ahead of the sensor
    grid.cells[row, :] = OCCUPIED
    pose = (0.0, 0.0, math.pi / 2)
    # the half disc's part nearer than d: int_0^d 2 sqrt(R^2 - y^2) dy over pi R^2 / 2
    r = MAX_RANGE
    expected = (d * math.sqrt(r * r - d * d) + r * r * math.asin(d / r)) / (math.pi * r * r / 2)
    got = occlusion_ratio(grid, pose, ANGLES, _scan(grid, pose), MAX_RANGE, math.pi / 2)
    assert got == pytest.approx(expected, abs=0.02)


@pytest.mark.parametrize("seed", range(6))
def test_ratio_matches_a_numpy_count_of_the_definition(seed):
    rng = np.random.default_rng(seed)
    prior = _field()
    prior.cells[rng.random(prior.cells.shape) < 0.02] = OCCUPIED  # posts the map knows
    prior.cells[rng.random(prior.cells.shape) < 0.01] = -1  # and unknown cells
    world = OccupancyGrid(prior.cells.copy(), 0.05, prior.origin)
    for _ in range(5):  # boxes the map does not know
        x, y = rng.integers(20, 180, 2)
        world.cells[y : y + 8, x : x + 8] = OCCUPIED
    pose = (*rng.uniform(-1, 1, 2), rng.uniform(-math.pi, math.pi))
    ranges = _scan(world, pose).astype(np.float32)
    ranges[rng.random(ranges.size) < 0.05] = np.nan
    half, heading = rng.uniform(0.3, math.pi), pose[2] + rng.uniform(-1.5, 1.5)
    got = occlusion_ratio(prior, pose, ANGLES, ranges, MAX_RANGE, half, heading)
    want = reference_ratio(prior, pose, ANGLES, ranges, MAX_RANGE, half, heading)
    assert got == pytest.approx(want, abs=2e-3)  # cells on the sector's edge may round apart


def test_labels_mark_the_occluded_cells_behind_a_box():
    prior = _field()
    world = OccupancyGrid(prior.cells.copy(), 0.05, prior.origin)
    world.cells[130:146, 96:104] = OCCUPIED  # 0.4 x 0.8 m, 1.5 m ahead, not in the map
    pose = (0.0, 0.0, math.pi / 2)
    ranges = _scan(world, pose)
    ratio, labels = occlusion_labels(prior, pose, ANGLES, ranges, MAX_RANGE, math.pi / 2)
    assert ratio == occlusion_ratio(prior, pose, ANGLES, ranges, MAX_RANGE, math.pi / 2)
    assert ratio == pytest.approx((labels == 2).sum() / (labels > 0).sum())
    assert (labels[150:170, 98:102] == 1).all()  # the box's shadow
    assert (labels[110:125, 90:110] == 2).all()  # in front of it
    assert (labels[:95] == 0).all()  # behind the sensor


def test_unknown_obstacle_and_nan_readings_shrink_the_ratio():
    prior = _field()
    world = OccupancyGrid(prior.cells.copy(), 0.05, prior.origin)
    world.cells[130:146, 96:104] = OCCUPIED  # 0.4 x 0.8 m, 1.5 m ahead, not in the map
    pose = (0.0, 0.0, math.pi / 2)
    ranges = _scan(world, pose)
    with_box = occlusion_ratio(prior, pose, ANGLES, ranges, MAX_RANGE, math.pi / 2)
    assert 0.85 < with_box < 0.97
    blind = ranges.copy()
    blind[ANGLES > 0] = np.nan  # the left half says nothing
    assert occlusion_ratio(prior, pose, ANGLES, blind, MAX_RANGE, math.pi / 2) == pytest.approx(
        with_box / 2, abs=0.03
    )


def test_width_factor_at_w1_b_and_w2():
    w1, w2, a = 0.70, 2.0, 4.9
    assert width_factor(w2 - w1, w1, w2, a) == pytest.approx(0.5, abs=1e-15)
    assert width_factor(w1, w1, w2, a) == pytest.approx(1 / (1 + math.exp(4.9 * 0.6)))
    assert width_factor(w2, w1, w2, a) == pytest.approx(1 / (1 + math.exp(-4.9 * 0.7)))
    np.testing.assert_allclose(
        width_factor(np.array([0.7, 1.3, 2.0])), [0.0502113, 0.5, 0.9686291], atol=1e-7
    )


def test_passage_width_of_a_corridor():
    # walls at y = +-0.75 m of a sensor looking along +x: w = 1.5 m
    s = np.sin(ANGLES)
    with np.errstate(divide="ignore"):
        ranges = np.minimum(MAX_RANGE, np.where(s != 0, 0.75 / np.abs(s), np.inf))
    assert passage_width(ANGLES, ranges, MAX_RANGE) == pytest.approx(1.5, abs=1e-6)  # float32


def _corridor(left, right, ahead):
    """Exact ranges of a sensor looking along +x between walls y = +left and y = -right, with
    an end wall x = ahead across the corridor (none when ahead is inf)."""
    s, c = np.sin(ANGLES), np.cos(ANGLES)
    with np.errstate(divide="ignore"):
        r = np.minimum.reduce(
            [
                np.where(s > 1e-9, left / s, np.inf),
                np.where(s < -1e-9, -right / s, np.inf),
                np.where(c > 1e-9, ahead / c, np.inf),
            ]
        )
    return np.minimum(MAX_RANGE, r)


@pytest.mark.parametrize("width", [2.3, 1.5])
@pytest.mark.parametrize("offset", [0.0, 0.25])
@pytest.mark.parametrize("ahead", [0.9, 0.4, 2.0, math.inf])
def test_passage_width_is_measured_across_the_heading(width, offset, ahead):
    # eq. 2 (Fig. 3a): w = W in a straight corridor of width W whatever wall lies ahead; the
    # 2.3 m corridor with a wall 0.9 m ahead gives 2.3 m (a wall straight ahead counted as a
    # side gave 0.006 m, f(w) = 0.0018); the limiter's v_ref carries f(W)
    ranges = _corridor(width / 2 + offset, width / 2 - offset, ahead)
    assert passage_width(ANGLES, ranges, MAX_RANGE) == pytest.approx(width, abs=1e-5)
    ref = SpeedLimiter(_field(), SpeedLimiterConfig(use_occlusion=False)).reference(
        (0.0, 0.0, 0.0), ANGLES, ranges, MAX_RANGE
    )
    assert ref["width"] == pytest.approx(width, abs=1e-5)
    assert ref["v_ref"] == pytest.approx(0.5 / (1 + math.exp(-4.9 * (width - 1.3))), abs=1e-5)


def test_limiter_combines_the_terms_and_limits_acceleration():
    grid = _field()
    grid.cells[round((2.0 + 5.0) / 0.05), :] = OCCUPIED
    pose = (0.0, 0.0, math.pi / 2)
    ranges = _scan(grid, pose)
    limiter = SpeedLimiter(grid, SpeedLimiterConfig())
    assert isinstance(limiter, SpeedLimitSource)
    ref = limiter.reference(pose, ANGLES, ranges, MAX_RANGE)
    ratio = occlusion_ratio(grid, pose, ANGLES, ranges, MAX_RANGE, math.pi / 2)
    w = passage_width(ANGLES, ranges, MAX_RANGE, 0.0)
    assert ref["v_ref"] == pytest.approx(0.5 * ratio * width_factor(w))
    limits = [limiter.update(pose, ANGLES, ranges, MAX_RANGE, 0.1).speed_limit for _ in range(10)]
    # from rest, 0.05 m/s per 0.1 s step until v_ref
    np.testing.assert_allclose(limits, np.minimum(0.05 * np.arange(1, 11), ref["v_ref"]))
    msg = limiter.update(pose, ANGLES, ranges, MAX_RANGE, 0.1)
    assert isinstance(msg, SpeedLimit) and not msg.percentage
    assert msg.to_message() == {
        "percentage": False,
        "speed_limit": msg.speed_limit,
        "max_speed": 0.5,
        "stop": False,
    }
    assert (
        SpeedLimit(0.0).to_message()["stop"]
        and not SpeedLimit(0.0, True).as_percentage().to_message()["speed_limit"]
    )
    # 'no' was read as a percentage (truthy): 50 "percent" became 0.25 m/s
    for bad in ({"percentage": "no"}, {"speed_limit": True}, {"max_speed": "0.5"}):
        with pytest.raises(ValueError, match="must be"):
            SpeedLimit(**{"speed_limit": 50, **bad})
    only_width = SpeedLimiter(grid, SpeedLimiterConfig(use_occlusion=False))
    assert only_width.reference(pose, ANGLES, ranges, MAX_RANGE)["v_ref"] == pytest.approx(
        0.5 * width_factor(w)
    )


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda g: occlusion_ratio(g, (0, 0, 0), [], [], 4.0, 1.0), "empty"),
        (lambda g: occlusion_ratio(g, (0, 0, 0), ANGLES, ANGLES[:5], 4.0, 1.0), "differ"),
        (lambda g: occlusion_ratio(g, (0, 0, 0), ANGLES, ONES, 4.0, 0.0), "half_angle"),
        (lambda g: occlusion_ratio(g, (0, 0, 0), ANGLES, ONES, 4.0, 3.2), "half_angle"),
        (lambda g: occlusion_ratio(g, (0, 0, 0), ANGLES, ONES, -1.0, 1.0), "max_range"),
        (lambda g: occlusion_ratio(g, (0, 0), ANGLES, ONES, 4.0, 1.0), "pose"),
        (lambda g: occlusion_ratio(g, (0, 0, 0), ANGLES[::-1], ONES, 4.0, 1.0), "increase"),
        (lambda g: width_factor(1.0, 2.0, 2.0, 4.9), "w2 must exceed w1"),
        (lambda g: width_factor(1.0, 0.7, 0.5, 4.9), "w2 must exceed w1"),
        (lambda g: width_factor(1.0, 0.7, 2.0, -1.0), "a must be positive"),
        (lambda g: SpeedLimiterConfig(w1=2.0, w2=1.0), "w2"),
        (lambda g: SpeedLimiterConfig(half_angle=0.0), "half_angle"),
        (lambda g: SpeedLimiter(g).update((0, 0, 0), ANGLES, ONES, 4.0, -0.1), "dt"),
        (lambda g: SpeedLimiter("map.yaml"), "OccupancyGrid"),
    ],
)
def test_bad_input_is_refused_by_name(call, match):
    with pytest.raises((ValueError, TypeError), match=match):
        call(_field())


@pytest.mark.parametrize(
    ("field", "value", "message"),
    [
        ("a_max", 0.0, "SpeedLimiterConfig.a_max must be a finite number > 0 m/s^2, got 0.0"),
        ("w1", math.nan, "SpeedLimiterConfig.w1 must be a finite number > 0 m, got nan"),
        ("a", -4.9, "SpeedLimiterConfig.a must be a finite number > 0 1/m, got -4.9"),
        ("v_max", 0.0, "SpeedLimiterConfig.v_max must be a finite number in (0, 10] m/s, got 0.0"),
    ],
)
def test_a_bad_limiter_number_is_worded_as_one_rule(field, value, message):
    with pytest.raises(ValueError) as e:
        SpeedLimiterConfig(**{field: value})
    assert str(e.value) == message


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"speed_limit": -0.1}, "speed_limit must be a finite number >= 0 m/s, got -0.1"),
        (
            {"speed_limit": 150, "percentage": True},
            "speed_limit must be a finite number in [0, 100] %, got 150",
        ),
        ({"speed_limit": math.inf}, "speed_limit must be a finite number >= 0 m/s, got inf"),
        (
            {"speed_limit": 0.2, "max_speed": 0.0},
            "max_speed must be a finite number > 0 m/s, got 0.0",
        ),
        (
            {"speed_limit": 0.2, "max_speed": "0.5"},
            "max_speed must be a finite number > 0 m/s, got '0.5'",
        ),
    ],
)
def test_a_bad_speed_limit_is_worded_as_one_rule(kwargs, message):
    with pytest.raises(ValueError) as e:
        SpeedLimit(**kwargs)
    assert str(e.value) == message
