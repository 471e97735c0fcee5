# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The MCAP log of a route playback, written as the run goes (a :class:`RunWriter`: a killed run
keeps every complete chunk). Topics, one message per control step:

* ``/ground_truth`` (world frame) and ``/estimate`` (the taught map's frame, ``map``):
  ``foxglove.PoseInFrame``;
* ``/odom``: ``kiseki.Odometry2D``;
* ``/cmd_vel``: ``kiseki.Twist`` as the simulator writes it (the follower's command before the
  robot's acceleration limits; :meth:`SimRun.velocities` reads it);
* ``/collision``: ``kiseki.Collision`` (:meth:`PlaybackLog.record`), once, when the simulated
  robot touched an obstacle or a pedestrian and the run ended, as a simulated run writes it;
* with a speed limiter, ``/scan`` (``foxglove.LaserScan``, the true sensor pose in the world)
  and ``/speed_limit``: ``kiseki.SpeedLimit``, the fields of ``nav2_msgs/msg/SpeedLimit``
  (``percentage``, ``speed_limit``; the header as ``timestamp`` and ``frame_id``) and the
  ``max_speed`` a percentage refers to, and ``stop``: a limit of 0 m/s means stop here, whereas
  nav2 reads ``speed_limit`` 0 as no limit, so a bridge to ROS must turn ``stop`` into a stop.
"""

from __future__ import annotations

import os
from fractions import Fraction
from typing import Any

import numpy as np

from kiseki.control import SpeedLimit
from kiseki.io.runlog import TWIST_SCHEMA, TWIST_SCHEMA_NAME, RunWriter

__all__ = ["SPEED_LIMIT_SCHEMA", "PlaybackLog"]

_TIME = {
    "type": "object",
    "properties": {"sec": {"type": "integer"}, "nsec": {"type": "integer"}},
}

SPEED_LIMIT_SCHEMA: dict[str, Any] = {
    "title": "kiseki.SpeedLimit",
    "description": "nav2_msgs/msg/SpeedLimit: the speed limit a limiter sets for the robot",
    "type": "object",
    "properties": {
        "timestamp": _TIME,
        "frame_id": {"type": "string"},
        "percentage": {
            "type": "boolean",
            "description": "true: speed_limit is a percentage of max_speed; false: m/s",
        },
        "speed_limit": {"type": "number", "description": "percent or m/s (see percentage)"},
        "max_speed": {"type": "number", "description": "the robot's maximum speed, m/s"},
        "stop": {
            "type": "boolean",
            "description": "the limit is 0 m/s: stop (nav2 reads speed_limit 0 as no limit)",
        },
    },
    "required": ["percentage", "speed_limit", "max_speed"],
}


class PlaybackLog:
    """One playback run's log at ``path`` (which must not exist); use as a context manager."""

    def __init__(self, path: str | os.PathLike, metadata: dict[str, str]) -> None:
        self._writer = RunWriter(path, metadata)

    def __enter__(self) -> PlaybackLog:
        return self

    def __exit__(self, *exc) -> None:
        self._writer.close()

    def step(self, t: float, truth, estimate, odometry) -> None:
        """The poses of the step at time ``t`` (s)."""
        w = self._writer
        w.write_pose("/ground_truth", t, truth)
        w.write_pose("/estimate", t, estimate, frame_id="map")
        w.write_odometry("/odom", t, odometry)

    def scan(self, t: float, sensor_pose, angles: np.ndarray, ranges, max_range: float) -> None:
        self._writer.write_laser_scan("/scan", t, sensor_pose, angles, ranges, max_range=max_range)

    def speed_limit(self, t: float, limit: SpeedLimit) -> None:
        ns = round(Fraction(t) * 1_000_000_000)  # as RunWriter stamps its own messages
        payload = {
            "timestamp": {"sec": ns // 1_000_000_000, "nsec": ns % 1_000_000_000},
            "frame_id": "base_link",
            **limit.to_message(),
        }
        self._writer.write_json("/speed_limit", t, "kiseki.SpeedLimit", payload, SPEED_LIMIT_SCHEMA)

    def record(self, topic: str, t: float, schema_name: str, payload: dict, schema: dict) -> None:
        """Another JSON message of the run (a simulated run's ``/collision``)."""
        self._writer.write_json(topic, t, schema_name, payload, schema)

    def command(self, t: float, v: float, w: float) -> None:
        payload = {"vx": float(v), "vy": 0.0, "w": float(w)}
        self._writer.write_json("/cmd_vel", t, TWIST_SCHEMA_NAME, payload, TWIST_SCHEMA)
