# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What kiseki's ROS bag reader (:mod:`kiseki.datasets.rosbag`) and writer
(:mod:`kiseki.datasets.rosbag_writer`) share about ROS messages: frame names, stamps, the
TFMessage layout, the heading of a pose's quaternion (a unit one to tf2's tolerance, or
refused) and planar poses composed and inverted."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = [
    "NS_PER_S",
    "TF_MESSAGE_MSG",
    "UNIT_QUATERNION_TOLERANCE",
    "NotARotationError",
    "compose",
    "frame_name",
    "inverse",
    "wrap_angle",
    "yaw",
    "yaw_or_nan",
]

NS_PER_S = 1_000_000_000
TF_MESSAGE_MSG = "geometry_msgs/TransformStamped[] transforms\n"  # ROS 1's tf/tfMessage

UNIT_QUATERNION_TOLERANCE = 1e-2  # on |q|^2 - 1, tf2's QUATERNION_NORMALIZATION_TOLERANCE


class NotARotationError(ValueError):
    """A quaternion of a pose that is not a unit quaternion (read_bag_scans names the bag)."""


def yaw(q: Any) -> float:
    """The heading (rad) of quaternion q (x, y, z, w). A pose's quaternion is a unit one, to
    tf2's tolerance (|q|^2 within 1e-2 of 1): a scaled or zero one gave other headings without
    a word (a zero one, yaw 0) and is refused; one off by more than float rounding is normalised
    (tf2 does so too), one within it read as before."""
    norm2 = q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w
    if not abs(norm2 - 1.0) <= UNIT_QUATERNION_TOLERANCE:
        raise NotARotationError(
            f"an orientation ({q.x:g}, {q.y:g}, {q.z:g}, {q.w:g}) of norm {math.sqrt(norm2):.6g} "
            "is not a unit quaternion"
        )
    x, y, z, w = q.x, q.y, q.z, q.w
    if abs(norm2 - 1.0) > 1e-6:
        x, y, z, w = (v / math.sqrt(norm2) for v in (x, y, z, w))
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def yaw_or_nan(q: Any) -> float:
    """yaw, NaN for a quaternion that is not a unit one: a /tf or /tf_static frame the scans do
    not use may hold one (tf2 warns and goes on); a frame they use then shows as a NaN pose."""
    try:
        return yaw(q)
    except NotARotationError:
        return math.nan


def frame_name(name: str) -> str:
    """A tf frame id without its leading slash (ROS 1's "/base_link" is "base_link")."""
    return name.lstrip("/")


def wrap_angle(theta: np.ndarray) -> np.ndarray:
    return np.remainder(theta + np.pi, 2 * np.pi) - np.pi


def compose(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a ∘ b`` for planar poses (rows of x, y, theta; ``b`` may be one pose)."""
    b = np.broadcast_to(b, a.shape)
    c, s = np.cos(a[:, 2]), np.sin(a[:, 2])
    return np.column_stack(
        [
            a[:, 0] + c * b[:, 0] - s * b[:, 1],
            a[:, 1] + s * b[:, 0] + c * b[:, 1],
            wrap_angle(a[:, 2] + b[:, 2]),
        ]
    )


def inverse(pose: np.ndarray) -> np.ndarray:
    x, y, theta = pose
    c, s = math.cos(theta), math.sin(theta)
    return np.array([-c * x - s * y, s * x - c * y, -theta])
