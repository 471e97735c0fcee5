# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The main job's demo: uses only the repository's data, is deterministic, stops at P2, and
shows odometry drift in the map taught along the odometry path."""

from __future__ import annotations

import json

import numpy as np
from rich.console import Console

from kiseki import load_map
from kiseki.demo import run_demo
from kiseki.experiments.corridor_scans import CorridorLaser, simulate_scans


def test_demo_runs_the_corridor_and_writes_everything(tmp_path, project_root):
    scene = project_root / "data" / "worlds" / "factory_corridor.yaml"
    summary = run_demo(scene, tmp_path / "a", seed=3, console=Console(quiet=True))
    for name in (
        "scene.png",
        "map_true_path.png",
        "map_odometry_path.png",
        "run.mcap",
        "map_true_path.yaml",
        "map_odometry_path.pgm",
        "config.yaml",
        "summary.json",
    ):
        assert (tmp_path / "a" / name).stat().st_size > 0, name
    assert summary["reached_goal"] and summary["stop_error_m"] <= 0.1
    assert summary["endpoints_true_path_map"] > 0.99
    dx, dy = summary["odometry_error_m"]["P2"]
    assert 0.005 < abs(dy) < 1.0 and abs(dx) < 0.1  # drift is mostly sideways, as in the thesis
    truth_map = load_map(tmp_path / "a" / "map_true_path.yaml")
    assert truth_map.resolution == 0.05
    again = run_demo(scene, tmp_path / "b", seed=3, console=Console(quiet=True))
    assert again["odometry_error_m"] == summary["odometry_error_m"]  # same seed, same run
    other = json.loads(json.dumps(run_demo(scene, tmp_path / "c", 4, Console(quiet=True))))
    assert other["odometry_error_m"] != summary["odometry_error_m"]


def test_corridor_laser_noise_is_seeded_and_has_its_sd(project_data):
    grid = load_map(project_data / "maps" / "factory_corridor.yaml")
    _, r1, _ = simulate_scans(grid, CorridorLaser(seed=1))
    _, r2, _ = simulate_scans(grid, CorridorLaser(seed=1))
    _, r3, _ = simulate_scans(grid, CorridorLaser(seed=2))
    assert np.array_equal(r1, r2) and not np.array_equal(r1, r3)
    noise = (r1 - r3)[(r1 < 30) & (r3 < 30)]
    assert abs(noise.std() - np.sqrt(2) * 0.01) < 0.001  # two independent N(0, 0.01) draws
