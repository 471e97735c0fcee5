# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Paper 004's limit along a recorded log: for each scan at its reference pose on a map of the
building, eq. 4's reference speed and its terms, as the robot would have been told to slow
down. The direction of motion is the laser's heading (``heading="laser"``: a differential-drive
robot, as in every CARMEN log, drives where it faces) or the direction of the log's own
displacement (``"motion"``, for an omnidirectional robot with densely logged poses: toward the
next pose at least 1 cm away, the pose's own heading once the robot stops).

A real laser reaches further than the paper's 4 m: ``reach`` bounds the region of eq. 1 (the
paper's sensor range; readings at or beyond it are free space seen up to it) and the passage
width's search; the scan's own ``max_range`` readings are no return as always.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from kiseki._support.real_numbers import check_number
from kiseki.grid import OccupancyGrid
from kiseki.scans import LaserScans
from kiseki.speed.limiter import SpeedLimiter, SpeedLimiterConfig

__all__ = ["LimitsAlongLog", "limits_along_log", "motion_headings"]


@dataclass(frozen=True)
class LimitsAlongLog:
    """Per scan: time (s), laser pose (x, y, theta), direction of motion (rad, map frame),
    eq. 1's ratio, the passage width w (m), f(w), and v_ref = v_max * ratio * f(w) (m/s)."""

    times: np.ndarray
    poses: np.ndarray
    headings: np.ndarray
    ratio: np.ndarray
    width: np.ndarray
    width_factor: np.ndarray
    v_ref: np.ndarray

    def columns(self) -> dict[str, np.ndarray]:
        return {
            "t": self.times,
            "x": self.poses[:, 0],
            "y": self.poses[:, 1],
            "theta": self.poses[:, 2],
            "heading": self.headings,
            "ratio": self.ratio,
            "width": self.width,
            "width_factor": self.width_factor,
            "v_ref": self.v_ref,
        }


def motion_headings(poses: np.ndarray, min_step: float = 0.01) -> np.ndarray:
    """The direction of motion at each pose: toward the next pose at least ``min_step`` metres
    away (m); the pose's own heading where the robot does not move any more."""
    poses = np.asarray(poses, dtype=float)
    if poses.ndim != 2 or poses.shape[1] != 3:
        raise ValueError(f"motion_headings: poses must be (n, 3) x, y, theta, got {poses.shape}")
    bad = ~np.isfinite(poses).all(axis=1)
    if bad.any():  # a NaN pose took its neighbour's heading, or its own NaN
        i = int(np.argmax(bad))
        raise ValueError(f"motion_headings: poses must be finite, pose {i} is {poses[i].tolist()}")
    # NaN or -1 took the pose's own heading
    check_number(min_step, "motion_headings: min_step", 0.0, unit="m")
    headings = poses[:, 2].copy()
    target = None
    for i in range(len(poses) - 1, -1, -1):
        if target is None or math.dist(poses[i, :2], target) >= min_step:
            ahead = target
            if ahead is not None:
                headings[i] = math.atan2(ahead[1] - poses[i, 1], ahead[0] - poses[i, 0])
            target = poses[i, :2]
        else:
            headings[i] = headings[i + 1]
    return headings


def limits_along_log(
    scans: LaserScans,
    grid: OccupancyGrid,
    config: SpeedLimiterConfig | None = None,
    reach: float = 4.0,
    heading: str = "laser",
) -> LimitsAlongLog:
    """Eq. 4 for every scan of a log with reference poses, on ``grid`` (the building's map)."""
    if heading not in ("laser", "motion"):
        raise ValueError(f"heading must be laser or motion, got {heading!r}")
    if not isinstance(scans, LaserScans):
        raise TypeError(f"scans must be kiseki LaserScans, got {type(scans).__name__}")
    if len(scans) == 0:
        raise ValueError("the log has no scans")
    if not scans.has_reference_poses:
        raise ValueError("the log has no reference poses: the limit needs where each scan was")
    check_number(reach, "reach", 0.0, low_open=True, unit="m")
    limiter = SpeedLimiter(grid, config)
    headings = motion_headings(scans.poses) if heading == "motion" else scans.poses[:, 2].copy()
    reach = min(reach, scans.max_range)
    clipped = np.minimum(scans.ranges, np.float32(reach))  # NaN stays NaN
    out = np.empty((len(scans), 4))
    for i in range(len(scans)):
        r = limiter.reference(scans.poses[i], scans.angles, clipped[i], reach, headings[i])
        out[i] = r["ratio"], r["width"], r["width_factor"], r["v_ref"]
    return LimitsAlongLog(
        scans.times, scans.poses, headings, out[:, 0], out[:, 1], out[:, 2], out[:, 3]
    )
