# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The time budget, printed, never asserted: tracking along Freiburg building 079 (map built
from its corrected poses at 0.05 m, odometry noise 0.1) with the likelihood field at 50,000
particles x 360 beams on every core, without a budget and with --budget-ms 20, side by side:
the 99th percentile of the update times after the first ten, the position RMSE with its 95 %
interval over the seeds (Student's t), and whether two runs of one seed with one cost model
give the same trajectory. The cost model is calibrated once (kiseki.filters.budget) and every
budgeted run chooses by it. Goal: p99 under 20 ms, the budgeted RMSE within the unbudgeted
run's interval, the same output for the same seed.

Run: python benchmarks/bench_budget.py [--seeds 5] [--scans 0] [--budget-ms 20] [--log PATH]
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import time
from pathlib import Path

import numpy as np
from scipy import stats

from kiseki.datasets import read_carmen_log
from kiseki.filters import LocalizeConfig, calibrate, localize, motion_alphas
from kiseki.mapping import MapBuildConfig, map_of_log
from kiseki.metrics import ape
from timing import machine_line  # beside this file

LOG = (
    Path(__file__).resolve().parents[2]
    / "shared"
    / "data"
    / "carmen"
    / "freiburg-079-corrected.log.gz"
)
SKIPPED_UPDATES = 10  # the first updates (caches, the field's table) are left out of the p99


def interval(values: list[float]) -> tuple[float, float]:
    """Mean and half-width of the 95 % Student's t interval (0 half-width for one value)."""
    v = np.asarray(values)
    if len(v) < 2:
        return float(v.mean()), 0.0
    return float(v.mean()), float(stats.t.ppf(0.975, len(v) - 1) * v.std(ddof=1) / np.sqrt(len(v)))


def run(scans, grid, config, cost):
    start = time.perf_counter()
    result = localize(scans, grid, config, cost_model=cost)
    ms = 1000.0 * result.update_seconds[SKIPPED_UPDATES:]
    rmse = ape(result.estimates, scans.poses).rmse
    return (
        result,
        float(np.percentile(ms, 99)),
        float(np.median(ms)),
        rmse,
        time.perf_counter() - start,
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", type=int, default=5, help="seeds per setting")
    parser.add_argument("--scans", type=int, default=0, help="the log's first scans (0: all)")
    parser.add_argument("--budget-ms", type=float, default=20.0)
    parser.add_argument("--particles", type=int, default=50_000)
    parser.add_argument("--beams", type=int, default=360)
    parser.add_argument("--log", type=Path, default=LOG, help="the Freiburg-079 corrected log")
    args = parser.parse_args()
    print(machine_line(), flush=True)
    if not args.log.is_file():
        raise SystemExit(f"the Freiburg-079 log is not at {args.log}")
    full = read_carmen_log(args.log).scans
    grid = map_of_log(full, MapBuildConfig(0.05))
    scans = full.first(args.scans)
    plain = LocalizeConfig(particles=args.particles, beams=args.beams, odometry_noise=0.1)
    budgeted = dataclasses.replace(plain, budget_ms=args.budget_ms)
    print(
        f"Freiburg-079: {len(scans)} scans, {scans.ranges.shape[1]} beams, map "
        f"{grid.width} x {grid.height}; {os.cpu_count()} cores, load {os.getloadavg()[0]:.2f}"
    )
    cost = calibrate(scans, grid, budgeted, motion_alphas(budgeted, scans))
    print(
        f"cost model: {cost.fixed_ms:.4g} ms + {cost.per_particle_ms:.4g} ms x N + "
        f"{cost.per_beam_ms:.4g} ms x N x B (from 90th percentiles, ms: "
        f"{cost.calibration['quantile_ms']})"
    )
    rows: dict[str, list] = {"unbudgeted": [], f"budget {args.budget_ms:g} ms": []}
    first: dict[str, np.ndarray] = {}
    choice = None
    for seed in range(args.seeds):
        for (name, out), config in zip(rows.items(), (plain, budgeted), strict=True):
            config = dataclasses.replace(config, seed=seed)
            result, p99, median, rmse, wall = run(scans, grid, config, cost)
            choice = result.budget or choice
            out.append((p99, median, rmse))
            first.setdefault(name, result.estimates)
            print(
                f"  seed {seed} {name:<16} p99 {p99:7.2f} ms  median {median:7.2f} ms  "
                f"RMSE {rmse:.4f} m  ({wall:.0f} s, load {os.getloadavg()[0]:.2f})",
                flush=True,
            )
    print(choice.describe() if choice else "no budgeted run")
    again = localize(scans, grid, dataclasses.replace(budgeted, seed=0), cost_model=cost).estimates
    same = np.array_equal(again, first[f"budget {args.budget_ms:g} ms"])
    print(f"{'setting':<18}{'p99 ms':>9}{'p99 / budget':>14}{'median ms':>11}{'RMSE m (95 %)':>22}")
    for name, values in rows.items():
        p99 = max(v[0] for v in values)  # the worst seed's
        median = float(np.median([v[1] for v in values]))
        mean, half = interval([v[2] for v in values])
        print(
            f"{name:<18}{p99:>9.2f}{p99 / args.budget_ms:>14.2f}{median:>11.2f}"
            f"{f'{mean:.4f} +- {half:.4f}':>22}"
        )
    (plain_mean, plain_half), (budget_mean, _) = (
        interval([v[2] for v in values]) for values in rows.values()
    )
    inside = abs(budget_mean - plain_mean) <= plain_half
    print(
        f"budgeted RMSE / unbudgeted: {budget_mean / plain_mean:.3f} (within the unbudgeted "
        f"interval: {'yes' if inside else 'no'}); seed 0 budgeted twice, one cost model: "
        f"{'identical' if same else 'DIFFERENT'} trajectories"
    )


if __name__ == "__main__":
    main()
