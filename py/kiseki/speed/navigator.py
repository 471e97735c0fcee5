# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""A goal-seeking navigator for paper 004's omnidirectional robot: the Fuzzy Potential Method
chooses the direction of motion, a speed limiter (the paper's, a baseline, or none) caps the
speed, and the robot drives along that direction without turning.

Each call of ``command(t, pose, scans)`` (the simulator calls it every 0.1 s):

1. ``done`` once the robot's centre is within ``goal_tolerance`` of the goal (it then commands
   zero for good).
2. The scan of the laser named ``laser`` is re-expressed about the robot's centre, in the body
   frame (``scan_about_body``): the FPM's clearances (its robot half-width) are about the
   centre, and the laser of the speed worlds sits 0.2 m ahead of it. The FPM gives the heading
   psi (body frame) and its speed v_fpm towards the goal (also in the body frame).
3. The limiter, if any, is updated with the scan as the laser gave it, dt = t - the previous
   call's t (``period`` = 0.1 s on the first call) and heading = theta + psi (map frame);
   no limiter: the limit is v_max.
4. v = min(v_fpm, limit, sqrt(2 * 0.8 * a_max * d_goal), v_max): the third term lets the robot
   stop at the goal braking at 0.8 a_max (as ``kiseki.control.PurePursuit`` does).
5. (vx, vy, w) = (v cos psi, v sin psi, 0): body-frame velocities; the omnidirectional robot
   drives sideways when it must and keeps facing its start heading (the paper's robot looks
   ahead along +y of its frame).

Every call is recorded in ``log`` (``NavigatorLog``): t, the limit, v_fpm, v, vx, vy and psi, so
experiments can plot speed against time.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from kiseki._support.real_numbers import check_number
from kiseki.control import FuzzyPotentialMethod, SpeedLimitSource

__all__ = ["NavigatorLog", "SpeedControlledNavigator", "scan_about_body"]


@dataclass
class NavigatorLog:
    """One entry per ``command`` call: time (s), limit (m/s; NaN once done), FPM speed,
    commanded speed, body-frame vx, vy (m/s) and heading psi (rad, body frame)."""

    t: list[float] = field(default_factory=list)
    limit: list[float] = field(default_factory=list)
    fpm_speed: list[float] = field(default_factory=list)
    speed: list[float] = field(default_factory=list)
    vx: list[float] = field(default_factory=list)
    vy: list[float] = field(default_factory=list)
    heading: list[float] = field(default_factory=list)

    def append(self, **values: float) -> None:
        for name, value in values.items():
            getattr(self, name).append(float(value))

    def as_arrays(self) -> dict[str, np.ndarray]:
        return {name: np.asarray(getattr(self, name)) for name in self.__dataclass_fields__}


def _finite_pose(name: str, value) -> tuple[float, float, float]:
    try:
        p = np.asarray(value, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        p = np.empty(0)
    if p.shape != (3,) or not np.isfinite(p).all():  # a NaN made every beam NaN
        raise ValueError(f"{name} must be three finite numbers (x, y, theta), got {value!r}")
    return float(p[0]), float(p[1]), float(p[2])


def scan_about_body(pose, sensor_pose, angles, ranges, max_range):
    """(angles, ranges) of the scan's returns seen from the body centre, in the body frame;
    beams without a return (>= max_range or NaN) come back with range +inf."""
    x, y, theta = _finite_pose("pose", pose)
    sx, sy, st = _finite_pose("sensor_pose", sensor_pose)
    angles = np.asarray(angles, dtype=float).reshape(-1)
    ranges = np.asarray(ranges, dtype=float).reshape(-1)
    if angles.shape != ranges.shape:
        raise ValueError(f"{angles.size} angles but {ranges.size} ranges")
    hit = np.isfinite(ranges) & (ranges < max_range)
    c, s = math.cos(theta), math.sin(theta)
    ox, oy = c * (sx - x) + s * (sy - y), -s * (sx - x) + c * (sy - y)  # sensor, body frame
    a = angles + (st - theta)
    r = np.where(hit, ranges, 0.0)
    px, py = ox + r * np.cos(a), oy + r * np.sin(a)
    out_angles = np.where(hit, np.arctan2(py, px), a)
    return out_angles, np.where(hit, np.hypot(px, py), np.inf)


class SpeedControlledNavigator:
    """Drives an omnidirectional robot to ``goal_xy`` (map frame, m) along the FPM's direction
    under a speed limiter (module docstring). ``limiter``: any ``SpeedLimitSource`` or None."""

    def __init__(
        self,
        goal_xy,
        fpm: FuzzyPotentialMethod,
        limiter: SpeedLimitSource | None,
        v_max: float = 0.5,
        goal_tolerance: float = 0.1,
        laser: str = "scan",
        a_max: float = 0.5,
        period: float = 0.1,
    ) -> None:
        goal = np.asarray(goal_xy, dtype=float).reshape(-1)
        if goal.shape != (2,) or not np.isfinite(goal).all():
            raise ValueError(f"goal_xy must be two finite numbers, got {goal_xy!r}")
        for name, value, unit in (("v_max", v_max, "m/s"), ("goal_tolerance", goal_tolerance, "m"),
                                  ("a_max", a_max, "m/s^2"), ("period", period, "s")):  # fmt: skip
            check_number(value, name, 0.0, low_open=True, unit=unit)
        self.goal, self.fpm, self.limiter = goal, fpm, limiter
        self.v_max, self.goal_tolerance, self.laser = v_max, goal_tolerance, laser
        self.a_max, self.period = a_max, period
        self.done = False
        self.log = NavigatorLog()
        self._last_t: float | None = None

    def command(self, t: float, pose, scans) -> tuple[float, float, float]:
        """Body-frame (vx, vy, w) for the robot at ``pose`` = (x, y, theta) (map frame) with
        ``scans[laser]`` = (sensor_pose, angles, ranges, max_range) at time ``t`` (s)."""
        x, y, theta = (float(v) for v in np.asarray(pose, dtype=float).reshape(3))
        dx, dy = self.goal[0] - x, self.goal[1] - y
        d_goal = math.hypot(dx, dy)
        dt = self.period if self._last_t is None else t - self._last_t
        self._last_t = t
        if self.done or d_goal <= self.goal_tolerance:
            self.done = True
            self.log.append(t=t, limit=math.nan, fpm_speed=0, speed=0, vx=0, vy=0, heading=0)
            return 0.0, 0.0, 0.0
        sensor_pose, angles, ranges, max_range = scans[self.laser]
        body_angles, body_ranges = scan_about_body(pose, sensor_pose, angles, ranges, max_range)
        c, s = math.cos(theta), math.sin(theta)
        goal_body = (c * dx + s * dy, -s * dx + c * dy)
        psi, v_fpm = self.fpm.direction(goal_body, body_angles, body_ranges, max_range)
        limit = self.v_max
        if self.limiter is not None:
            out = self.limiter.update(sensor_pose, angles, ranges, max_range, dt, theta + psi)
            limit = out.metres_per_second
        v = min(v_fpm, limit, math.sqrt(2 * 0.8 * self.a_max * d_goal), self.v_max)
        vx, vy = v * math.cos(psi), v * math.sin(psi)
        self.log.append(t=t, limit=limit, fpm_speed=v_fpm, speed=v, vx=vx, vy=vy, heading=psi)
        return vx, vy, 0.0
