# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Space observation model (penetration/intrusion likelihood), printed, never asserted:
evaluations per second of one particle against an 80 x 80-cell local map (8 m at 0.1 m, the
thesis' sizes) on the simulated factory corridor's 0.1 m map, kiseki's C++ (bit-packed,
pre-rotated local maps, one core) beside the straightforward numpy version of the same formula,
with the check that both give the same likelihoods. Goal: >= 1,000,000 evaluations/s and >= 100x.

Run: python benchmarks/bench_space_observation.py
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from kiseki import Pose2
from kiseki.grid import beam_angles
from kiseki.models import LocalMapBuilder, SpaceObservationModel, likelihood_reference
from kiseki.sim.scene import load_scene

WORLDS = Path(__file__).resolve().parents[1] / "data" / "worlds"


def main() -> None:
    scene = load_scene(WORLDS / "factory_corridor.yaml")
    scene.grid_resolution = 0.1  # the thesis' map resolution
    grid = scene.ground_truth(0.35, 0.45)
    angles = beam_angles(1081, np.radians(270))
    ranges = grid.cast_scans(np.array([[7.4, 0.0, 0.0]]), angles, max_range=30.0)[0]
    local = LocalMapBuilder(8.0, 0.1)
    local.add_scan(Pose2(), angles, ranges.astype(np.float32), 30.0)
    model = SpaceObservationModel(grid)
    model.set_local_map(local.build())
    rng = np.random.default_rng(0)
    n = 200_000
    poses = np.column_stack(
        [7.4 + rng.normal(0, 0.3, n), rng.normal(0, 0.1, n), rng.normal(0, np.radians(5), n)]
    )
    model.likelihoods(poses[:2000])  # warm the rotation cache of the headings in use
    best = np.inf
    for _ in range(3):
        start = time.perf_counter()
        fast = model.likelihoods(poses)
        best = min(best, time.perf_counter() - start)
    m = 2000
    start = time.perf_counter()
    slow = likelihood_reference(model, grid, poses[:m])
    numpy_s = time.perf_counter() - start
    same = np.allclose(fast[:m], slow, rtol=1e-13, atol=0)
    print(f"local map 80 x 80 cells on a {grid.width} x {grid.height} map at 0.1 m:")
    print(f"  kiseki C++ : {n / best:12,.0f} evaluations/s (goal 1,000,000)")
    print(f"  numpy      : {m / numpy_s:12,.0f} evaluations/s")
    print(f"  ratio      : {(n / best) / (m / numpy_s):12,.0f} x (goal 100x); same results: {same}")


if __name__ == "__main__":
    main()
