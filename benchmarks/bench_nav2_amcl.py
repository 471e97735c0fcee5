# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""nav2 AMCL beside kiseki's Monte Carlo localization on the CARMEN logs (printed, never
asserted): position and heading RMSE against the logs' corrected laser poses, and wall time per
filter update (motion + sensor + resampling, one update per scan).

nav2 AMCL is run through the PyPI package ``amcl`` (Python bindings of nav2_amcl's own C++
particle filter, motion models and laser models). ``amcl`` is GPL-3.0: kiseki never imports it;
it is only the optional benchmark extra (``pip install amcl``, or ``pip install kiseki[bench]``)
and this script stops with a one-line message without it.

For each log, beam count and particle count both filters get the same map (built from the log
at 0.05 m), the same noisy odometry, the same beams of each scan, the same particle count and the
same initial cloud parameters; the parameter choices are written beside each setting below. The
``amcl`` package (0.1.x) exposes only nav2's *beam* model (its likelihood-field model is not
reachable from Python), so nav2 always runs the beam model; kiseki runs ``--kiseki-model``
(default: its beam model, the same model; or its likelihood field), and the header says which.
Times are measured with time.perf_counter around each nav2 ``update`` call (the Python scan
objects are built beforehand) and taken from kiseki's per-update times.

Needs ../shared/data (the recorded datasets). Run: python benchmarks/bench_nav2_amcl.py
(--quick: Intel only, first 200 scans, 1000 particles, 60 beams; --help for the options).
"""

from __future__ import annotations

import argparse
import contextlib
import csv
import ctypes
import dataclasses
import importlib.metadata
import os
import sys
import time
from pathlib import Path

import numpy as np
from tqdm import tqdm

from amcl_inputs import (  # beside this file
    ALPHA5,
    CHI_OUTLIER,
    DATA,
    INITIAL_SD,
    LAMBDA_SHORT,
    LOGS,
    ODOMETRY_NOISE,
    SIGMA_HIT,
    Z_HIT,
    Z_MAX,
    Z_RAND,
    Z_SHORT,
    load_log,
    log_odometry,
    select_scans,
)
from kiseki.filters import LOCALIZATION_METHODS, LocalizeConfig
from kiseki.grid import FREE, OCCUPIED
from kiseki.metrics import ape
from timing import machine_line  # beside this file

try:
    import amcl  # GPL-3.0, the benchmark extra only
except ImportError:
    amcl = None

# The settings both filters share (odometry noise, alphas, the mixture, the initial cloud) and
# the log loading are in amcl_inputs.py, beside this file; those of this script alone follow.
# Update gates: nav2's node updates only after update_min_d (0.25 m) / update_min_a (0.2 rad) of
# travel; the amcl package has no gate (every update() call is a motion + sensor + resampling
# step) and kiseki gets update_min_d = update_min_a = 0, so every scan is an update in both.
UPDATE_MIN_D = UPDATE_MIN_A = 0.0
# Particle count fixed in both: nav2 min_particles = max_particles, so KLD sampling (pf_err /
# pf_z, fixed at 0.01 / 3 inside the amcl package) cannot change the count.
# Recovery off: alpha_slow = alpha_fast = 0 (no random particles injected).
ALPHA_SLOW = ALPHA_FAST = 0.0
# Resampling at every update, multinomial in both: nav2 resample_interval 1 (the amcl package
# resamples on each update() call, with nav2's multinomial sampler, a linear search of the
# cumulative weights per particle); kiseki resample_threshold 1.0 (resample whenever the
# effective sample size is below N, that is at every update) with resampling "multinomial".
# Both combine the beams with nav2's rule p = 1 + sum pz^3 (kiseki: combination "nav2").
RESAMPLE_THRESHOLD = 1.0

COLUMNS = (
    "log",
    "beams",
    "particles",
    "scans",
    "nav2_rmse_m",
    "nav2_heading_deg",
    "nav2_ms",
    "kiseki1_rmse_m",
    "kiseki1_heading_deg",
    "kiseki1_ms",
    "kisekiN_rmse_m",
    "kisekiN_heading_deg",
    "kisekiN_ms",
    "ratio_1",
    "ratio_N",
)


def nav2_map(grid):
    """The kiseki grid as an amcl.OccupancyGrid: ROS values (0 free, 100 occupied, -1 unknown;
    the package treats anything but 0 and 100 as unknown, and its rays stop at unknown cells
    as well as occupied ones), rows from the origin. The package (like nav2's node) places cell
    i's centre at origin_x + i * resolution, while kiseki's origin is the corner of cell 0: half
    a cell is added so that both filters see the same walls."""
    if abs(grid.origin.theta) > 1e-12:
        raise ValueError("nav2 AMCL maps cannot be rotated")
    cells = np.asarray(grid.cells)
    data = np.full(cells.shape, -1, dtype=np.int8)
    data[cells == FREE] = 0
    data[cells == OCCUPIED] = 100
    half = 0.5 * grid.resolution
    out = amcl.OccupancyGrid(
        grid.width, grid.height, grid.resolution, grid.origin.x + half, grid.origin.y + half
    )
    out.data = data.ravel().tolist()
    return out


def nav2_scans(ranges: np.ndarray, angles: np.ndarray, max_range: float) -> list:
    """amcl.LaserScan objects ([range, bearing] pairs). As in nav2's node, readings at or beyond
    max range are set to it (the beam model's z_max term); NaN and non-positive readings are
    NaN, which the beam model skips (kiseki skips them too)."""
    r = np.minimum(ranges.astype(np.float64), max_range)
    r[~(r > 0)] = np.nan
    return [
        amcl.create_laser_scan_from_list(np.column_stack([row, angles]).tolist(), max_range)
        for row in r
    ]


def seed_nav2(seed: int) -> None:
    """The amcl package draws from libc's drand48, seeded with the time when a filter is made
    and with a process-wide counter when the initial cloud is drawn; seeding it after that makes
    the runs repeatable (where libc has srand48)."""
    with contextlib.suppress(OSError, AttributeError):
        ctypes.CDLL(None).srand48(ctypes.c_long(seed))


def run_nav2(scans, grid_nav2, odom, alphas, particles, seed, label) -> tuple[np.ndarray, ...]:
    angles = scans.angles
    laser = amcl.LaserParameters(
        Z_HIT, Z_SHORT, Z_MAX, Z_RAND, SIGMA_HIT, LAMBDA_SHORT, CHI_OUTLIER, len(angles)
    )
    motion = amcl.MotionParameters(*alphas, ALPHA5)
    pf = amcl.AMCL(particles, particles, ALPHA_SLOW, ALPHA_FAST, motion, laser, "differential")
    pf.set_map(grid_nav2)
    pf.set_laser_pose(amcl.Vector3D(0.0, 0.0, 0.0))  # the poses and odometry are the laser's
    sx, sy, sa = INITIAL_SD
    pf.set_initial_pose(
        amcl.Vector3D(*scans.poses[0]), amcl.create_diagonal_covariance(sx**2, sy**2, sa**2)
    )
    seed_nav2(seed)
    laser_scans = nav2_scans(scans.ranges, angles, float(scans.max_range))
    estimates = np.empty((len(scans), 3))
    seconds = np.empty(len(scans))
    for k in tqdm(range(len(scans)), desc=label, unit="scan", leave=False):
        pose = amcl.Vector3D(*odom[k])
        start = time.perf_counter()
        pf.update(laser_scans[k], pose)  # the first one: zero motion, sensor, resampling
        seconds[k] = time.perf_counter() - start
        mean = pf.get_pose_mean()  # weighted mean of all particles (not the best cluster's)
        estimates[k] = (mean.x, mean.y, mean.theta)
    return estimates, seconds


def kiseki_api():
    """kiseki's localize if it has the benchmark API (per-update times, threads), else None."""
    names = {f.name for f in dataclasses.fields(LocalizeConfig)}
    if not {"beams", "threads", "update_min_d", "resample_threshold", "combination"} <= names:
        return None
    from kiseki.filters import localize

    return localize


def run_kiseki(localize, scans, grid, method, particles, threads, seed, alphas, caster=None):
    """kiseki's estimates and per-update seconds; `caster` the beam model's ray caster (None:
    LocalizeConfig's default)."""
    extra = {} if caster is None else {"caster": caster}
    config = LocalizeConfig(
        method=method,
        particles=particles,
        beams=scans.ranges.shape[1],  # the beams chosen above, every one of them
        threads=threads,
        seed=seed,
        odometry_noise=0.0,  # the scans carry the noisy odometry nav2 gets
        alphas=tuple(alphas),
        initial_sd=INITIAL_SD,
        sigma_hit=SIGMA_HIT,
        z_hit=Z_HIT,
        z_rand=Z_RAND,
        z_short=Z_SHORT,
        z_max=Z_MAX,
        lambda_short=LAMBDA_SHORT,
        combination="nav2",  # nav2's p = 1 + sum pz^3 (kiseki's default is the product)
        kld=False,  # fixed particle count
        resampling="multinomial",  # nav2's scheme (kiseki's default is systematic)
        resample_threshold=RESAMPLE_THRESHOLD,
        recovery="none",
        update_min_d=UPDATE_MIN_D,
        update_min_a=UPDATE_MIN_A,
        **extra,
    )
    result = localize(scans, grid, config)
    return np.asarray(result.estimates), np.asarray(result.update_seconds)


def errors(estimates: np.ndarray, reference: np.ndarray) -> tuple[float, float]:
    return (
        float(ape(estimates, reference).rmse),
        float(ape(estimates, reference, "rotation_deg").rmse),
    )


def fmt(value: float, spec: str) -> str:
    return format(value, spec) if np.isfinite(value) else "-"


def print_table(rows: list[dict], threads: int) -> None:
    head = (
        f"{'log':<13}{'beams':>6}{'particles':>10}{'scans':>6} | "
        f"{'nav2 AMCL':^22} | {'kiseki, 1 thread':^22} | "
        f"{f'kiseki, {threads} threads':^22} | {'nav2/kiseki':^13}"
    )
    sub = f"{'':35} | " + " | ".join([f"{'RMSE m':>7}{'deg':>6}{'ms':>9}"] * 3) + " |   1 T   all T"
    print(head)
    print(sub)
    print("-" * len(head))
    for r in rows:
        cells = [
            f"{fmt(r[f'{k}_rmse_m'], '.3f'):>7}{fmt(r[f'{k}_heading_deg'], '.2f'):>6}"
            f"{fmt(r[f'{k}_ms'], '.2f'):>9}"
            for k in ("nav2", "kiseki1", "kisekiN")
        ]
        print(
            f"{r['log']:<13}{r['beams']:>6}{r['particles']:>10}{r['scans']:>6} | "
            + " | ".join(cells)
            + f" | {fmt(r['ratio_1'], '5.1f'):>5} {fmt(r['ratio_N'], '7.1f'):>7}"
        )


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    methods = [m for m in LOCALIZATION_METHODS if m not in ("odometry", "space-observation")]
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--logs", nargs="+", choices=LOGS, default=list(LOGS))
    parser.add_argument("--beams", nargs="+", type=int, default=[60, 90])
    parser.add_argument("--particles", nargs="+", type=int, default=[1000, 10000])
    parser.add_argument(
        "--extra-particles",
        type=int,
        default=50000,
        help="also this many particles on the first --extra-scans scans of Intel (0: skip)",
    )
    parser.add_argument("--extra-scans", type=int, default=300)
    parser.add_argument("--scans", type=int, default=None, help="only the first N scans of a log")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument(
        "--kiseki-model",
        choices=methods,
        default="beam" if "beam" in methods else "likelihood-field",
        help="kiseki's sensor model (nav2 runs the beam model, the only one amcl exposes)",
    )
    parser.add_argument("--nav2-only", action="store_true", help="skip kiseki")
    parser.add_argument(
        "--quick", action="store_true", help="Intel, first 200 scans, 1000 particles, 60 beams"
    )
    parser.add_argument("--output", type=Path, help="also write the table to this CSV file")
    args = parser.parse_args(argv)
    if args.quick:
        args.logs, args.scans, args.particles, args.beams = ["intel"], 200, [1000], [60]
        args.extra_particles = 0
    few_scans = args.scans is not None and args.scans < 2
    if min(args.beams) < 2 or min(args.particles) < 1 or few_scans:
        parser.error("beams must be >= 2, particles >= 1 and scans >= 2")
    return args


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)  # first: --help and a bad option need no bindings
    if amcl is None:
        print("bench_nav2_amcl: needs the GPL-3.0 nav2 AMCL bindings: pip install amcl")
        return 1
    print(machine_line(), flush=True)
    if not DATA.is_dir():
        print(f"recorded datasets not found at {DATA}: nothing to benchmark")
        return 1
    localize = None if args.nav2_only else kiseki_api()
    if localize is None and not args.nav2_only:
        print("kiseki's localize has no per-update times / threads yet: nav2 AMCL only")
    threads = os.cpu_count() or 1
    runs = []
    for log in args.logs:
        for beams in args.beams:
            for particles in args.particles:
                runs.append((log, beams, particles, args.scans))
            if log == "intel" and args.extra_particles > 0:
                n = args.extra_scans if args.scans is None else min(args.scans, args.extra_scans)
                runs.append((log, beams, args.extra_particles, n))
    print(
        f"nav2 AMCL (amcl {importlib.metadata.version('amcl')}, beam model) beside kiseki "
        f"({'not run' if localize is None else args.kiseki_model}); odometry noise "
        f"{ODOMETRY_NOISE}, seed {args.seed}, every scan an update, resampling every update"
    )
    rows, logs = [], {}
    for log, beams, particles, n in tqdm(runs, desc="runs", unit="run"):
        if log not in logs:
            inputs = load_log(log)
            logs[log] = (inputs, log_odometry(inputs, args.seed), nav2_map(inputs.grid))
        inputs, odom, grid_nav2 = logs[log]
        grid, alphas = inputs.grid, inputs.alphas
        scans = select_scans(inputs.scans, odom, beams, n)
        m = len(scans)
        label = f"{log} {len(scans.angles)} beams {particles} particles"
        est, sec = run_nav2(scans, grid_nav2, odom[:m], alphas, particles, args.seed, label)
        row = dict(log=log, beams=len(scans.angles), particles=particles, scans=m)
        row["nav2_rmse_m"], row["nav2_heading_deg"] = errors(est, scans.poses)
        row["nav2_ms"] = 1000 * float(np.mean(sec))
        for key, t in (("kiseki1", 1), ("kisekiN", threads)):
            if localize is None:
                row[f"{key}_rmse_m"] = row[f"{key}_heading_deg"] = row[f"{key}_ms"] = np.nan
                continue
            est, sec = run_kiseki(
                localize, scans, grid, args.kiseki_model, particles, t, args.seed, alphas
            )
            row[f"{key}_rmse_m"], row[f"{key}_heading_deg"] = errors(est, scans.poses)
            row[f"{key}_ms"] = 1000 * float(np.mean(sec)) if len(sec) else np.nan
        row["ratio_1"] = row["nav2_ms"] / row["kiseki1_ms"]
        row["ratio_N"] = row["nav2_ms"] / row["kisekiN_ms"]
        rows.append(row)
    print()
    print_table(rows, threads)
    if args.output:
        with open(args.output, "w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=COLUMNS)
            writer.writeheader()
            writer.writerows(rows)
        print(f"\ntable written to {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
