# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The baseline speed limiters: the distance-only limit against its closed form for occluded
regions at known distances, the rate limit, and the polygon's hand-computed limits and point
counts against a brute-force point-in-polygon test."""

from __future__ import annotations

import dataclasses
import math
import typing

import numpy as np
import pytest

from kiseki.control import SpeedLimitSource
from kiseki.core import Pose2
from kiseki.grid import FREE, OccupancyGrid
from kiseki.speed import (
    AccelerationLimit,
    DistanceLimiterConfig,
    DistanceSpeedLimiter,
    PolygonLimiterConfig,
    PolygonSpeedLimiter,
    SpeedLimiterConfig,
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


def free_map() -> OccupancyGrid:
    """A free 10 m x 10 m prior map, 0.05 m cells, cell edges at multiples of 0.05 m."""
    return OccupancyGrid(200, 200, 0.05, Pose2(-5.0, -5.0, 0.0), FREE)


FACING_Y = (0.0, 0.0, math.pi / 2)  # the sensor at the origin looking along +y of the map
D_STOP = 0.5 * 0.1 + 0.5**2 / (2 * 0.5)  # v_max t_react + v_max^2 / (2 a_max) = 0.30 m


def nearest_hidden_behind(face):
    """Distance from the sensor to the nearest cell centre an unknown wall across the heading,
    its face ``face`` metres ahead (just past a cell edge), hides: the cell holding the face
    has its centre beyond the beams' ends (not seen), the one before it is passed more than
    half a cell before them (seen); the centres nearest the axis sit 0.025 m off it."""
    centre = math.floor(face / 0.05) * 0.05 + 0.025
    return math.hypot(0.025, centre)


def test_both_are_speed_limit_sources():
    assert isinstance(DistanceSpeedLimiter(free_map()), SpeedLimitSource)
    assert isinstance(PolygonSpeedLimiter(), SpeedLimitSource)


def test_polygon_limiter_ramps_to_its_boxes_limits_at_a_max():
    # Defaults: robot boxes 0.35 m half length; stop box to 0.35 + 0.3 m ahead, slowdown box to
    # 0.35 + 1.0 m (half the 0.5 m/s there), 4 points needed, a_max 0.5 m/s^2: 0.05 m/s a step of
    # 0.1 s. A wall 1.0 m ahead is in the slowdown box only; one 0.5 m ahead is in the stop box.
    limiter = PolygonSpeedLimiter()
    slow, stop = wall_ahead(1.0), wall_ahead(0.5)
    assert limiter.target(ORIGIN, ANGLES, slow, MAX_RANGE) == 0.25
    assert limiter.target(ORIGIN, ANGLES, stop, MAX_RANGE) == 0.0
    assert limiter.target(ORIGIN, ANGLES, np.full(ANGLES.shape, MAX_RANGE), MAX_RANGE) == 0.5
    up = [limiter.update(ORIGIN, ANGLES, slow, MAX_RANGE, 0.1) for _ in range(7)]
    np.testing.assert_allclose(
        [u.speed_limit for u in up], [0.05, 0.10, 0.15, 0.20, 0.25, 0.25, 0.25], atol=1e-12
    )
    down = [limiter.update(ORIGIN, ANGLES, stop, MAX_RANGE, 0.1).speed_limit for _ in range(6)]
    np.testing.assert_allclose(down, [0.20, 0.15, 0.10, 0.05, 0.0, 0.0], atol=1e-12)


def test_distance_limit_without_an_occluded_region_is_v_max():
    # a free field seen to the sensor's reach: nothing within 4 m - 0.35 m is occluded; an empty
    # map has no free cell at all
    limiter = DistanceSpeedLimiter(free_map())
    open_scan = np.full(ANGLES.shape, MAX_RANGE)
    assert limiter.hidden_distance(FACING_Y, ANGLES, open_scan, MAX_RANGE) > 3.5
    assert limiter.target(FACING_Y, ANGLES, open_scan, MAX_RANGE) == 0.5
    unknown = OccupancyGrid(200, 200, 0.05, Pose2(-5.0, -5.0, 0.0), -1)
    limiter = DistanceSpeedLimiter(unknown)
    assert limiter.hidden_distance(FACING_Y, ANGLES, open_scan, MAX_RANGE) == math.inf
    assert limiter.target(FACING_Y, ANGLES, open_scan, MAX_RANGE) == 0.5
    assert DistanceLimiterConfig().stop_distance == pytest.approx(D_STOP)


def test_distance_limit_at_half_the_stop_distance_is_half_v_max():
    # an unknown wall (not on the map) 0.455 m ahead hides the map's free space behind it;
    # with the body's half size set so that the region is d_stop / 2 from the body: v_max / 2
    hidden = nearest_hidden_behind(0.455)
    config = DistanceLimiterConfig(half_length=hidden - D_STOP / 2)
    limiter = DistanceSpeedLimiter(free_map(), config)
    ranges = wall_ahead(0.455)
    assert limiter.hidden_distance(FACING_Y, ANGLES, ranges, MAX_RANGE) == pytest.approx(
        D_STOP / 2, abs=1e-9
    )
    assert limiter.target(FACING_Y, ANGLES, ranges, MAX_RANGE) == pytest.approx(0.25, abs=1e-9)


@pytest.mark.parametrize("face", [0.305, 0.355, 0.405, 0.505, 0.605, 0.655, 0.905, 2.005])
def test_distance_limit_follows_the_ramp_to_v_max(face):
    # v = v_max min(1, d_hidden / d_stop), d_hidden = nearest hidden centre - 0.35 m (>= 0)
    limiter = DistanceSpeedLimiter(free_map())
    d = max(0.0, nearest_hidden_behind(face) - 0.35)
    got = limiter.target(FACING_Y, ANGLES, wall_ahead(face), MAX_RANGE)
    assert got == pytest.approx(0.5 * min(1.0, d / D_STOP), abs=1e-9)


def test_distance_limit_slows_for_a_region_hidden_to_the_side():
    # an unknown pillar 0.45 m away at 60 deg to the left of the heading (outside +-30 deg)
    # hides the free cells behind it: a cell is unseen when its centre lies less than half a
    # cell before the beam's end, so the nearest lies 0.45 - 0.025 to 0.45 + 0.035 (half a
    # cell's diagonal) m from the sensor, 0.075-0.135 m from the body, well under d_stop. A
    # limiter that reads only the scan's points within +-30 deg of the heading sees nothing
    # ahead and allows v_max.
    bearing, distance = math.radians(60), 0.45
    ranges = np.full(ANGLES.shape, MAX_RANGE)
    ranges[np.abs(ANGLES - bearing) <= math.radians(6)] = distance
    limiter = DistanceSpeedLimiter(free_map())
    d = limiter.hidden_distance(FACING_Y, ANGLES, ranges, MAX_RANGE)
    assert 0.45 - 0.025 - 0.35 <= d <= 0.45 + 0.0354 - 0.35
    assert limiter.target(FACING_Y, ANGLES, ranges, MAX_RANGE) == pytest.approx(
        0.5 * d / D_STOP, abs=1e-9
    )
    assert limiter.target(FACING_Y, ANGLES, ranges, MAX_RANGE) < 0.5 / 2


def test_distance_limit_measures_from_the_body_centre_in_the_direction_of_motion():
    # laser 0.2 m ahead of the centre: the wall's hidden cells are 0.2 m farther from the body
    face = 0.305
    on_axis = math.floor(face / 0.05) * 0.05 + 0.025
    offset = DistanceSpeedLimiter(free_map(), DistanceLimiterConfig(sensor_offset=0.2))
    d = offset.hidden_distance(FACING_Y, ANGLES, wall_ahead(face), MAX_RANGE)
    assert d == pytest.approx(math.hypot(0.025, on_axis + 0.2) - 0.35, abs=1e-9)
    # moving backwards (heading -y): eq. 1's region is the half disc behind the sensor, which
    # the +-120 deg laser sees only in two 30 deg wedges: the hidden cells beside the sensor
    # then lie within 0.35 m of the body centre -> stop
    limiter = DistanceSpeedLimiter(free_map())
    back = limiter.target(FACING_Y, ANGLES, wall_ahead(2.0), MAX_RANGE, heading=-math.pi / 2)
    assert back == 0.0


def test_distance_limiter_needs_the_map():
    with pytest.raises(TypeError, match="prior map"):
        DistanceSpeedLimiter(DistanceLimiterConfig())


def test_acceleration_limit_moves_by_at_most_a_max_dt_both_ways():
    rate = AccelerationLimit(0.5)
    assert [round(rate.step(0.5, 0.1), 12) for _ in range(3)] == [0.05, 0.1, 0.15]
    assert rate.step(0.0, 0.1) == pytest.approx(0.10)
    assert rate.step(0.12, 1.0) == pytest.approx(0.12)  # reachable: lands on the target
    assert AccelerationLimit(0.5, initial=0.3).step(0.0, 0.2) == pytest.approx(0.2)
    with pytest.raises(ValueError, match="dt"):
        rate.step(0.1, -0.1)


def test_limiter_output_is_rate_limited_towards_the_closed_form_limit():
    limiter = DistanceSpeedLimiter(free_map())
    near, far = wall_ahead(0.505), wall_ahead(3.0)
    v_near = 0.5 * (nearest_hidden_behind(0.505) - 0.35) / D_STOP
    out = [limiter.update(FACING_Y, ANGLES, near, MAX_RANGE, 0.1).speed_limit for _ in range(9)]
    assert out == pytest.approx([min(0.05 * (k + 1), v_near) for k in range(9)])
    up = [limiter.update(FACING_Y, ANGLES, far, MAX_RANGE, 0.1).speed_limit for _ in range(4)]
    assert up == pytest.approx([min(0.5, v_near + 0.05 * (k + 1)) for k in range(4)])
    down = limiter.update(FACING_Y, ANGLES, wall_ahead(0.305), MAX_RANGE, 0.1)
    assert down.speed_limit == pytest.approx(up[-1] - 0.05)  # brakes at a_max, not at once
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
        (DistanceLimiterConfig, "reaction_time", -0.1),
        (PolygonLimiterConfig, "slowdown_ratio", 1.5),
        (PolygonLimiterConfig, "min_points", 0),
        (PolygonLimiterConfig, "stop_ahead", -0.1),
        # a starting speed above v_max made the first limits exceed the robot's maximum
        (DistanceLimiterConfig, "initial_speed", 5.0),
        (PolygonLimiterConfig, "initial_speed", 0.51),
        (PolygonLimiterConfig, "a_max", True),
    ],
)
def test_bad_config_names_the_field(cls, field, value):
    with pytest.raises(ValueError, match=f"{cls.__name__}.{field}"):
        cls(**{field: value})


@pytest.mark.parametrize(
    ("cls", "field", "value", "rule"),
    [
        (DistanceLimiterConfig, "a_max", 0.0, "a finite number > 0 m/s^2"),
        (DistanceLimiterConfig, "reaction_time", -0.1, "a finite number >= 0 s"),
        (DistanceLimiterConfig, "free_threshold", -1, "an integer in 0..100"),
        (PolygonLimiterConfig, "slowdown_ratio", 1.5, "a finite number in (0, 1]"),
        (PolygonLimiterConfig, "min_points", 0, "an integer >= 1"),
        (PolygonLimiterConfig, "half_width", math.inf, "a finite number > 0 m"),
    ],
)
def test_a_bad_config_number_is_worded_as_one_rule(cls, field, value, rule):
    with pytest.raises(ValueError) as e:
        cls(**{field: value})
    assert str(e.value) == f"{cls.__name__}.{field} must be {rule}, got {value!r}"


# each float field's rule for NaN, in its unit (v_max's is the top speed's)
NAN_RULES = {
    DistanceLimiterConfig: {
        "v_max": "a finite number in (0, 10] m/s",
        "a_max": "a finite number > 0 m/s^2",
        "reaction_time": "a finite number >= 0 s",
        "half_angle": "a finite number > 0 rad",
        "half_length": "a finite number >= 0 m",
        "sensor_offset": "a finite number >= 0 m",
        "initial_speed": "a finite number >= 0 m/s",
    },
    PolygonLimiterConfig: {
        "v_max": "a finite number in (0, 10] m/s",
        "a_max": "a finite number > 0 m/s^2",
        "half_length": "a finite number > 0 m",
        "half_width": "a finite number > 0 m",
        "stop_ahead": "a finite number >= 0 m",
        "slowdown_ahead": "a finite number > 0 m",
        "slowdown_ratio": "a finite number in (0, 1]",
        "sensor_offset": "a finite number >= 0 m",
        "initial_speed": "a finite number >= 0 m/s",
    },
}


@pytest.mark.parametrize("cls", list(NAN_RULES))
def test_every_float_field_of_a_baseline_config_is_checked_in_its_unit(cls):
    """The numbers were chosen by their annotation's text (f.type == "float"), which skips
    every field once the module loses its postponed annotations or a field reads
    ``float | None``, and their messages gave no unit; each float field is found here from
    its type, so one the check leaves out lets NaN through and fails."""
    hints = typing.get_type_hints(cls)
    floats = [
        f.name
        for f in dataclasses.fields(cls)
        if float in (hints[f.name], *typing.get_args(hints[f.name]))
    ]
    assert floats == list(NAN_RULES[cls])
    for name in floats:
        with pytest.raises(ValueError) as e:
            cls(**{name: math.nan})
        assert str(e.value) == f"{cls.__name__}.{name} must be {NAN_RULES[cls][name]}, got nan"


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: AccelerationLimit(0.0), "a_max must be a finite number > 0 m/s^2, got 0.0"),
        (lambda: AccelerationLimit(True), "a_max must be a finite number > 0 m/s^2, got True"),
        (lambda: AccelerationLimit(0.5, math.nan), "initial must be a finite number, got nan"),
        (
            lambda: AccelerationLimit(0.5).step(0.1, -0.1),
            "dt must be a finite number >= 0 s, got -0.1",
        ),
        (
            lambda: AccelerationLimit(0.5).step(0.1, True),
            "dt must be a finite number >= 0 s, got True",
        ),
        (
            lambda: AccelerationLimit(0.5).step(True, 0.1),
            "target must be a finite number, got True",
        ),
    ],
)
def test_the_acceleration_limit_refuses_a_bad_number(call, message):
    """True was a rate of 1 m/s^2, a step of 1 s or a target of 1 m/s."""
    with pytest.raises(ValueError) as e:
        call()
    assert str(e.value) == message


@pytest.mark.parametrize(
    ("max_range", "heading", "message"),
    [
        (0.0, None, "max_range must be a finite number > 0 m, got 0.0"),
        (True, None, "max_range must be a finite number > 0 m, got True"),  # was 1 m
        (MAX_RANGE, math.nan, "heading must be a finite number, got nan"),
        (MAX_RANGE, "0.5", "heading must be a finite number, got '0.5'"),  # was 0.5 rad
    ],
)
def test_the_polygon_refuses_a_bad_range_or_heading(max_range, heading, message):
    with pytest.raises(ValueError) as e:
        PolygonSpeedLimiter().counts(FACING_Y, ANGLES, wall_ahead(2.0), max_range, heading)
    assert str(e.value) == message


def test_no_limiter_starts_above_the_robots_maximum_speed():
    """SpeedLimiter(grid, initial=5.0) gave 4.95 m/s on a 0.5 m/s robot (the limit falls from
    the starting speed at a_max); a start at v_max is the most it takes."""
    from kiseki.speed import SpeedLimiter, SpeedLimiterConfig

    grid = OccupancyGrid(40, 40, 0.1, Pose2(0.0, 0.0, 0.0), FREE)
    for initial in (5.0, 0.5000001, -0.1, math.nan, True, "0.3"):
        with pytest.raises(ValueError, match="initial must be a speed in \\[0, v_max = 0.5\\]"):
            SpeedLimiter(grid, initial=initial)
    limiter = SpeedLimiter(grid, SpeedLimiterConfig(), initial=0.5)
    limit = limiter.update((2.0, 2.0, 0.0), ANGLES, wall_ahead(MAX_RANGE), MAX_RANGE, 0.1)
    assert limit.speed_limit <= 0.5


@pytest.mark.parametrize(
    "config", [SpeedLimiterConfig, DistanceLimiterConfig, PolygonLimiterConfig]
)
def test_a_top_speed_past_the_limit_is_refused_in_the_config(config):
    """v_max = 1e200 m/s was taken, and the distance-only baseline's stopping distance then
    raised OverflowError (v_max^2); the limit is the command line's --v-max bound, 10 m/s."""
    assert config(v_max=10.0).v_max == 10.0
    for bad in (10.000001, 1e200):
        with pytest.raises(
            ValueError,
            match=rf"^{config.__name__}\.v_max must be a finite number in \(0, 10\] m/s, got",
        ):
            config(v_max=bad)
