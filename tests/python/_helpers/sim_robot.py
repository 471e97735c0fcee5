# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What the simulated robots' tests share: odometry without errors, a robot without
acceleration limits, poses as arrays, angle differences and the tolerance of a sample SD."""

from __future__ import annotations

import math

import numpy as np

from kiseki.core import Pose2
from kiseki.sim.robot_params import DiffDriveParams, OdometryErrorParams

NONE = OdometryErrorParams.none()
FAST = DiffDriveParams(max_accel=1e6, max_yaw_accel=1e6)  # limits out of the way


def pose_array(p: Pose2) -> np.ndarray:
    return np.array([p.x, p.y, p.theta])


def angle_diff(a: float, b: float) -> float:
    return math.remainder(a - b, 2 * math.pi)


def relative_sd_tolerance(n: int, k: float = 4.0) -> float:
    """k standard errors of a sample SD, relative: k / sqrt(2 (n - 1))."""
    return k / math.sqrt(2 * (n - 1))
