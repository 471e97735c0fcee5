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

from arguments import no_options  # beside this file
from kiseki import Pose2
from kiseki.filters import MclConfig, MonteCarloLocalizer
from kiseki.grid import beam_angles
from kiseki.models import LocalMapBuilder, SpaceObservationModel, likelihood_reference
from kiseki.sim.scene import load_scene
from timing import machine_line  # beside this file

WORLDS = Path(__file__).resolve().parents[1] / "data" / "worlds"


def main() -> None:
    print(machine_line(), flush=True)
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
    occlusion_rates(grid, local.build(), poses)
    filter_step()


def occlusion_rates(grid, local, poses) -> None:
    """Occlusion-aware (proposal 1): a particle cloud of 1000 around the robot, as in a filter
    step (visibility is cached per map cell, so a step pays for the cells its cloud covers)."""
    model = SpaceObservationModel(grid, occlusion_aware=True)
    model.set_local_map(local)
    cloud = poses[:1000]
    start = time.perf_counter()
    model.likelihoods(cloud)  # cold: visibility of every cell the cloud covers
    cold = time.perf_counter() - start
    start = time.perf_counter()
    for _ in range(20):
        model.likelihoods(cloud)
    warm = (time.perf_counter() - start) / 20
    print("occlusion-aware, 1000 particles (sd 0.3 m, 0.1 m, 5 deg):")
    print(
        f"  first step {len(cloud) / cold:10,.0f} evaluations/s (goal 50,000); "
        f"later steps {len(cloud) / warm:10,.0f}/s"
    )


def filter_step() -> None:
    """One full step of the filter: two 160 x 120 depth images -> depth-band local map ->
    1000 likelihoods -> weights, estimate, resampling, prediction. Goal: < 10 ms."""
    from kiseki.sim.setup import build_robot, build_sensors
    from kiseki.teach.local_maps import LocalMapMaker

    scene = load_scene(WORLDS / "factory_corridor.yaml")
    scene.grid_resolution = 0.1
    grid = scene.ground_truth(0.4, 1.0)
    cameras = [
        s.device
        for s in build_sensors(scene, build_robot(scene, 0), 0, 0.1)
        if s.kind == "depth_camera"
    ]
    images = [c.render(scene.world, (7.4, 0.0, 0.0)) for c in cameras]
    maker = LocalMapMaker(cameras, "band")
    model = SpaceObservationModel(grid)
    localizer = MonteCarloLocalizer(MclConfig(particles=1000), seed=0)
    localizer.initialize((7.4, 0.0, 0.0), (0.05, 0.05, 0.02))

    def observe():
        model.set_local_map(maker.make(images))
        return model

    steps, start = 50, time.perf_counter()
    for k in range(steps):
        localizer.step((7.4 + 0.05 * k, 0.0, 0.0), observe)
    per_step = (time.perf_counter() - start) / steps
    print(
        f"filter step (1000 particles, depth-band local map from two 160x120 images): "
        f"{1000 * per_step:.2f} ms (goal < 10 ms; rendering the images not included)"
    )


if __name__ == "__main__":
    no_options(__doc__)
    main()
