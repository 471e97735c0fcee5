# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Speed-limit benchmark (printed, never asserted): one limit of paper 004 (eq. 4: the occlusion
ratio of eq. 1 and the width term) for a 683-beam scan (the scene laser, +-120 deg, 4 m) on the
0.05 m grid of the crossroad scene, at poses along its route. Goal: under 1 ms on one core (for
comparison, nav2's collision monitor reports about 4.5 ms for a 360-point scan). Also printed:
the baselines (distance-only and nav2-style polygons) on the same scans.

Run: python benchmarks/bench_speed.py
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np

from arguments import no_options  # beside this file
from kiseki.sim.scene import load_scene
from kiseki.sim.sensors import LASER_PRESETS
from kiseki.speed import (
    DistanceSpeedLimiter,
    PolygonSpeedLimiter,
    SpeedLimiter,
    occlusion_ratio,
)
from timing import machine_line  # beside this file

WORLDS = Path(__file__).resolve().parents[1] / "data" / "worlds"


def per_call(fn, calls: list, repeats: int = 5) -> float:
    """Best mean seconds per call over `repeats` passes through `calls`."""
    best = math.inf
    for _ in range(repeats):
        start = time.perf_counter()
        for args in calls:
            fn(*args)
        best = min(best, (time.perf_counter() - start) / len(calls))
    return best


def main() -> None:
    print(machine_line(), flush=True)
    scene = load_scene(WORLDS / "speed_crossroad.yaml", "playback")
    prior = load_scene(WORLDS / "speed_crossroad.yaml").ground_truth(0.28, 0.32)
    world = scene.ground_truth(0.28, 0.32)
    laser = LASER_PRESETS["speed_lrf"]
    angles = laser.angles
    poses = np.column_stack([np.zeros(200), np.linspace(0.0, 10.0, 200), np.full(200, math.pi / 2)])
    scans = world.cast_scans(poses, angles, max_range=laser.max_range).astype(np.float32)
    calls = [(p, angles, r, laser.max_range) for p, r in zip(poses, scans, strict=True)]
    print(f"{len(calls)} scans of {angles.size} beams, {laser.max_range} m, 0.05 m grid")

    ratio = per_call(lambda p, a, r, m: occlusion_ratio(prior, p, a, r, m, math.pi / 2), calls)
    limiter = SpeedLimiter(prior)
    full = per_call(lambda p, a, r, m: limiter.update(p, a, r, m, 0.1), calls)
    distance = DistanceSpeedLimiter(prior)
    polygon = PolygonSpeedLimiter()
    dist_t = per_call(lambda p, a, r, m: distance.update(p, a, r, m, 0.1), calls)
    poly_t = per_call(lambda p, a, r, m: polygon.update(p, a, r, m, 0.1), calls)
    rows = [
        ("occlusion ratio (eq. 1)", ratio),
        ("SpeedLimiter.update (eq. 4 + acceleration limit)", full),
        ("distance-only baseline", dist_t),
        ("nav2-style polygon baseline", poly_t),
    ]
    for name, seconds in rows:
        print(f"  {name:<50s} {1e3 * seconds:7.3f} ms   {1e-3 / seconds:6.1f}x the 1 ms goal")
    print(f"  nav2 collision monitor (reported, 360 points): 4.5 ms -> {4.5e-3 / full:.1f}x slower")


if __name__ == "__main__":
    no_options(__doc__)
    main()
