# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Relocalization from one scan, printed, never asserted: time per scan of the branch-and-bound
correlative matcher (kiseki.filters.Relocalizer, RelocalizeConfig's defaults) over the whole
map, on the Intel Research Lab map (built from its corrected log at 0.05 m) and on the CMU Wean
Hall map (0.1 m), for scans spread evenly over each log, on one thread and on two. Goal: under
1 s per scan on 2 cores on both maps.

Beside the times: the map size, the search lattice (headings for the scan), and on Intel, whose
corrected poses are a reference, whether the best hypothesis lies within 0.3 m and 5 degrees of
the laser's pose (Wean's logs have no reference poses).

Needs ../shared/data (the recorded datasets). Run: python benchmarks/bench_relocalize.py
[--scans 10]
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np

from kiseki.datasets import read_carmen_log, read_wean_log
from kiseki.filters import RelocalizeConfig, Relocalizer
from kiseki.io.ros_map import load_map
from kiseki.mapping import MapBuildConfig, map_of_log
from timing import machine_line  # beside this file

DATA = Path(__file__).resolve().parents[2] / "shared" / "data"


def run(name: str, grid, scans, count: int) -> None:
    picks = np.linspace(0, len(scans) - 1, count).round().astype(int)
    print(
        f"{name}: map {grid.width} x {grid.height} cells at {grid.resolution:g} m "
        f"({grid.width * grid.resolution:.1f} x {grid.height * grid.resolution:.1f} m), "
        f"{scans.ranges.shape[1]} beams per scan, {count} scans"
    )
    for threads in (1, 2):
        config = RelocalizeConfig(threads=threads)
        start = time.perf_counter()
        matcher = Relocalizer(grid, scans.max_range, config)
        build = time.perf_counter() - start
        times, hits, headings = [], 0, []
        for i in picks:
            headings.append(matcher.headings(scans.angles, scans.ranges[i]))
            start = time.perf_counter()
            found = matcher.match(scans.angles, scans.ranges[i])
            times.append(time.perf_counter() - start)
            if scans.has_reference_poses and found:
                x, y, theta = scans.poses[i]
                best = found[0]
                turn = abs(math.remainder(best.theta - theta, 2 * math.pi))
                hits += math.hypot(best.x - x, best.y - y) <= 0.3 and turn <= math.radians(5)
        line = (
            f"  {threads} thread(s): {np.median(times):.2f} s per scan (median; max "
            f"{max(times):.2f} s); grids built in {build:.2f} s; headings "
            f"{min(headings)}..{max(headings)}"
        )
        if scans.has_reference_poses:
            line += f"; best within 0.3 m and 5 deg: {hits}/{count}"
        print(line)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scans", type=int, default=10, help="scans timed per map")
    args = parser.parse_args()
    print(machine_line(), flush=True)
    intel = DATA / "carmen" / "intel-corrected.log.gz"
    wean_map, wean_log = DATA / "cmu_wean" / "wean.dat.gz", DATA / "cmu_wean" / "robotdata1.log.gz"
    for path in (intel, wean_map, wean_log):
        if not path.is_file():
            raise SystemExit(f"{path.name} is not at {path}")
    scans = read_carmen_log(intel).scans
    run("Intel", map_of_log(scans, MapBuildConfig(0.05)), scans, args.scans)
    run("Wean", load_map(wean_map), read_wean_log(wean_log).scans, args.scans)


if __name__ == "__main__":
    main()
