# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Foundation benchmarks (printed, never asserted): ray casting throughput and map building.

1. Ray casting on the Intel Research Lab map (built from its corrected log at 0.05 m):
   360-beam scans, 30 m max range, from the log's own poses. kiseki's C++ grid traversal
   (one core) beside a vectorised numpy reference that samples each ray every quarter cell;
   the ratio and the agreement of the two are printed.
2. Map building from the Intel log: read, build, endpoint agreement.

Needs ../shared/data (the recorded datasets). Run: python benchmarks/bench_foundation.py
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

from arguments import no_options  # beside this file
from kiseki.datasets import read_carmen_log
from kiseki.grid import OccupancyGrid, beam_angles
from kiseki.mapping import build_map, endpoint_agreement
from timing import best_of, machine_line  # beside this file

DATA = Path(__file__).resolve().parents[2] / "shared" / "data"


def numpy_cast(grid: OccupancyGrid, poses: np.ndarray, angles: np.ndarray, max_range: float):
    """Reference ray casting in numpy: sample every ray at a quarter of a cell."""
    t = np.arange(0.0, max_range, grid.resolution / 4)
    out = np.empty((len(poses), len(angles)))
    for i, (x, y, th) in enumerate(poses):
        a = th + angles
        px = x + np.cos(a)[:, None] * t  # (beams, samples)
        py = y + np.sin(a)[:, None] * t
        cx = np.floor((px - grid.origin.x) / grid.resolution).astype(int)
        cy = np.floor((py - grid.origin.y) / grid.resolution).astype(int)
        inside = (cx >= 0) & (cx < grid.width) & (cy >= 0) & (cy < grid.height)
        occ = np.zeros_like(inside)
        occ[inside] = grid.cells[cy[inside], cx[inside]] >= 65
        first = np.where(occ.any(axis=1), occ.argmax(axis=1), -1)
        out[i] = np.where(first >= 0, t[np.maximum(first, 0)], max_range)
    return out


def main() -> int:
    if not DATA.is_dir():
        print(f"recorded datasets not found at {DATA}: nothing to benchmark")
        return 1
    print(machine_line())
    start = time.perf_counter()
    log = read_carmen_log(DATA / "carmen" / "intel-corrected.log.gz")
    read_s = time.perf_counter() - start
    s = log.scans
    build_s, grid = best_of(lambda: build_map(s.poses, s.ranges, s.angles, s.max_range))
    share = endpoint_agreement(grid, s.poses, s.ranges, s.angles, s.max_range)
    print(f"\nmap building, Intel log ({len(s)} scans x {s.ranges.shape[1]} beams, 0.05 m):")
    print(
        f"  read {read_s:.2f} s, build {build_s:.2f} s ({len(s) / build_s:.0f} scans/s), "
        f"{grid.width} x {grid.height} cells, {100 * share:.1f} % endpoints on occupied"
    )

    angles = beam_angles(360, 2 * np.pi * 359 / 360)
    poses = s.poses
    kiseki_s, ranges = best_of(lambda: grid.cast_scans(poses, angles, max_range=30.0))
    sub = poses[:: max(1, len(poses) // 40)]
    numpy_s, ref = best_of(lambda: numpy_cast(grid, sub, angles, 30.0), repeats=1)
    rays_kiseki = poses.shape[0] * len(angles) / kiseki_s
    rays_numpy = sub.shape[0] * len(angles) / numpy_s
    diff = np.abs(grid.cast_scans(sub, angles, max_range=30.0) - ref)
    print("\nray casting, Intel map, 360 beams, 30 m max range (one core):")
    print(
        f"  kiseki C++ traversal : {rays_kiseki / 1e6:8.2f} M rays/s "
        f"({poses.shape[0] / kiseki_s:.0f} scans/s)"
    )
    print(f"  numpy sampling       : {rays_numpy / 1e6:8.2f} M rays/s")
    print(f"  ratio                : {rays_kiseki / rays_numpy:8.1f} x")
    print(
        f"  agreement            : median |diff| {np.median(diff) * 100:.2f} cm, "
        f"{100 * np.mean(diff <= grid.resolution):.1f} % within one cell"
    )
    return 0


if __name__ == "__main__":
    no_options(__doc__)
    sys.exit(main())
