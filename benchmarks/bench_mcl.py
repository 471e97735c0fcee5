# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The Monte Carlo engine's update, printed, never asserted: time per measurement update
(motion model, weighing, resampling) of the likelihood-field and beam models on a real log
(Freiburg building 079, 360 beams, map built from its corrected poses at 0.05 m), for particle
counts up to 50,000, on one thread and on every core, and the speed-up. Goals: 50,000 particles
x 360 beams with the likelihood field in under 100 ms per update on 2 cores (10 Hz).

The side-by-side comparison with nav2's AMCL is benchmarks/bench_nav2_amcl.py.

Run: python benchmarks/bench_mcl.py [--scans 30] [--particles 50000 200000] [--models
likelihood-field]
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

from kiseki.datasets import read_carmen_log
from kiseki.filters import LocalizeConfig, MclConfig, MonteCarloLocalizer, scan_model
from kiseki.mapping import MapBuildConfig, map_of_log
from timing import machine_line  # beside this file

LOG = (
    Path(__file__).resolve().parents[2]
    / "shared"
    / "data"
    / "carmen"
    / "freiburg-079-corrected.log.gz"
)


def time_updates(scans, grid, method: str, particles: int, beams: int, threads: int, n: int):
    """Median ms per update over n consecutive scans (after 3 warm-up updates)."""
    config = MclConfig(particles=particles, threads=threads, resample_threshold=1.0)
    loc = MonteCarloLocalizer(config, 0, grid)
    loc.initialize(scans.poses[0], (0.1, 0.1, 0.05))
    model = scan_model(method, grid, LocalizeConfig(method=method, beams=beams))
    times = []
    for k in range(n + 3):
        start = time.perf_counter()
        model.set_scan(scans.angles, scans.ranges[k], scans.max_range)
        loc.step(scans.poses[k], lambda: model)
        times.append(time.perf_counter() - start)
    return 1000.0 * float(np.median(times[3:]))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scans", type=int, default=20, help="updates timed per setting")
    parser.add_argument(
        "--particles",
        nargs="+",
        type=int,
        default=[1000, 10_000, 50_000],
        help="the likelihood field's particle counts (360 beams)",
    )
    parser.add_argument(
        "--models",
        nargs="+",
        choices=("likelihood-field", "beam"),
        default=["likelihood-field", "beam"],
    )
    args = parser.parse_args()
    print(machine_line(), flush=True)
    if args.scans < 1 or min(args.particles) < 1:
        parser.error("scans and particles must be >= 1")
    if not LOG.is_file():
        raise SystemExit(f"the Freiburg-079 log is not at {LOG}")
    scans = read_carmen_log(LOG).scans
    grid = map_of_log(scans, MapBuildConfig(0.05))
    cores = os.cpu_count() or 1
    print(f"Freiburg-079: {scans.ranges.shape[1]} beams, map {grid.width} x {grid.height}")
    head = f"{'model':<17}{'particles':>10}{'beams':>7}{'1 thread ms':>13}"
    print(head + f"{f'{cores} threads ms':>14}{'speed-up':>10}")
    settings = [("likelihood-field", n, 360) for n in args.particles]
    settings += [("beam", 1000, 60), ("beam", 10_000, 60)]
    settings = [s for s in settings if s[0] in args.models]
    for method, particles, beams in settings:
        one = time_updates(scans, grid, method, particles, beams, 1, args.scans)
        all_ = time_updates(scans, grid, method, particles, beams, 0, args.scans)
        print(f"{method:<17}{particles:>10}{beams:>7}{one:>13.2f}{all_:>14.2f}{one / all_:>10.2f}")


if __name__ == "__main__":
    main()
