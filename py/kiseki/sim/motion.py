# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What one step of a simulated robot is, as its sensors and its odometry see it: the two
wheels' ground travel (:class:`WheelMotion`, the differential-drive AGV) or the body's motion
(:class:`BodyMotion`, the omnidirectional robot), and the geometry both robots and their odometry
share (checked poses, the exact circular-arc step).

Units are SI throughout (m, s, rad); poses are ``(x, y, theta)`` in the world frame."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from kiseki._support.real_numbers import check_number, hold_number
from kiseki.core import Pose2, normalize_angle

__all__ = ["BodyMotion", "WheelMotion"]

PoseLike = Pose2 | Sequence[float]


@dataclass(frozen=True)
class WheelMotion:
    """True ground travel of the two drive wheels during one step (what the encoders sense).

    Attributes:
        left: signed travel of the left wheel's contact point along its rolling direction, m.
        right: the same for the right wheel, m.
        dt: duration of the step, s.
    """

    left: float
    right: float
    dt: float

    def __post_init__(self) -> None:
        for name in ("left", "right"):
            hold_number(self, name, f"WheelMotion.{name}")
        hold_number(self, "dt", "WheelMotion.dt", 0.0, low_open=True, unit="s")


@dataclass(frozen=True)
class BodyMotion:
    """True motion of a robot during one step, in the body frame at the start of the step.

    Attributes:
        dx, dy: displacement, m, in the body frame at the step's start (x forward, y left).
        dtheta: heading change, rad (not wrapped).
        distance: path length travelled, m (speed x dt; >= the chord sqrt(dx^2 + dy^2)).
        dt: duration of the step, s.
    """

    dx: float
    dy: float
    dtheta: float
    distance: float
    dt: float

    def __post_init__(self) -> None:
        for name in ("dx", "dy", "dtheta"):
            hold_number(self, name, f"BodyMotion.{name}")
        hold_number(self, "distance", "BodyMotion.distance", 0.0, unit="m")
        hold_number(self, "dt", "BodyMotion.dt", 0.0, low_open=True, unit="s")


def as_pose(pose: PoseLike, name: str) -> tuple[float, float, float]:
    if isinstance(pose, Pose2):
        return pose.x, pose.y, pose.theta
    try:
        x, y, theta = pose
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a Pose2 or (x, y, theta), got {pose!r}") from None
    return (
        check_number(x, f"{name}.x"),
        check_number(y, f"{name}.y"),
        check_number(theta, f"{name}.theta"),
    )


def sinc(a: float) -> float:
    """sin(a) / a, accurate near 0."""
    if abs(a) < 1e-4:
        return 1.0 - a * a / 6.0
    return math.sin(a) / a


def arc_displacement(theta: float, ds: float, dtheta: float) -> tuple[float, float]:
    """World displacement of a motion of length ``ds`` along a constant-curvature arc.

    Starting at heading ``theta`` and turning by ``dtheta``: the chord has length
    ``ds * sinc(dtheta / 2)`` and points along ``theta + dtheta / 2``. Exact for any dtheta
    (a straight line for dtheta = 0).
    """
    half = 0.5 * dtheta
    chord = ds * sinc(half)
    mid = theta + half
    return chord * math.cos(mid), chord * math.sin(mid)


def wrap_angle(angle: float) -> float:
    return float(normalize_angle(angle))
