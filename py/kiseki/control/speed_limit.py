# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Speed limits as a navigation stack passes them around, and what a limiter looks like to the
code that drives a robot (route playback, the simulator's navigators).

``SpeedLimit`` carries the two fields of nav2's ``nav2_msgs/msg/SpeedLimit``: ``percentage``
(True: ``speed_limit`` is a percentage of the robot's maximum speed; False: metres per second)
and ``speed_limit``. nav2 reads a ``speed_limit`` of 0 as "no limit"; kiseki's 0 means stop, so
its messages (``to_message``) also carry ``stop`` (the limit is 0 m/s): a bridge to ROS must
turn that into a stop, not into no limit.

Code that drives a robot takes any object with the ``SpeedLimitSource`` method ``update``; it
never imports the limiter's area (kiseki.speed), so playback stays independent of it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from kiseki._support.real_numbers import check_number

__all__ = ["SpeedLimit", "SpeedLimitSource"]


@dataclass(frozen=True)
class SpeedLimit:
    """A speed limit with nav2's semantics, plus the robot's maximum it refers to.

    Attributes:
        speed_limit: m/s when ``percentage`` is False, else percent of ``max_speed``.
        percentage: nav2's flag.
        max_speed: the robot's maximum speed (m/s) the percentage refers to.
    """

    speed_limit: float
    percentage: bool = False
    max_speed: float = 0.5

    def __post_init__(self) -> None:
        if not isinstance(self.percentage, bool | np.bool_):  # "no" read as True
            raise ValueError(f"percentage must be True or False, got {self.percentage!r}")
        # a percentage is of max_speed, at most all of it
        high, unit = (100.0, "%") if self.percentage else (float("inf"), "m/s")
        check_number(self.speed_limit, "speed_limit", 0.0, high, unit=unit)
        check_number(self.max_speed, "max_speed", 0.0, low_open=True, unit="m/s")

    @property
    def metres_per_second(self) -> float:
        """The limit in m/s whatever its form."""
        if self.percentage:
            return self.max_speed * self.speed_limit / 100.0
        return self.speed_limit

    def as_percentage(self) -> SpeedLimit:
        """The same limit as a percentage of ``max_speed`` (capped at 100)."""
        value = min(100.0, 100.0 * self.metres_per_second / self.max_speed)
        return SpeedLimit(value, True, self.max_speed)

    def to_message(self) -> dict:
        """The fields of ``nav2_msgs/msg/SpeedLimit`` (without the header), the ``max_speed`` a
        percentage refers to, and ``stop`` (the limit is 0 m/s; nav2 would read 0 as no limit)."""
        return {
            "percentage": bool(self.percentage),
            "speed_limit": float(self.speed_limit),
            "max_speed": float(self.max_speed),
            "stop": self.metres_per_second == 0.0,
        }


@runtime_checkable
class SpeedLimitSource(Protocol):
    """What a speed limiter offers to the code that drives the robot: one update per scan.

    ``sensor_pose``: the laser's (x, y, theta) in the map frame; ``angles``: beam angles in the
    sensor frame (rad); ``ranges``: the scan (m; readings >= ``max_range`` are no return, NaN
    says nothing); ``dt``: seconds since the previous update; ``heading``: the direction of
    motion in the map frame (rad), default the sensor's heading."""

    def update(
        self,
        sensor_pose: tuple[float, float, float] | np.ndarray,
        angles: np.ndarray,
        ranges: np.ndarray,
        max_range: float,
        dt: float,
        heading: float | None = None,
    ) -> SpeedLimit: ...
