# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The baseline speed limiters: hand-computed limits for walls at known distances, the rate
limit, and the polygon's point counts against a brute-force point-in-polygon test."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kiseki.control import SpeedLimitSource
from kiseki.speed import (
    AccelerationLimit,
    DistanceLimiterConfig,
    DistanceSpeedLimiter,
    PolygonLimiterConfig,
    PolygonSpeedLimiter,
)

MAX_RANGE = 4.0
ANGLES = np.linspace(-math.radians(120), math.radians(120), 683)
ORIGIN = (0.0, 0.0, 0.0)


def wall_ahead(d, angles=ANGLES):
    """Ranges to the infinite wall x = d (sensor frame)."""
    c = np.cos(angles)
    with np.errstate(divide="ignore"):
        r = np.where(c > 1e-9, d / c, np.inf)
    return np.minimum(r, MAX_RANGE)


def wall_left(d, angles=ANGLES):
    """Ranges to the infinite wall y = d (sensor frame)."""
    s = np.sin(angles)
    with np.errstate(divide="ignore"):
        r = np.where(s > 1e-9, d / s, np.inf)
    return np.minimum(r, MAX_RANGE)


def test_both_are_speed_limit_sources():
    assert isinstance(DistanceSpeedLimiter(), SpeedLimitSource)
    assert isinstance(PolygonSpeedLimiter(), SpeedLimitSource)


@pytest.mark.parametrize(
    ("d", "expected"),
    [
        (0.30, 0.0),  # inside the stop distance 0.35 + 0.1
        (0.449, 0.0),
        (0.55, math.sqrt(2 * 0.5 * 0.10)),  # 0.316 m/s
        (0.60, math.sqrt(2 * 0.5 * 0.15)),  # 0.387 m/s
        (0.70, 0.5),  # sqrt(0.25) = 0.5 exactly: the cap
        (2.00, 0.5),
    ],
)
def test_distance_limit_for_a_wall_ahead(d, expected):
    limiter = DistanceSpeedLimiter()
    assert limiter.target(ORIGIN, ANGLES, wall_ahead(d), MAX_RANGE) == pytest.approx(expected)


def test_distance_limit_measures_from_the_body_centre_and_looks_along_the_heading():
    # laser 0.2 m ahead of the centre: a wall 0.4 m ahead of it is 0.6 m from the centre
    offset = DistanceSpeedLimiter(DistanceLimiterConfig(sensor_offset=0.2))
    got = offset.target((1.0, 2.0, 0.3), ANGLES, wall_ahead(0.4), MAX_RANGE, heading=0.3)
    assert got == pytest.approx(math.sqrt(0.15))
    # a wall 0.6 m to the left: moving left (heading +90 deg) it is 0.6 m ahead; moving
    # forwards the nearest point within +-30 deg is at 0.6 / sin(30 deg) = 1.2 m -> v_max
    limiter = DistanceSpeedLimiter()
    ranges = wall_left(0.6)
    nearest = 0.6 / math.sin(ANGLES[np.argmin(np.abs(ANGLES - math.pi / 2))])  # no beam at 90
    assert limiter.target(ORIGIN, ANGLES, ranges, MAX_RANGE, heading=math.pi / 2) == (
        pytest.approx(math.sqrt(2 * 0.5 * (nearest - 0.45)), abs=1e-12)
    )
    assert limiter.target(ORIGIN, ANGLES, ranges, MAX_RANGE, heading=0.0) == 0.5
    # the sensor turned by 90 deg in the map: the same scan, heading +90 deg in the map = 0
    # relative to the sensor
    turned = limiter.target((0, 0, math.pi / 2), ANGLES, ranges, MAX_RANGE, heading=math.pi / 2)
    assert turned == 0.5


def test_acceleration_limit_moves_by_at_most_a_max_dt_both_ways():
    rate = AccelerationLimit(0.5)
    assert [round(rate.step(0.5, 0.1), 12) for _ in range(3)] == [0.05, 0.1, 0.15]
    assert rate.step(0.0, 0.1) == pytest.approx(0.10)
    assert rate.step(0.12, 1.0) == pytest.approx(0.12)  # reachable: lands on the target
    assert AccelerationLimit(0.5, initial=0.3).step(0.0, 0.2) == pytest.approx(0.2)
    with pytest.raises(ValueError, match="dt"):
        rate.step(0.1, -0.1)


def test_limiter_output_is_rate_limited_towards_the_hand_computed_limit():
    limiter = DistanceSpeedLimiter()
    near, far = wall_ahead(0.6), wall_ahead(3.0)
    out = [limiter.update(ORIGIN, ANGLES, near, MAX_RANGE, 0.1).speed_limit for _ in range(9)]
    expected = [min(0.05 * (k + 1), math.sqrt(0.15)) for k in range(9)]
    assert out == pytest.approx(expected)
    up = [limiter.update(ORIGIN, ANGLES, far, MAX_RANGE, 0.1).speed_limit for _ in range(4)]
    assert up == pytest.approx([min(0.5, math.sqrt(0.15) + 0.05 * (k + 1)) for k in range(4)])
    down = limiter.update(ORIGIN, ANGLES, wall_ahead(0.4), MAX_RANGE, 0.1)
    assert down.speed_limit == pytest.approx(0.5 - 0.05)  # brakes at a_max, not instantly
    assert down.percentage is False and down.max_speed == 0.5


@pytest.mark.parametrize(
    ("d", "expected"), [(0.6, 0.0), (0.64, 0.0), (1.0, 0.25), (1.34, 0.25), (1.5, 0.5)]
)
def test_polygon_limit_for_a_wall_ahead(d, expected):
    # stop box reaches 0.35 + 0.3 = 0.65 m ahead of the centre, slowdown box 1.35 m
    got = PolygonSpeedLimiter().target(ORIGIN, ANGLES, wall_ahead(d), MAX_RANGE)
    assert got == expected


def test_polygon_needs_min_points():
    # k points 0.5 m ahead (inside the stop box), nothing else
    angles = np.linspace(-0.1, 0.1, 9)
    for k, expected in [(3, 0.5), (4, 0.0)]:
        ranges = np.full(angles.shape, np.inf)
        ranges[:k] = 0.5
        assert PolygonSpeedLimiter().target(ORIGIN, angles, ranges, MAX_RANGE) == expected


def inside_polygon(px, py, poly):
    """Crossing-number test, one point and one edge at a time."""
    inside = False
    for i in range(len(poly)):
        (x0, y0), (x1, y1) = poly[i], poly[(i + 1) % len(poly)]
        if (y0 > py) != (y1 > py) and px < x0 + (py - y0) * (x1 - x0) / (y1 - y0):
            inside = not inside
    return inside


@pytest.mark.parametrize("seed", range(5))
def test_polygon_counts_match_a_brute_force_point_in_polygon(seed):
    rng = np.random.default_rng(seed)
    config = PolygonLimiterConfig(sensor_offset=0.2)
    pose = (rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-math.pi, math.pi))
    heading = pose[2] + rng.uniform(-math.pi, math.pi)
    angles = rng.uniform(-math.pi, math.pi, 400)
    ranges = rng.uniform(0.05, 2.5, 400)
    ranges[:20] = MAX_RANGE  # no return
    ranges[20:30] = np.nan
    got = PolygonSpeedLimiter(config).counts(pose, angles, ranges, MAX_RANGE, heading)

    cx = pose[0] - 0.2 * math.cos(pose[2])  # body centre in the map
    cy = pose[1] - 0.2 * math.sin(pose[2])
    ch, sh = math.cos(heading), math.sin(heading)

    def box(front):
        corners = [(-0.35, -0.35), (front, -0.35), (front, 0.35), (-0.35, 0.35)]
        return [(cx + ch * u - sh * v, cy + sh * u + ch * v) for u, v in corners]

    stop, slow = box(0.65), box(1.35)
    expected = [0, 0]
    for a, r in zip(angles, ranges, strict=True):
        if not r < MAX_RANGE:
            continue
        px, py = pose[0] + r * math.cos(pose[2] + a), pose[1] + r * math.sin(pose[2] + a)
        expected[0] += inside_polygon(px, py, stop)
        expected[1] += inside_polygon(px, py, slow)
    assert got == tuple(expected)
    assert got[1] > 0  # the draw put points in the boxes


@pytest.mark.parametrize(
    ("cls", "field", "value"),
    [
        (DistanceLimiterConfig, "a_max", 0.0),
        (DistanceLimiterConfig, "half_angle", math.nan),
        (PolygonLimiterConfig, "slowdown_ratio", 1.5),
        (PolygonLimiterConfig, "min_points", 0),
        (PolygonLimiterConfig, "stop_ahead", -0.1),
    ],
)
def test_bad_config_names_the_field(cls, field, value):
    with pytest.raises(ValueError, match=f"{cls.__name__}.{field}"):
        cls(**{field: value})
