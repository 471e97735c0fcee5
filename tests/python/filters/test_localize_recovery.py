# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""`kiseki localize --recovery`: a robot kidnapped a third of the way round (its odometry
frame jumps by one of three rigid offsets while the robot does not move, so every later
increment is right) stays lost without recovery and is found again with Augmented MCL. A
6 m x 4 m room with a pillar, an elliptic loop around the pillar, noise-free scans, one seed.
(Sensor resetting recovers from the third jump only here: the room is nearly symmetric under a
half turn; the mcl-kidnapping experiment measures the methods' reliability over many trials.)"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from _helpers.room_log import ANGLES, room
from kiseki import save_map
from kiseki.io.runlog import RunWriter

STEPS, KIDNAP = 240, 80
# the odometry frame's offset after the kidnapping: x, y (m), theta (rad)
JUMPS = [(0.0, 0.0, np.pi), (2.5, 1.0, 1.5), (1.5, -0.5, 2.5)]


def _loop() -> np.ndarray:
    """The true poses: an ellipse (radii 2.0 and 1.2 m) around the pillar, facing along it."""
    a = np.linspace(0.0, 2.0 * np.pi, STEPS, endpoint=False)
    x, y = 2.15 + 2.0 * np.cos(a), -0.25 + 1.2 * np.sin(a)
    return np.column_stack([x, y, np.arctan2(1.2 * np.cos(a), -2.0 * np.sin(a))])


def _offset(poses: np.ndarray, jump) -> np.ndarray:
    """``poses`` seen from an odometry frame moved by ``jump`` (rigid: increments kept)."""
    dx, dy, dth = jump
    c, s = np.cos(dth), np.sin(dth)
    x = dx + c * poses[:, 0] - s * poses[:, 1]
    y = dy + s * poses[:, 0] + c * poses[:, 1]
    return np.column_stack([x, y, poses[:, 2] + dth])


@pytest.fixture(scope="module", params=JUMPS, ids=["half-turn", "far", "turned-back"])
def kidnapped(request, tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("kidnapped")
    grid = room()
    save_map(grid, folder / "room.yaml")
    truth = _loop()
    odometry = truth.copy()
    odometry[KIDNAP:] = _offset(truth[KIDNAP:], request.param)
    ranges = grid.cast_scans(truth, ANGLES, max_range=8.0)
    with RunWriter(folder / "log.mcap") as w:
        for k in range(STEPS):
            t = 0.1 * k
            w.write_pose("/ground_truth", t, truth[k])
            w.write_odometry("/odom", t, odometry[k])
            w.write_laser_scan("/scan", t, truth[k], ANGLES, ranges[k], max_range=8.0)
    return folder


def _errors(folder: Path, recovery: str) -> np.ndarray:
    out = folder / f"{recovery}.csv"
    done = subprocess.run(
        [sys.executable, "-m", "kiseki.cli", "localize", "log.mcap", "--map", "room.yaml",
         "--recovery", recovery, "--particles", "1000", "--seed", "4", "-o", out.name],
        cwd=folder, capture_output=True, text=True, timeout=600,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    table = np.loadtxt(out, delimiter=",", skiprows=1)
    assert table.shape == (STEPS, 5)
    return np.hypot(*(table[:, 1:3] - _loop()[:, :2]).T)


def test_without_recovery_it_stays_lost_and_augmented_mcl_finds_it_again(kidnapped):
    lost, found = _errors(kidnapped, "none"), _errors(kidnapped, "augmented")
    for error in (lost, found):
        assert error[:KIDNAP].max() < 0.1  # tracking before the kidnapping
        assert error[KIDNAP] > 1.0  # the jump threw the filter off
    assert np.median(lost[-60:]) > 1.0
    assert np.median(found[-60:]) < 0.3
