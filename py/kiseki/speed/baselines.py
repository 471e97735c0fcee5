# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Two baseline speed limiters to compare paper 004's occlusion- and width-aware limit with, on
the same runs. Both implement ``kiseki.control.SpeedLimitSource`` and pass their output through
``kiseki.speed.acceleration.AccelerationLimit``, the rate limiter the paper's limiter uses too.

``DistanceSpeedLimiter``: distance-only slowdown after paper 004's ref. [4] (J. Miura,
Y. Negishi and Y. Shirai, "Adaptive robot speed control by considering map and motion
uncertainty", J. RSJ 24(1) 47-55, 2006), which paper 004 describes only as setting the speed
from the distance to the unobserved region the robot moves towards, and then faults for looking
at the distance alone and not at how large the hidden region is. The rule kept here: with
d_hidden the distance from the robot's body to the nearest occluded region,

    v = v_max * min(1, d_hidden / d_stop),  d_stop = v_max * t_react + v_max^2 / (2 a_max)

d_stop is the distance the robot needs to stop from v_max: one scan period t_react = 0.1 s
(paper 004's LRF cycle, after which the next limit applies) at v_max, then braking at a_max.
The ramp is linear, not the kinematic sqrt(2 a_max d): a robot at this v stops within
d^2 / d_stop <= d, so it still stops before the region, and a ramp is what "a speed set from
the distance" says; the kinematic reading allows more speed at every d < d_stop. The occluded
region is exactly method 1's (eq. 1; ``kiseki.speed.occlusion_labels``): the prior map's free
cells within +-theta of the direction of motion and within the sensor's reach that the current
scan does not see. d_hidden = the distance from the body centre to the nearest such cell's
centre minus ``half_length`` (the body taken as a disc of 0.35 m, the 0.70 m robot), at least
0; no occluded cell: v_max. Paper 004's sentence on [4] also names obstacles the sensor
detects; those are left out on purpose: the navigator that drives every method (the Fuzzy
Potential Method) already slows for what it sees, so this baseline and method 1 differ only in
how they turn the occluded region into a speed (its distance here, its size in eq. 1).

``PolygonSpeedLimiter``: nav2's collision monitor (nav2_collision_monitor; parameters as in
docs.nav2.org "Using Collision Monitor" and the package README): polygons with ``action_type``
``stop`` and ``slowdown`` (with ``slowdown_ratio``) trigger when at least ``min_points`` sensor
points lie inside (nav2's default min_points is 4; Humble called it max_points = 3). Here both
are rectangles ahead of the robot in its direction of motion, covering the body
(+-half_length along, +-half_width across, 0.35 m each) plus ``stop_ahead`` = 0.3 m
(stop) or ``slowdown_ahead`` = 1.0 m (slowdown) in front of it; slowdown_ratio 0.5. The limit is
0 with >= min_points points in the stop box, slowdown_ratio * v_max with >= min_points in the
slowdown box, v_max otherwise. Differences from nav2: nav2 scales the commanded velocity
(slowdown) and its polygons are fixed to the base frame; here the output is a cap on the speed
(as paper 004's limit is) and the boxes turn with the direction of motion (the robot is
omnidirectional). Points on a box's edge count as inside.

Geometry shared by both: the laser sits ``sensor_offset`` metres ahead of the body centre along
its own x axis (the speed worlds mount it at 0.2 m; default 0), facing the body's front; the
heading (map frame) defaults to the sensor's. The polygon ignores scan returns at or beyond
``max_range`` and NaN ones; for the distance limiter they are what eq. 1 makes of them (a
no-return reading sees up to the range, a NaN one sees nothing).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from kiseki import _core
from kiseki._support.counts import check_count
from kiseki._support.field_types import check_field_types
from kiseki._support.real_numbers import check_number
from kiseki.control.speed_limit import SpeedLimit
from kiseki.grid import OccupancyGrid
from kiseki.speed.acceleration import AccelerationLimit, check_initial_speed, check_top_speed

__all__ = [
    "DistanceLimiterConfig",
    "DistanceSpeedLimiter",
    "PolygonLimiterConfig",
    "PolygonSpeedLimiter",
    "points_in_motion_frame",
]


def _check_config(config, numbers: tuple[tuple[str, str, bool], ...]) -> None:
    """v_max in (0, SPEED_LIMIT] m/s; each of ``numbers`` (name, unit, whether 0 is taken)
    finite and > 0 (>= 0 where 0 is taken), in its unit; initial_speed at most v_max. Named
    one by one: a test that each float field is among them keeps a new one from going
    unchecked. The counts are checked by the config."""
    kind = type(config).__name__
    check_top_speed(kind + ".v_max", config.v_max)
    for name, unit, zero in numbers:
        value = getattr(config, name)
        check_number(value, f"{kind}.{name}", 0.0, low_open=not zero, unit=unit)
    check_initial_speed(kind + ".initial_speed", config.initial_speed, config.v_max)


def points_in_motion_frame(sensor_pose, angles, ranges, max_range, heading, sensor_offset):
    """Scan returns as (x along the heading, y to its left) about the body centre (m)."""
    x, y, theta = (float(v) for v in np.asarray(sensor_pose, dtype=float).reshape(3))
    angles = np.asarray(angles, dtype=float).reshape(-1)
    ranges = np.asarray(ranges, dtype=float).reshape(-1)
    if angles.shape != ranges.shape:
        raise ValueError(f"{angles.size} angles but {ranges.size} ranges")
    check_number(max_range, "max_range", 0.0, low_open=True, unit="m")
    if not all(map(math.isfinite, (x, y, theta))):
        raise ValueError("the sensor pose must be finite")
    heading = theta if heading is None else check_number(heading, "heading")
    hit = np.isfinite(ranges) & (ranges < max_range)
    r, a = ranges[hit], angles[hit] + theta - heading
    dx = sensor_offset * math.cos(theta - heading)  # sensor relative to the centre, motion frame
    dy = sensor_offset * math.sin(theta - heading)
    return r * np.cos(a) + dx, r * np.sin(a) + dy


@dataclass(frozen=True)
class DistanceLimiterConfig:
    """``DistanceSpeedLimiter``'s parameters (m, m/s, m/s^2, s, rad); ``half_angle`` and
    ``free_threshold`` are method 1's (``SpeedLimiterConfig``), so both see one region."""

    v_max: float = 0.5
    a_max: float = 0.5
    reaction_time: float = 0.1  # s, one scan period of paper 004's LRF
    half_angle: float = math.pi / 2  # rad, theta of eq. 1
    half_length: float = 0.35  # m, the body's half size (the 0.70 m robot)
    free_threshold: int = 25  # map cells 0..25 are free, as for method 1
    sensor_offset: float = 0.0
    initial_speed: float = 0.0

    def __post_init__(self) -> None:
        check_field_types(self)
        _check_config(
            self,
            (
                ("a_max", "m/s^2", False),
                ("reaction_time", "s", True),
                ("half_angle", "rad", False),  # at most pi: below
                ("half_length", "m", True),
                ("sensor_offset", "m", True),
                ("initial_speed", "m/s", True),
            ),
        )
        if self.half_angle > math.pi:
            raise ValueError(
                f"DistanceLimiterConfig.half_angle must be <= pi, got {self.half_angle}"
            )
        check_count(self.free_threshold, "DistanceLimiterConfig.free_threshold", 0, 100)

    @property
    def stop_distance(self) -> float:
        """d_stop = v_max t_react + v_max^2 / (2 a_max) (m): 0.30 m at the defaults."""
        return self.v_max * self.reaction_time + self.v_max**2 / (2 * self.a_max)


class DistanceSpeedLimiter:
    """v = v_max min(1, d_hidden / d_stop): the distance to the nearest occluded region alone
    (module docstring). ``grid``: the prior map, as for ``SpeedLimiter``."""

    def __init__(self, grid: OccupancyGrid, config: DistanceLimiterConfig | None = None) -> None:
        if not isinstance(grid, OccupancyGrid):
            raise TypeError(
                "DistanceSpeedLimiter(grid, config) needs the prior map (a kiseki OccupancyGrid) "
                f"first, got {type(grid).__name__}"
            )
        self.grid = grid
        self.config = config if config is not None else DistanceLimiterConfig()
        self.rate = AccelerationLimit(self.config.a_max, self.config.initial_speed)

    def hidden_distance(self, sensor_pose, angles, ranges, max_range, heading=None) -> float:
        """d_hidden (m): from the body to the nearest occluded cell's centre, inf if none."""
        c = self.config
        x, y, theta = (float(v) for v in np.asarray(sensor_pose, dtype=float).reshape(3))
        _, _, _, labels = _core.occlusion_ratio(
            self.grid, (x, y, theta), angles, ranges, float(max_range), c.half_angle, heading,
            free_threshold=c.free_threshold, with_labels=True,
        )  # fmt: skip
        rows, cols = np.nonzero(labels == 1)  # 1: a free cell of eq. 1's region not seen
        if rows.size == 0:
            return math.inf
        centres = self.grid.cell_to_world(np.column_stack([cols, rows]))
        cx = x - c.sensor_offset * math.cos(theta)  # the body centre
        cy = y - c.sensor_offset * math.sin(theta)
        nearest = float(np.hypot(centres[:, 0] - cx, centres[:, 1] - cy).min())
        return max(0.0, nearest - c.half_length)

    def target(self, sensor_pose, angles, ranges, max_range, heading=None) -> float:
        """The limit (m/s) before the acceleration limit."""
        c = self.config
        d = self.hidden_distance(sensor_pose, angles, ranges, max_range, heading)
        return c.v_max * min(1.0, d / c.stop_distance)

    def update(self, sensor_pose, angles, ranges, max_range, dt, heading=None) -> SpeedLimit:
        value = self.rate.step(self.target(sensor_pose, angles, ranges, max_range, heading), dt)
        return SpeedLimit(max(0.0, value), False, self.config.v_max)


@dataclass(frozen=True)
class PolygonLimiterConfig:
    """``PolygonSpeedLimiter``'s parameters (m, m/s, m/s^2, a ratio, a count)."""

    v_max: float = 0.5
    a_max: float = 0.5
    half_length: float = 0.35
    half_width: float = 0.35
    stop_ahead: float = 0.3
    slowdown_ahead: float = 1.0
    slowdown_ratio: float = 0.5
    min_points: int = 4
    sensor_offset: float = 0.0
    initial_speed: float = 0.0

    def __post_init__(self) -> None:
        check_field_types(self)
        _check_config(
            self,
            (
                ("a_max", "m/s^2", False),
                ("half_length", "m", False),
                ("half_width", "m", False),
                ("stop_ahead", "m", True),
                ("slowdown_ahead", "m", False),
                ("sensor_offset", "m", True),
                ("initial_speed", "m/s", True),
            ),
        )
        name = "PolygonLimiterConfig.slowdown_ratio"
        check_number(self.slowdown_ratio, name, 0.0, 1.0, low_open=True)
        check_count(self.min_points, "PolygonLimiterConfig.min_points", 1)


class PolygonSpeedLimiter:
    """nav2 collision monitor style: a stop box and a slowdown box ahead of the robot."""

    def __init__(self, config: PolygonLimiterConfig | None = None) -> None:
        self.config = config if config is not None else PolygonLimiterConfig()
        self.rate = AccelerationLimit(self.config.a_max, self.config.initial_speed)

    def counts(self, sensor_pose, angles, ranges, max_range, heading=None) -> tuple[int, int]:
        """Numbers of scan points inside the stop box and inside the slowdown box."""
        c = self.config
        px, py = points_in_motion_frame(
            sensor_pose, angles, ranges, max_range, heading, c.sensor_offset
        )
        beside = (np.abs(py) <= c.half_width) & (px >= -c.half_length)
        n_stop = int(np.count_nonzero(beside & (px <= c.half_length + c.stop_ahead)))
        n_slow = int(np.count_nonzero(beside & (px <= c.half_length + c.slowdown_ahead)))
        return n_stop, n_slow

    def target(self, sensor_pose, angles, ranges, max_range, heading=None) -> float:
        """The limit (m/s) before the acceleration limit."""
        c = self.config
        n_stop, n_slow = self.counts(sensor_pose, angles, ranges, max_range, heading)
        if n_stop >= c.min_points:
            return 0.0
        return c.slowdown_ratio * c.v_max if n_slow >= c.min_points else c.v_max

    def update(self, sensor_pose, angles, ranges, max_range, dt, heading=None) -> SpeedLimit:
        value = self.rate.step(self.target(sensor_pose, angles, ranges, max_range, heading), dt)
        return SpeedLimit(max(0.0, value), False, self.config.v_max)
