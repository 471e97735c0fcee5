# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The rubble paper's S-DEM search beside two point-cloud registration baselines on the same
scan pairs (issue 13 item 5; printed, never asserted): the pairs of the terrain-env-a,
terrain-env-b and terrain-corridor experiments (kiseki_experiments.terrain.terrain_common: one
move of the simulated tilting laser, median of 3, both sweeps levelled with the gyro's reading,
gyro error included), one seed.

* S-DEM: Hough plane removal (the paper's) and the exhaustive search over the paper's 56,916
  candidates, then the coarse-to-fine search (all cores);
* small_gicp (PyPI ``small_gicp``): GICP, single thread, both clouds downsampled to 5 cm
  voxels, 1 m correspondence distance (its defaults otherwise);
* KISS-ICP (PyPI ``kiss-icp``): its odometry pipeline fed the two clouds as two frames, 5 m
  range, 5 cm voxels (KISS-ICP's own rule: max range / 100), no deskewing.

All start from the same initial guess, zero motion (the identity); the registrations estimate
a full rigid motion (the S-DEM search translation only, the rotation given by the gyro), and
the translation is compared with the truth. A missing package is reported, not an error.

Run: python benchmarks/bench_terrain_baselines.py [SEED]
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np

from kiseki.sim.pose6 import PAPER_MOVES, Pose6
from kiseki.terrain import correlation_search, remove_planes
from kiseki_experiments.terrain.terrain_common import local_maps
from timing import machine_line  # beside this file

ROOT = Path(__file__).resolve().parents[1]
WORLDS = ROOT / "data" / "worlds"
PAIRS = {
    "A (rubble_a)": (WORLDS / "rubble_a.yaml", PAPER_MOVES["A"]),
    "B (rubble_b)": (WORLDS / "rubble_b.yaml", PAPER_MOVES["B"]),
    "corridor": (WORLDS / "terrain_corridor.yaml", Pose6(0.35, 0.0, 0.0)),
}
VOXEL = 0.05


def sdem_rows(maps, seed: int):
    rows = []
    start = time.perf_counter()
    prev = remove_planes(maps.previous, "hough", seed=seed).kept
    cur = remove_planes(maps.current, "hough", seed=seed).kept
    removal = time.perf_counter() - start
    for method in ("exhaustive", "coarse-to-fine"):
        start = time.perf_counter()
        result = correlation_search(prev, cur, None, None, method)
        rows.append((f"S-DEM hough {method}", result.translation, None,
                     removal + time.perf_counter() - start))  # fmt: skip
    return rows


def small_gicp_row(prev_points, cur_points):
    try:
        import small_gicp
    except ImportError:
        return ("small_gicp", None, "not installed (pip install small_gicp)", math.nan)
    start = time.perf_counter()
    result = small_gicp.align(
        prev_points, cur_points, np.eye(4), registration_type="GICP",
        downsampling_resolution=VOXEL, max_correspondence_distance=1.0, num_threads=1,
    )  # fmt: skip
    seconds = time.perf_counter() - start
    return ("small_gicp GICP (1 thread)", result.T_target_source, None, seconds)


def kiss_icp_row(prev_points, cur_points):
    try:
        from kiss_icp.config import KISSConfig
        from kiss_icp.kiss_icp import KissICP
    except ImportError:
        return ("KISS-ICP", None, "not installed (pip install kiss-icp)", math.nan)
    config = KISSConfig()
    config.data.max_range, config.data.min_range, config.data.deskew = 5.0, 0.0, False
    config.mapping.voxel_size = VOXEL
    odometry = KissICP(config)
    start = time.perf_counter()
    odometry.register_frame(prev_points, np.zeros(0))
    odometry.register_frame(cur_points, np.zeros(0))
    seconds = time.perf_counter() - start
    return ("KISS-ICP", np.asarray(odometry.last_pose), None, seconds)


def main(seed: int) -> None:
    print(machine_line(), flush=True)
    print(f"seed {seed}; translation (cm), error |t - truth| (cm), rotation (deg), time (s)")
    for name, (scene, move) in PAIRS.items():
        maps = local_maps(str(scene), move, seed, 10.0)
        truth = 100 * maps.truth
        prev_points = maps.previous.to_points()[0].astype(float)
        cur_points = maps.current.to_points()[0].astype(float)
        print(f"\n{name}: truth ({truth[0]:.0f}, {truth[1]:.0f}, {truth[2]:.0f}) cm, "
              f"{len(prev_points)} and {len(cur_points)} points")  # fmt: skip
        rows = [*sdem_rows(maps, seed), small_gicp_row(prev_points, cur_points),
                kiss_icp_row(prev_points, cur_points)]  # fmt: skip
        for label, estimate, problem, seconds in rows:
            if problem is not None:
                print(f"  {label:34s} {problem}")
                continue
            if np.shape(estimate) == (4, 4):
                t = 100 * estimate[:3, 3]
                angle = math.degrees(
                    math.acos(max(-1.0, min(1.0, (np.trace(estimate[:3, :3]) - 1) / 2)))
                )
                rot = f"{angle:5.2f}"
            else:
                t, rot = 100 * np.asarray(estimate), "  gyro"
            err = float(np.linalg.norm(t - truth))
            print(f"  {label:34s} ({t[0]:6.1f}, {t[1]:6.1f}, {t[2]:6.1f})  error {err:5.1f}  "
                  f"rot {rot}  {seconds:7.3f} s")  # fmt: skip


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("seed", nargs="?", type=int, default=0, help="the scenes' seed")
    main(parser.parse_args().seed)
