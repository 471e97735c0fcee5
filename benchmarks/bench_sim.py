# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Simulator benchmarks (printed, never asserted), on the scenes kept in data/worlds:

1. the factory corridor at 10 Hz with two 160 x 120 depth cameras and a 1081-beam laser,
   whole runs written to MCAP: simulated seconds per wall second (goal: >= 5x real time);
2. the 2-D laser in the factory scene, 1081 beams, 30 m, 0.05 m grid (goal: >= 1000 scans/s);
3. one 160 x 120 depth frame (goal: < 10 ms on one core);
4. the OcTree of rubble environment A at 0.02 m (goal: < 2 s).

Run: python benchmarks/bench_sim.py
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

from arguments import no_options  # beside this file
from kiseki import _core
from kiseki.sim.run import SimConfig, simulate
from kiseki.sim.scene import load_scene
from kiseki.sim.sensors import LASER_PRESETS, DepthCamera, DepthCameraParams, Mount
from timing import best_of, machine_line  # beside this file

WORLDS = Path(__file__).resolve().parents[1] / "data" / "worlds"


def main() -> None:
    print(machine_line(), flush=True)
    factory = load_scene(WORLDS / "factory_corridor.yaml")
    with tempfile.TemporaryDirectory() as tmp:
        runs = [
            simulate(factory, Path(tmp) / f"r{i}.mcap", SimConfig(seed=i), progress=False)
            for i in range(3)
        ]
    factor = max(r.sim_seconds / r.wall_seconds for r in runs)
    print(
        f"factory corridor run to P2 (two 160x120 depth cameras + 1081-beam laser, 10 Hz, "
        f"MCAP): {runs[0].sim_seconds:.1f} s simulated, {factor:.1f}x real time (goal 5x)"
    )

    grid = factory.ground_truth(0.38, 0.42)
    angles = LASER_PRESETS["hokuyo_utm30lx"].angles
    poses = np.column_stack([np.linspace(0, 13, 2000), np.zeros(2000), np.zeros(2000)])
    seconds, _ = best_of(lambda: grid.cast_scans(poses, angles, max_range=30.0))
    print(
        f"2-D laser, factory, 1081 beams, 30 m, 0.05 m grid: {len(poses) / seconds:,.0f} "
        "scans/s (goal 1,000)"
    )

    camera = DepthCamera(DepthCameraParams(), Mount(0.0, 0.29, 0.4, 90.0), seed=0)
    seconds, _ = best_of(lambda: camera.render(factory.world, (4.0, 0.0, 0.0), noise=False), 20)
    noisy, _ = best_of(lambda: camera.render(factory.world, (4.0, 0.0, 0.0)), 20)
    print(
        f"depth frame 160x120: {1000 * seconds:.2f} ms geometry, {1000 * noisy:.2f} ms with "
        "the disparity noise (goal < 10 ms)"
    )

    rubble = load_scene(WORLDS / "rubble_a.yaml")
    seconds, tree = best_of(lambda: _core.OctreeWorld.from_boxes(rubble.world, 0.02), 2)
    print(
        f"OcTree of rubble environment A at 0.02 m: {seconds:.2f} s, "
        f"{tree.occupied_leaves:,} occupied leaves (goal < 2 s)"
    )


if __name__ == "__main__":
    no_options(__doc__)
    main()
