# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""A small room with a pillar and a run log of a robot driving through it: the inputs the
command-line tests hand the commands (map files, logs with and without scans)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from kiseki import OccupancyGrid, Pose2, save_map
from kiseki.io.runlog import RunWriter
from kiseki.scans import LaserScans

STEPS = 40
ANGLES = np.linspace(-np.pi / 2, np.pi / 2, 91)


def room() -> OccupancyGrid:
    """A 6 m x 4 m room at 0.05 m with a pillar, free inside."""
    cells = np.zeros((80, 120), np.int8)
    cells[[0, -1], :] = 100
    cells[:, [0, -1]] = 100
    cells[30:40, 60:66] = 100
    return OccupancyGrid(cells, 0.05, Pose2(-1.0, -2.0, 0.0))


def room_scans(n: int, length: float = 1.0, turn: float = 0.0, first: int = 0) -> LaserScans:
    """``n`` scans of the room (8 m range) from poses along y = -1, x from 0 to ``length`` m and
    the heading from 0 to ``turn`` rad, at times 0.1 (first + k) s; the odometry is the poses."""
    poses = np.column_stack(
        [np.linspace(0.0, length, n), np.full(n, -1.0), np.linspace(0, turn, n)]
    )
    ranges = room().cast_scans(poses, ANGLES, max_range=8.0)
    return LaserScans(0.1 * np.arange(first, first + n), poses, poses.copy(), ranges, ANGLES, 8.0)


def write_log(path: Path, scan: bool = True, chunk_size: int = 128 * 1024) -> None:
    """A robot driving along y = -1 in the room: truth, odometry and (with ``scan``) scans."""
    scans = room_scans(STEPS, length=2.0)
    with RunWriter(path, chunk_size=chunk_size) as w:
        for t, pose, ranges in zip(scans.times, scans.poses, scans.ranges, strict=True):
            w.write_pose("/ground_truth", t, pose)
            w.write_odometry("/odom", t, pose)
            if scan:
                w.write_laser_scan("/scan", t, pose, ANGLES, ranges, max_range=8.0)


def write_inputs(folder: Path) -> Path:
    """The room's map (room.yaml) and the run through it (log.mcap) in ``folder``."""
    save_map(room(), folder / "room.yaml")
    write_log(folder / "log.mcap")
    return folder
