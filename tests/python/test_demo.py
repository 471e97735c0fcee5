# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The main job's demo: uses only the repository's data, is deterministic, and rebuilds the map."""

from __future__ import annotations

import json

import numpy as np
from rich.console import Console

from kiseki import load_map
from kiseki.demo import DemoConfig, run_demo, simulate_scans


def test_demo_rebuilds_the_corridor(tmp_path, project_data):
    map_file = project_data / "maps" / "factory_corridor.yaml"
    summary = run_demo(map_file, tmp_path / "a", seed=3, console=Console(quiet=True))
    for name in ("map_scan_at_P1.png", "distance_field.png", "rebuilt_map.png", "config.yaml"):
        assert (tmp_path / "a" / name).stat().st_size > 0
    assert summary["endpoints_on_true_map"] > 0.99
    assert summary["endpoints_on_rebuilt_map"] > 0.95
    rebuilt = load_map(tmp_path / "a" / "rebuilt_map.yaml")
    truth = load_map(map_file)
    # every occupied cell of the rebuilt map lies within one cell of a true obstacle
    occupied = np.argwhere(rebuilt.cells == 100)
    world = rebuilt.cell_to_world(occupied[:, ::-1].astype(float))
    cells = truth.world_to_cell(world)
    inside = (cells[:, 0] >= 0) & (cells[:, 0] < truth.width)
    inside &= (cells[:, 1] >= 0) & (cells[:, 1] < truth.height)
    dist = truth.distance_field()[cells[inside, 1], cells[inside, 0]]
    assert inside.all() and (dist <= 1.5 * truth.resolution).mean() > 0.99


def test_demo_is_deterministic(tmp_path, project_data):
    grid = load_map(project_data / "maps" / "factory_corridor.yaml")
    _, r1, _ = simulate_scans(grid, DemoConfig(seed=1))
    _, r2, _ = simulate_scans(grid, DemoConfig(seed=1))
    _, r3, _ = simulate_scans(grid, DemoConfig(seed=2))
    assert np.array_equal(r1, r2) and not np.array_equal(r1, r3)
    noise = (r1 - r3)[(r1 < 30) & (r3 < 30)]
    assert abs(noise.std() - np.sqrt(2) * 0.01) < 0.001  # two independent N(0, 0.01) draws
    run_demo(
        project_data / "maps" / "factory_corridor.yaml", tmp_path / "b", 1, Console(quiet=True)
    )
    summary = json.loads((tmp_path / "b" / "summary.json").read_text())
    assert summary["scans"] == 131 and summary["beams_per_scan"] == 1081
