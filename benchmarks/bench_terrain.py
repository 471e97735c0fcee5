# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The rubble paper's correlation search and global map, timed side by side (printed, never
asserted). Data: the first two stops of ``kiseki terrain run data/worlds/rubble_a.yaml`` (seed
0): two tilting-laser sweeps of 151 x 181 cells, median of 3, levelled with the gyro, planes
removed by the paper's Hough step.

* exhaustive search over the paper's 56,916 candidates (x 0..70, y -50..50, z -30..30 cm,
  2 cm) on every core, median of 3 (goal < 0.5 s on 2 cores), against a straightforward numpy
  version of eq. 4 (per candidate: reproject every kept point, nearest per cell, compare),
  timed on 40 candidates and scaled to the grid (goal: kiseki >= 100x), both goals on one line;
* coarse to fine (goal < 50 ms, the same minimum);
* PCL's ICP and GICP on the same pair from the same initial guess (no motion);
* OctoMap insertion of one sweep (27,331 rays, 5 m cut): kiseki's GlobalVoxelMap.insert
  (octomap's insertPointCloud in its discretize mode) against octomap's insertPointCloud as
  called by default (one ray per point), median of 5.

Run: python benchmarks/bench_terrain.py
"""

from __future__ import annotations

import math
import os
import statistics
import time
from pathlib import Path

import numpy as np

from arguments import no_options  # beside this file
from kiseki import _core
from kiseki.core import rotation_zyx
from kiseki.sim.terrain_moves import terrain_stops
from kiseki.terrain import (
    correlation_search,
    register_pcl,
    remove_planes,
    sdem_from_points,
    sdem_from_ranges,
)
from timing import machine_line  # beside this file

ROOT = Path(__file__).resolve().parents[1]
DEG = math.pi / 180


def levelled(stop):
    roll, pitch, _ = stop.gyro_rpy
    points, _ = sdem_from_ranges(stop.ranges).to_points()
    return sdem_from_points(points, rotation_zyx(0.0, pitch, roll)), points


def numpy_eq4(prev_points, current_ranges, rot, t):
    """Eq. 4 for one candidate, straightforwardly in numpy (mean form)."""
    q = (prev_points - t) @ rot
    r = np.linalg.norm(q, axis=1)
    th = np.arctan2(q[:, 2], q[:, 0])
    ph = np.arctan2(q[:, 1], np.hypot(q[:, 0], q[:, 2]))
    row = np.floor(th / DEG + 120.5).astype(int)
    col = np.floor(ph / DEG + 90.5).astype(int)
    ok = (r < 5) & (row >= 0) & (row < 151) & (col >= 0) & (col < 181)
    virtual = np.full((151, 181), np.inf)
    np.minimum.at(virtual, (row[ok], col[ok]), r[ok])
    both = np.isfinite(virtual) & ~np.isnan(current_ranges)
    w = np.broadcast_to(np.cos(np.radians(np.arange(-90, 91))), (151, 181))[both]
    return float(((virtual[both] - current_ranges[both]) ** 2 * w).sum() / w.sum())


def main() -> None:
    print(machine_line(), flush=True)
    stops = terrain_stops(ROOT / "data" / "worlds" / "rubble_a.yaml", 1, seed=0)
    (a, raw_a), (b, _) = levelled(stops[0]), levelled(stops[1])
    kept_a, kept_b = remove_planes(a, "hough").kept, remove_planes(b, "hough").kept
    turn = rotation_zyx(stops[1].gyro_rpy[2] - stops[0].gyro_rpy[2])
    prev_points, _ = kept_a.to_points()
    print(f"cores: {os.cpu_count()}; kept points after Hough removal: {len(prev_points)} of "
          f"{a.valid_cells}; current map {kept_b.valid_cells} cells")  # fmt: skip

    runs = []
    for _ in range(3):  # the median of three: the first also pays for the threads' start
        t0 = time.perf_counter()
        full = correlation_search(kept_a, kept_b, turn, method="exhaustive")
        runs.append(time.perf_counter() - t0)
    t_full = statistics.median(runs)
    t0 = time.perf_counter()
    fine = correlation_search(kept_a, kept_b, turn, method="coarse-to-fine")
    t_fine = time.perf_counter() - t0
    grid = _core.TranslationGrid()
    rng = np.random.default_rng(0)
    picks = rng.choice(grid.size, 40, replace=False)
    t0 = time.perf_counter()
    for k in picks:
        numpy_eq4(prev_points, kept_b.ranges, turn, np.asarray(grid.at(int(k))))
    t_numpy = (time.perf_counter() - t0) / len(picks) * grid.size
    one = _core.CorrelationSearch(prev_points, kept_b, turn, "mean", 50, 1)
    part = _core.TranslationGrid()
    part.x_max = 0.16  # 9 of the 36 x steps: a quarter of the grid, on one thread
    t0 = time.perf_counter()
    one.exhaustive(part)
    t_one = (time.perf_counter() - t0) / part.size * grid.size
    print(f"exhaustive, 56,916 candidates: {t_full:.2f} s on every core (goal < 0.5 s), "
          f"{t_numpy / t_full:.0f}x numpy's eq. 4 (goal >= 100x); one thread, from a quarter "
          f"of the grid: {t_one:.2f} s")  # fmt: skip
    print(f"numpy eq. 4, scaled from 40 candidates: {t_numpy:.0f} s")
    same = np.allclose(full.translation, fine.translation)
    print(f"coarse to fine: {1000 * t_fine:.1f} ms, {fine.evaluated} candidates, "
          f"{'the same minimum' if same else 'a DIFFERENT minimum'} "
          f"{np.round(100 * fine.translation, 1)} cm (goal < 50 ms)")  # fmt: skip
    truth = stops[1].sensor[:3, 3] - stops[0].sensor[:3, 3]
    yaw = stops[0].gyro_rpy[2]
    truth = rotation_zyx(yaw).T @ truth
    print(
        f"true move {np.round(100 * truth, 1)} cm, found {np.round(100 * full.translation, 1)} cm"
    )

    # PCL's ICP and GICP on the same pair (levelled points after plane removal, turned by the
    # gyro's yaw change), from the same initial guess (no motion)
    cur_points, _ = kept_b.to_points()
    source = cur_points @ turn.T  # the current points in the previous levelled frame, unmoved
    for method in ("icp", "gicp"):
        t0 = time.perf_counter()
        reg = register_pcl(source, prev_points, None, method)
        dt = time.perf_counter() - t0
        err = 100 * np.linalg.norm(reg.transform[:3, 3] - truth)
        print(f"PCL {method.upper()}: {1000 * dt:.0f} ms, found "
              f"{np.round(100 * reg.transform[:3, 3], 1)} cm (error {err:.1f} cm, converged "
              f"{reg.converged}); S-DEM exhaustive error "
              f"{100 * np.linalg.norm(full.translation - truth):.1f} cm")  # fmt: skip

    points = raw_a
    pose = stops[0].sensor
    times = {}
    for name, discretize in (("kiseki (discretize)", True), ("octomap default", False)):
        runs = []
        for _ in range(5):
            m = _core.GlobalVoxelMap(0.05, 5.0)
            t0 = time.perf_counter()
            m.insert(points, pose, discretize)
            runs.append(time.perf_counter() - t0)
        times[name] = statistics.median(runs)
        print(f"OctoMap insertion of {len(points)} points, {name}: {1000 * times[name]:.0f} ms "
              f"({m.occupied_leaves} occupied voxels)")  # fmt: skip
    ratio = times["octomap default"] / times["kiseki (discretize)"]
    print(f"insertion: kiseki {ratio:.1f}x octomap's default call (goal >= 1x)")


if __name__ == "__main__":
    no_options(__doc__)
    main()
