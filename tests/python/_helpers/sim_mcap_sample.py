# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The sample run of the MCAP run-log tests (tests/python/io/test_sim_mcap*.py): 40 steps of
poses, transforms and scans, odometry at 20 Hz, a depth image, a grid and a JSON message."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

import kiseki
from kiseki.io.runlog import (
    RunWriter,
)

N_STEPS = 40
BEAMS = 21
ANGLES = np.linspace(-np.pi / 2, np.pi / 2, BEAMS)
MAX_RANGE = 12.5


def truth_pose(k: int) -> tuple[float, float, float]:
    return (0.25 * k, 1.0 - 0.125 * k, math.remainder(0.3 * k, math.tau))


def laser_pose(k: int) -> tuple[float, float, float]:
    x, y, theta = truth_pose(k)
    return (x + 0.2 * math.cos(theta), y + 0.2 * math.sin(theta), theta)


def scan_ranges(k: int) -> np.ndarray:
    rng = np.random.default_rng(k)
    ranges = rng.uniform(0.1, MAX_RANGE, BEAMS).astype(np.float32)
    ranges[k % BEAMS] = MAX_RANGE  # a no-return beam
    return ranges


def odom_pose(j: int) -> tuple[float, float, float]:
    return (0.26 * j / 2, 1.01 - 0.06 * j, 0.151 * j)


def make_grid() -> kiseki.OccupancyGrid:
    cells = np.full((6, 9), -1, dtype=np.int8)
    cells[0, :] = 0  # row 0 (at the origin) free
    cells[5, 8] = 100
    cells[2, 3] = 37
    return kiseki.OccupancyGrid(cells, 0.05, kiseki.Pose2(-1.5, 2.0, 0.25))


DEPTH = (np.arange(20, dtype=np.float32).reshape(4, 5) * 0.37 + 0.5).astype(np.float32)
DEPTH[1, 2] = np.nan
DEPTH[3, 4] = np.inf


def write_sample(path: Path, **kwargs) -> None:
    """40 steps at 10 Hz: truth pose + transform + scan per step, odometry at 20 Hz shifted by
    5 ms, a depth image, a grid and a magnetometer message of kiseki's own."""
    mag_schema = {
        "title": "kiseki.Magnetometer",
        "type": "object",
        "properties": {"heading": {"type": "number"}},
    }
    with RunWriter(path, {"seed": "42", "world": "corridor"}, **kwargs) as w:
        w.write_grid("/map", 0.0, make_grid())
        for j in range(2 * N_STEPS):
            w.write_odometry("/odom", 0.05 * j + 0.005, odom_pose(j), velocity=(0.5, 0.1))
        for k in range(N_STEPS):
            t = k / 10
            w.write_pose("/ground_truth", t, truth_pose(k))
            w.write_transform(t, "world", "base_link", truth_pose(k))
            w.write_laser_scan(
                "/scan", t, laser_pose(k), ANGLES, scan_ranges(k), max_range=MAX_RANGE
            )
        w.write_depth_image("/depth", 1.5, DEPTH, frame_id="camera")
        w.write_json("/magnetometer", 2.0, "kiseki.Magnetometer", {"heading": 0.5}, mag_schema)
