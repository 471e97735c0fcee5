# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Ray casting for the beam model, printed, never asserted: rays per second on one core of the
distance-field caster (kiseki's RangeCaster) and the swept-sector caster (SectorCaster) on the
Intel Research Lab map, their ratio and the goal of 25 M rays/s (a beam model 5x nav2's), what
the swept-sector table costs (build seconds, MB), and the time per filter update with the beam
model at 1,000 and 10,000 particles on one thread: the model alone with either caster, and the
whole filter update with either caster beside nav2 AMCL.

Rays: poses uniform over the map's free cells (uniform inside each cell, uniform headings), 360
beams a pose over the full circle, each cast to the log's max range (81.83 m) with nav2's rule
(occupied and unknown cells stop a ray, as the beam model casts). The rays per second are timed
in C++ around the casts only (the casters' ``time_ranges`` and ``scans(timed=True)``; no Python
in the loop), one thread, the median of --repeats runs, by the thread's CPU time (and by wall
time, which on a shared machine also counts other processes). "per ray" is one call per ray with its
heading (``range``); "per scan" casts a pose's beams together as the beam model does
(``scan``: one sine and cosine a pose, 16 rays walked in turns). Both casters' ranges are
compared on every ray (the largest difference is printed).

Filter updates: the first --scans scans of the Intel log, 60 beams (nav2's max_beams), the
settings of benchmarks/bench_nav2_amcl.py (the same map, noisy odometry, initial cloud and
mixture; one update per scan with motion, sensor model and resampling), kiseki on 1 thread.
nav2 AMCL needs the GPL-3.0 ``amcl`` package (``pip install amcl``); without it its column is
left out.

Needs ../shared/data (the recorded datasets). Run: python benchmarks/bench_ray_casting.py
(--quick: fewer poses and scans, 1,000 particles only).
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import statistics
import sys
import time

import numpy as np

import bench_nav2_amcl as nav2_bench  # the side-by-side settings, shared
from amcl_inputs import nav2_beam_indices  # beside this file
from kiseki.datasets import read_carmen_log
from kiseki.filters import (
    LocalizeConfig,
    localize,
    motion_alphas,
    noisy_odometry,
    scan_model,
)
from kiseki.grid import FREE, RangeCaster, SectorCaster
from kiseki.mapping import MapBuildConfig, map_of_log
from timing import machine_line  # beside this file

BUILD_THREADS = os.environ.get("OMP_NUM_THREADS", os.cpu_count())
GOAL = 25e6  # rays/s on one core: a beam model 5x nav2's
BEAMS = 360
LOG = "intel"
FILTER_BEAMS = 60  # nav2's max_beams default


def free_poses(grid, n: int, seed: int) -> np.ndarray:
    """n poses uniform over the free cells (uniform inside each cell), uniform headings."""
    rng = np.random.default_rng(seed)
    free = np.argwhere(np.asarray(grid.cells) == FREE)[:, ::-1]  # (x, y)
    cells = free[rng.integers(0, len(free), n)].astype(float) + rng.random((n, 2))
    xy = np.array([grid.origin.x, grid.origin.y]) + cells * grid.resolution  # not rotated
    return np.column_stack([xy, rng.uniform(-np.pi, np.pi, n)])


def median_rates(timer, rays: int, repeats: int) -> tuple[float, float]:
    """Rays per second by the thread's CPU time and by wall time: the medians over repeats of
    rays / the C++-timed (wall, CPU) seconds."""
    runs = [timer() for _ in range(repeats)]
    return (
        statistics.median(rays / cpu for _, cpu in runs),
        statistics.median(rays / wall for wall, _ in runs),
    )


def ray_table(grid, max_range: float, poses: int, repeats: int, seed: int) -> None:
    p = free_poses(grid, poses, seed)
    angles = np.linspace(-np.pi, np.pi, BEAMS, endpoint=False)
    start = time.perf_counter()
    field = RangeCaster(grid, unknown_stops=True)
    field_build = time.perf_counter() - start
    start = time.perf_counter()
    sector = SectorCaster(grid, unknown_stops=True)
    sector_build = time.perf_counter() - start
    start = time.perf_counter()
    passable = SectorCaster(grid, unknown_stops=False)
    passable_build = time.perf_counter() - start
    want = field.ranges(p, angles, max_range)
    diff = max(
        float(np.abs(sector.ranges(p, angles, max_range) - want).max()),
        float(np.abs(sector.scans(p, angles, max_range) - want).max()),
    )
    rays = len(p) * BEAMS
    old = median_rates(lambda: field.time_ranges(p, angles, max_range), rays, repeats)
    per_ray = median_rates(lambda: sector.time_ranges(p, angles, max_range), rays, repeats)
    per_scan = median_rates(lambda: sector.scans(p, angles, max_range, timed=True), rays, repeats)
    cells = grid.width * grid.height
    print(
        f"Intel map {grid.width} x {grid.height} cells of {grid.resolution} m; {len(p)} poses on "
        f"free cells x {BEAMS} beams = {rays:,} rays to {max_range:.2f} m, one thread, median of "
        f"{repeats}; largest |swept-sector - distance-field| {diff:.1e} m"
    )
    print(f"{'M rays/s on one core':<32}{'CPU time':>10}{'wall':>8}{'x old':>8}{'x 25 M goal':>13}")
    for name, (cpu, wall) in (
        ("distance field (old), per ray", old),
        ("swept sector, per ray", per_ray),
        ("swept sector, per scan", per_scan),
    ):
        print(
            f"{name:<32}{cpu / 1e6:>10.2f}{wall / 1e6:>8.2f}{cpu / old[0]:>8.2f}{cpu / GOAL:>13.2f}"
        )
    print(
        "(CPU time: the thread's own seconds; wall time also counts other processes on the core; "
        "the ratios are of CPU time)"
    )
    print(
        f"\nprecompute: distance field {field_build:.2f} s, {4 * cells / 1e6:.1f} MB (float per "
        f"cell); swept-sector table ({sector.sectors} sectors) {sector_build:.2f} s, "
        f"{sector.memory_bytes / 1e6:.1f} MB; the same with unknown cells passable "
        f"{passable_build:.2f} s, {passable.memory_bytes / 1e6:.1f} MB (built by OpenMP on "
        f"{BUILD_THREADS} threads; OMP_NUM_THREADS sets them)"
    )


def weighing_table(scans, grid, particle_counts, n_scans: int, seed: int) -> None:
    """The beam model alone (kiseki's log_likelihoods, one thread): ms to weigh the particles
    against one scan, each caster, particles spread around each scan's reference pose."""
    idx = nav2_beam_indices(scans.ranges.shape[1], FILTER_BEAMS)
    angles = scans.angles[idx]
    steps = range(0, len(scans), max(1, len(scans) // n_scans))
    print(f"\nbeam model alone, {len(idx)} beams, {len(steps)} scans of the Intel log, 1 thread")
    print(f"{'particles':>10}{'distance field ms':>20}{'swept sector ms':>18}{'x':>7}")
    for particles in particle_counts:
        ms = {}
        for caster in ("distance-field", "swept-sector"):
            config = LocalizeConfig(method="beam", beams=len(idx), caster=caster)
            model = scan_model("beam", grid, config)
            rng = np.random.default_rng(seed)
            took = []
            for k in steps:
                poses = scans.poses[k] + rng.normal(0, [0.2, 0.2, 0.05], (particles, 3))
                model.set_scan(angles, scans.ranges[k, idx], scans.max_range)
                start = time.perf_counter()
                model.log_likelihoods(poses)
                took.append(time.perf_counter() - start)
            ms[caster] = 1000 * statistics.median(took)
        ratio = ms["distance-field"] / ms["swept-sector"]
        print(
            f"{particles:>10}{ms['distance-field']:>20.2f}{ms['swept-sector']:>18.2f}{ratio:>7.2f}"
        )


def update_table(scans, grid, particle_counts, n_scans: int, seed: int) -> None:
    alphas = motion_alphas(LocalizeConfig(odometry_noise=nav2_bench.ODOMETRY_NOISE), scans)
    odom = noisy_odometry(scans.odometry, nav2_bench.ODOMETRY_NOISE, seed)
    idx = nav2_beam_indices(scans.ranges.shape[1], FILTER_BEAMS)
    m = min(n_scans, len(scans))
    part = dataclasses.replace(
        scans,
        times=scans.times[:m],
        poses=scans.poses[:m],
        odometry=odom[:m],
        ranges=np.ascontiguousarray(scans.ranges[:m, idx]),
        angles=scans.angles[idx],
    )
    have_nav2 = nav2_bench.amcl is not None
    grid_nav2 = nav2_bench.nav2_map(grid) if have_nav2 else None
    print(
        f"\nfilter update, beam model, {len(idx)} beams, first {m} scans of the Intel log, 1 "
        f"thread (ms per update, mean; RMSE m against the corrected poses)"
    )
    head = f"{'particles':>10}{'distance field':>22}{'swept sector':>22}"
    print(head + (f"{'nav2 AMCL':>22}{'nav2 / swept':>14}" if have_nav2 else ""))
    same = []  # the largest difference of the two casters' estimates, per particle count
    for particles in particle_counts:
        cells = []
        ms, estimates = {}, {}
        for caster in ("distance-field", "swept-sector"):
            est, sec = nav2_bench.run_kiseki(
                localize, part, grid, "beam", particles, 1, seed, alphas, caster=caster
            )
            ms[caster], estimates[caster] = 1000 * float(np.mean(sec)), est
            rmse, _ = nav2_bench.errors(est, part.poses)
            cells.append(f"{ms[caster]:>12.2f} ({rmse:.3f})")
        same.append(float(np.abs(estimates["swept-sector"] - estimates["distance-field"]).max()))
        row = f"{particles:>10}" + "".join(f"{c:>22}" for c in cells)
        if have_nav2:
            label = f"nav2 {particles}"
            est, sec = nav2_bench.run_nav2(
                part, grid_nav2, odom[:m], alphas, particles, seed, label
            )
            nav2_ms = 1000 * float(np.mean(sec))
            rmse, _ = nav2_bench.errors(est, part.poses)
            row += f"{f'{nav2_ms:.2f} ({rmse:.3f})':>22}{nav2_ms / ms['swept-sector']:>14.2f}"
        print(row)
    print(
        "largest difference of the two casters' estimates (x, y, theta) over every update: "
        + ", ".join(f"{d:.1e}" for d in same)
        + " m (weights equal to rounding: the same filter)"
    )
    if not have_nav2:
        print("(nav2 AMCL not run: pip install amcl)")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--poses", type=int, default=3000, help="poses for the rays per second")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--particles", nargs="+", type=int, default=[1000, 10000])
    parser.add_argument("--scans", type=int, default=100, help="filter updates timed")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--quick", action="store_true", help="500 poses, 30 scans, 1000 particles")
    args = parser.parse_args(argv)
    print(machine_line(), flush=True)
    if args.quick:
        args.poses, args.scans, args.particles = 500, 30, [1000]
    if min(args.poses, args.repeats, args.scans, *args.particles) < 1:
        parser.error("poses, repeats, scans and particles must be >= 1")
    path = nav2_bench.DATA / "carmen" / f"{LOG}-corrected.log.gz"
    if not path.is_file():
        print(f"the Intel log is not at {path}: nothing to benchmark")
        return 1
    scans = read_carmen_log(path).scans
    grid = map_of_log(scans, MapBuildConfig(resolution=0.05))
    ray_table(grid, float(scans.max_range), args.poses, args.repeats, args.seed)
    weighing_table(scans, grid, args.particles, args.scans, args.seed)
    update_table(scans, grid, args.particles, args.scans, args.seed)
    return 0


if __name__ == "__main__":
    sys.exit(main())
