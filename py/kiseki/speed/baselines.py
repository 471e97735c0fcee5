# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Two baseline speed limiters to compare paper 004's occlusion- and width-aware limit with, on
the same runs. Both implement ``kiseki.control.SpeedLimitSource`` and pass their output through
``AccelerationLimit``, the rate limiter the paper's limiter reuses.

``AccelerationLimit``: the output moves towards the wanted limit by at most a_max * dt per
update, up and down alike (the robot can neither speed up nor brake faster than a_max), starting
from ``initial`` (0 m/s by default: the robot starts at rest).

``DistanceSpeedLimiter``: distance-only slowdown, in the spirit of J. Miura, Y. Negishi and
Y. Shirai, "Adaptive robot speed control by considering map and motion uncertainty" (J. RSJ
24(1) 47-55, 2006; paper 004's ref. [4]): the robot may go as fast as it can still stop, braking
at a_brake, before the nearest obstacle ahead. With d the distance from the robot's centre to
the nearest scan point within +-``half_angle`` of the heading,

    v = min(v_max, sqrt(2 a_brake max(0, d - d_stop))),  d_stop = half_length + stop_margin

a_brake = a_max (0.5 m/s^2), half_length 0.35 m (the 0.70 m robot), stop_margin 0.1 m: the
robot stops 0.1 m before its front would touch. No point ahead: v_max. (Miura et al. plan on a
map with uncertainty; only their distance-to-stop rule is kept here.)

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
its own x axis (the speed worlds mount it at 0.2 m; default 0), facing the body's front; scan
returns at or beyond ``max_range`` and NaN are ignored; the heading (map frame) defaults to the
sensor's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from kiseki.control.speed_limit import SpeedLimit

__all__ = [
    "AccelerationLimit",
    "DistanceLimiterConfig",
    "DistanceSpeedLimiter",
    "PolygonLimiterConfig",
    "PolygonSpeedLimiter",
    "points_in_motion_frame",
]


class AccelerationLimit:
    """Rate limiter: each ``step`` moves ``value`` towards ``target`` by at most a_max * dt."""

    def __init__(self, a_max: float, initial: float = 0.0) -> None:
        if not (math.isfinite(a_max) and a_max > 0):
            raise ValueError(f"a_max must be positive, got {a_max!r}")
        if not math.isfinite(initial):
            raise ValueError(f"initial must be finite, got {initial!r}")
        self.a_max, self.value = float(a_max), float(initial)

    def step(self, target: float, dt: float) -> float:
        """The new value after ``dt`` seconds of moving towards ``target`` (m/s)."""
        if not (math.isfinite(dt) and dt >= 0):
            raise ValueError(f"dt must be a finite number >= 0, got {dt!r}")
        if not math.isfinite(target):
            raise ValueError(f"target must be finite, got {target!r}")
        reach = self.a_max * dt
        self.value += min(reach, max(-reach, target - self.value))
        return self.value


def _check_config(config, non_negative=()) -> None:
    for f in fields(config):
        value = getattr(config, f.name)
        low_ok = value >= 0 if f.name in non_negative else value > 0
        if not (isinstance(value, (int, float)) and math.isfinite(value) and low_ok):
            kind = ">= 0" if f.name in non_negative else "positive"
            raise ValueError(f"{type(config).__name__}.{f.name} must be {kind}, got {value!r}")


def points_in_motion_frame(sensor_pose, angles, ranges, max_range, heading, sensor_offset):
    """Scan returns as (x along the heading, y to its left) about the body centre (m)."""
    x, y, theta = (float(v) for v in np.asarray(sensor_pose, dtype=float).reshape(3))
    angles = np.asarray(angles, dtype=float).reshape(-1)
    ranges = np.asarray(ranges, dtype=float).reshape(-1)
    if angles.shape != ranges.shape:
        raise ValueError(f"{angles.size} angles but {ranges.size} ranges")
    if not (math.isfinite(max_range) and max_range > 0):
        raise ValueError(f"max_range must be a positive number, got {max_range!r}")
    heading = theta if heading is None else float(heading)
    if not all(map(math.isfinite, (x, y, theta, heading))):
        raise ValueError("the sensor pose and the heading must be finite")
    hit = np.isfinite(ranges) & (ranges < max_range)
    r, a = ranges[hit], angles[hit] + theta - heading
    dx = sensor_offset * math.cos(theta - heading)  # sensor relative to the centre, motion frame
    dy = sensor_offset * math.sin(theta - heading)
    return r * np.cos(a) + dx, r * np.sin(a) + dy


@dataclass(frozen=True)
class DistanceLimiterConfig:
    """``DistanceSpeedLimiter``'s parameters (m, m/s, m/s^2, rad)."""

    v_max: float = 0.5
    a_max: float = 0.5
    half_angle: float = math.radians(30.0)
    half_length: float = 0.35
    stop_margin: float = 0.1
    sensor_offset: float = 0.0
    initial_speed: float = 0.0

    def __post_init__(self) -> None:
        _check_config(self, non_negative=("stop_margin", "sensor_offset", "initial_speed"))
        if self.half_angle > math.pi:
            raise ValueError(
                f"DistanceLimiterConfig.half_angle must be <= pi, got {self.half_angle}"
            )


class DistanceSpeedLimiter:
    """The speed from which the robot still stops before the nearest obstacle ahead."""

    def __init__(self, config: DistanceLimiterConfig | None = None) -> None:
        self.config = config if config is not None else DistanceLimiterConfig()
        self.rate = AccelerationLimit(self.config.a_max, self.config.initial_speed)

    def target(self, sensor_pose, angles, ranges, max_range, heading=None) -> float:
        """The limit (m/s) before the acceleration limit."""
        c = self.config
        px, py = points_in_motion_frame(
            sensor_pose, angles, ranges, max_range, heading, c.sensor_offset
        )
        ahead = np.abs(np.arctan2(py, px)) <= c.half_angle
        if not ahead.any():
            return c.v_max
        d = float(np.hypot(px[ahead], py[ahead]).min())
        return min(c.v_max, math.sqrt(2 * c.a_max * max(0.0, d - c.half_length - c.stop_margin)))

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
        _check_config(self, non_negative=("stop_ahead", "sensor_offset", "initial_speed"))
        if not self.slowdown_ratio <= 1:
            raise ValueError(
                f"PolygonLimiterConfig.slowdown_ratio must be in (0, 1], got {self.slowdown_ratio}"
            )
        if not isinstance(self.min_points, int) or isinstance(self.min_points, bool):
            raise ValueError(
                f"PolygonLimiterConfig.min_points must be an integer, got {self.min_points!r}"
            )


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
