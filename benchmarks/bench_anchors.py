# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""kiseki beside its anchors, nav2 AMCL and beluga, built from their own unmodified C++ sources
and run on the same inputs (printed, never asserted): time per filter update and position RMSE
against the Intel log's corrected poses, for each particle count, beam count and thread count.

The anchors' sources are read from the sibling folder ../shared/anchors of the repository root
(nav2_amcl/, beluga/, sophus/; the commits are in its README.md) or from --anchors DIR; without
them the script prints one line and exits 0. benchmarks/anchors/ holds the three C++ harnesses
and their CMake project, built in build/anchors (Release, -O3 -DNDEBUG, kiseki's own flags; a
second run reuses the build): nav2_harness (nav2_amcl's pf, map, motion and laser models; ROS's
pluginlib header replaced by a stand-in), beluga_harness (beluga::Amcl of the header-only core
over Eigen, Sophus, range-v3, TBB) and kiseki_harness (kiseki_core built from cpp/). kiseki is
never a dependency of the anchors' harnesses and their code is never part of kiseki.

Every library gets the same map (built from the log at 0.05 m), the same scans with the same
beams (nav2's max_beams rule; 360 on a 180-beam log is every beam), the same noisy odometry
(seeded; one odometry per seed, the same for all), the same particle count, initial cloud and
parameters (printed), the likelihood field (or, with --models beam, the beam model), every scan
an update, resampling (multinomial, as nav2 and beluga) at every update, a fixed particle count
and no recovery. Each harness times only the library's update calls, with one clock, in C++:
nav2 odometryUpdate + sensorUpdate + pf_update_resample, beluga Amcl::update, kiseki
MonteCarloLocalization::predict + update. nav2 has no threads: its one-thread time stands in
its rows of more threads (marked *). RMSE is the mean over the seeds with a 95% Student-t
interval; kiseki runs both nav2's beam combination (1 + sum pz^3, the anchors' only one) and its
default, the product of the beams.

What differs by design, not by setting: nav2's likelihood field scores a beam z_hit
exp(-d^2 / 2 sigma^2) + z_rand / max_range, beluga's divides the Gaussian by sqrt(2 pi) sigma
(an amplitude of 0.997 against nav2's 0.5 here); kiseki scores as nav2 with nav2's combination
and with the normalised Gaussian (Probabilistic Robotics, Table 6.3) with the product. beluga's
beam model sums pz^3 from 0, nav2's from 1. nav2's estimate is its heaviest cluster's mean (the
pose its node publishes), beluga's the weighted mean Amcl::update returns, kiseki's the weighted
mean before resampling (what kiseki.filters.localize reports).

Needs ../shared/data (the recorded datasets). Run: python benchmarks/bench_anchors.py
(by default the first 300 scans, 5 seeds, 1,000 / 10,000 / 50,000 particles, 60 and 360 beams,
1 and 2 threads; --quick: a smoke run; --help for the options).
"""

from __future__ import annotations

import argparse
import csv
import re
import sys
import tempfile
from pathlib import Path

import numpy as np
from scipy import stats
from tqdm import tqdm

from amcl_inputs import (  # beside this file
    DATA,
    INITIAL_SD,
    LAMBDA_SHORT,
    LIKELIHOOD_MAX_DIST,
    MAP_RESOLUTION,
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
from anchors_harness import (  # beside this file
    ANCHORS,
    BUILD,
    HarnessError,
    HarnessInput,
    anchors_present,
    build,
    run_harness,
    write_input,
)
from kiseki.core import derive_seed
from kiseki.metrics import ape
from timing import machine_line  # beside this file

LOG = "intel"
# (library, its harness, beam combination); the rows of one particle and thread count
RUNS = (
    ("nav2", "nav2_harness", "nav2"),
    ("beluga", "beluga_harness", "nav2"),
    ("kiseki", "kiseki_harness", "nav2"),
    ("kiseki_product", "kiseki_harness", "product"),
)
LIBRARIES = tuple(name for name, _, _ in RUNS)


def harness_input(scans, grid, alphas) -> HarnessInput:
    """The harnesses' input for one log slice, beam choice and odometry."""
    if abs(grid.origin.theta) > 1e-12:
        raise ValueError("the harnesses take maps without rotation")
    parameters = dict(
        z_hit=Z_HIT,
        z_rand=Z_RAND,
        sigma_hit=SIGMA_HIT,
        likelihood_max_dist=LIKELIHOOD_MAX_DIST,
        z_short=Z_SHORT,
        z_max=Z_MAX,
        lambda_short=LAMBDA_SHORT,
        alpha1=alphas[0],
        alpha2=alphas[1],
        alpha3=alphas[2],
        alpha4=alphas[3],
        initial_x=scans.poses[0, 0],
        initial_y=scans.poses[0, 1],
        initial_theta=scans.poses[0, 2],
        initial_sd_x=INITIAL_SD[0],
        initial_sd_y=INITIAL_SD[1],
        initial_sd_theta=INITIAL_SD[2],
    )
    return HarnessInput(
        cells=np.asarray(grid.cells, dtype=np.int8),
        resolution=float(grid.resolution),
        origin=(float(grid.origin.x), float(grid.origin.y)),
        max_range=float(scans.max_range),
        angles=np.asarray(scans.angles, dtype=np.float64),
        ranges=np.asarray(scans.ranges, dtype=np.float32),
        odometry=np.asarray(scans.odometry, dtype=np.float64),
        parameters=parameters,
    )


def kiseki_engine_seed(seed: int) -> int:
    """The engine seed kiseki.filters.localize uses for a run seed, so that the harness and the
    Python API give the same particles."""
    return derive_seed(seed, 2)


def interval(values: list[float]) -> tuple[float, float]:
    """Mean and the half-width of its 95% Student-t interval (NaN for one value)."""
    v = np.asarray(values, dtype=float)
    if len(v) < 2:
        return float(v.mean()), float("nan")
    half = stats.t.ppf(0.975, len(v) - 1) * v.std(ddof=1) / np.sqrt(len(v))
    return float(v.mean()), float(half)


def anchor_commits(anchors: Path) -> dict[str, str]:
    """The anchors' commits as their README.md lists them (folder -> commit)."""
    commits = {}
    readme = anchors / "README.md"
    text = readme.read_text() if readme.exists() else ""
    for folder in ("nav2_amcl", "beluga", "sophus"):
        found = re.search(rf"`{folder}/`[^\n]*?\b([0-9a-f]{{40}})\b", text)
        commits[folder] = found.group(1) if found else "unknown commit"
    return commits


def build_flags(build_dir: Path) -> str:
    cache = build_dir / "CMakeCache.txt"
    text = cache.read_text() if cache.exists() else ""
    found = re.search(r"^CMAKE_CXX_FLAGS_RELEASE:\w+=(.*)$", text, re.M)
    compiler = re.search(r"^CMAKE_CXX_COMPILER:\w+=(.*)$", text, re.M)
    flags = found.group(1) if found else "?"
    return f"{Path(compiler.group(1)).name if compiler else 'c++'} Release {flags}"


def print_settings(args, alphas, scans, commits, flags) -> None:
    print(
        f"anchors: nav2_amcl {commits['nav2_amcl'][:12]}, "
        f"beluga {commits['beluga'][:12]} (Sophus {commits['sophus'][:12]}); built with {flags}"
    )
    print(
        f"input: {LOG} log, {scans} scans, map {MAP_RESOLUTION} m, odometry noise "
        f"{ODOMETRY_NOISE} (seeds {', '.join(map(str, args.seed_list))}), every scan an update, "
        "multinomial resampling at every update, fixed particle count, no recovery"
    )
    print(
        f"parameters: z_hit {Z_HIT}, z_rand {Z_RAND}, sigma_hit {SIGMA_HIT} m, "
        f"laser_likelihood_max_dist {LIKELIHOOD_MAX_DIST} m, laser max range = the log's; "
        f"beam model: z_short {Z_SHORT}, z_max {Z_MAX}, lambda_short {LAMBDA_SHORT}; "
        f"alpha1..4 {', '.join(f'{a:.4g}' for a in alphas)}; initial SD "
        f"{INITIAL_SD[0]} m, {INITIAL_SD[1]} m, {np.degrees(INITIAL_SD[2]):.0f} deg"
    )


def fmt(value: float, spec: str) -> str:
    """`value` formatted, or "-" as wide when it is NaN (not run)."""
    return format(value, spec) if np.isfinite(value) else f"{'-':>{len(format(0.0, spec))}}"


def fmt_ratio(value: float, width: int) -> str:
    return f"{fmt(value, '.2f') + ('x' if np.isfinite(value) else ''):>{width}}"


def fmt_rmse(mean: float, half: float) -> str:
    if not np.isfinite(mean):
        return "-"
    return f"{mean:.3f}+-{fmt(half, '.3f')}"


def print_table(rows: list[dict]) -> None:
    head = (
        f"{'particles':>9} {'thr':>3} | {'nav2 ms':>9} {'beluga ms':>9} {'kiseki ms':>9} | "
        f"{'nav2/kiseki':>11} {'beluga/kiseki':>13} | "
        f"{'RMSE m: nav2':>14} {'beluga':>13} {'kiseki':>13} {'kiseki prod':>13}"
    )
    for key in dict.fromkeys((r["model"], r["beams"]) for r in rows):
        print(f"\n{key[0]}, {key[1]} beams (time per update; RMSE mean +- 95% interval)")
        print(head)
        print("-" * len(head))
        for r in (r for r in rows if (r["model"], r["beams"]) == key):
            star = "*" if r["threads"] > 1 else " "
            print(
                f"{r['particles']:>9} {r['threads']:>3} | {fmt(r['nav2_ms'], '8.2f')}{star} "
                f"{fmt(r['beluga_ms'], '9.2f')} {fmt(r['kiseki_ms'], '9.2f')} | "
                f"{fmt_ratio(r['nav2_over_kiseki'], 11)} {fmt_ratio(r['beluga_over_kiseki'], 13)}"
                " | "
                + " ".join(
                    f"{fmt_rmse(r[f'{lib}_rmse_m'], r[f'{lib}_rmse_ci']):>13}" for lib in LIBRARIES
                )
            )
    print("* nav2 is single-threaded: its one-thread time and RMSE")


def plot(rows: list[dict], path: Path) -> None:
    """Time per update against particles, log-log, one line per library and thread count."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    keys = list(dict.fromkeys((r["model"], r["beams"]) for r in rows))
    fig, axes = plt.subplots(1, len(keys), figsize=(6 * len(keys), 4.5), squeeze=False)
    for ax, key in zip(axes[0], keys, strict=True):
        sub = [r for r in rows if (r["model"], r["beams"]) == key]
        threads = sorted({r["threads"] for r in sub})
        lines = [("nav2", 1)] + [(lib, t) for lib in ("beluga", "kiseki") for t in threads]
        colours = {"nav2": "tab:blue", "beluga": "tab:orange", "kiseki": "tab:green"}
        for lib, t in lines:
            pts = sorted(
                (r["particles"], r[f"{lib}_ms"])
                for r in sub
                if r["threads"] == t and np.isfinite(r[f"{lib}_ms"])
            )
            if pts:
                x, y = zip(*pts, strict=True)
                label = f"{lib}, {t} thread{'s' if t > 1 else ''}"
                style = "-" if t == 1 else ("--", ":", "-.")[min(2, threads.index(t) - 1)]
                ax.plot(x, y, marker="o", linestyle=style, color=colours[lib], label=label)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("particles")
        ax.set_ylabel("time per update (ms)")
        ax.set_title(f"{LOG}, {key[0]}, {key[1]} beams")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--anchors", type=Path, default=ANCHORS, help="the anchors' sources")
    parser.add_argument("--build-dir", type=Path, default=BUILD)
    parser.add_argument("--particles", nargs="+", type=int, default=[1000, 10000, 50000])
    parser.add_argument("--beams", nargs="+", type=int, default=[60, 360])
    parser.add_argument("--threads", nargs="+", type=int, default=[1, 2])
    parser.add_argument("--seeds", type=int, default=5, help="seeds 0 .. N-1")
    parser.add_argument(
        "--scans", type=int, default=300, help="the first N scans of the log (0: all 910)"
    )
    parser.add_argument(
        "--nav2-max-particles",
        type=int,
        default=50000,
        help="run nav2 only up to this many particles (its resampler is quadratic in them: a "
        "linear search of the cumulative weights per particle, ~1.2 s per update at 50,000)",
    )
    parser.add_argument(
        "--models", nargs="+", choices=("likelihood-field", "beam"), default=["likelihood-field"]
    )
    parser.add_argument(
        "--quick",
        action="store_true",
        help="smoke run: 1000 particles, 60 beams, 100 scans, 2 seeds",
    )
    parser.add_argument("--output", type=Path, help="also write the table to this CSV file")
    parser.add_argument("--plot", type=Path, help="also plot time per update to this PNG")
    args = parser.parse_args(argv)
    if args.quick:
        args.particles, args.scans, args.seeds, args.beams = [1000], 100, 2, [60]
    if min(args.particles) < 1 or min(args.beams) < 2 or min(args.threads) < 1:
        parser.error("particles and threads must be >= 1 and beams >= 2")
    if args.seeds < 1 or args.scans == 1 or args.scans < 0:
        parser.error("seeds must be >= 1 and scans >= 2 (0: all)")
    args.scans = args.scans or None
    args.seed_list = list(range(args.seeds))
    args.threads = sorted(set(args.threads))
    return args


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    if not anchors_present(args.anchors):
        print(f"bench_anchors: the anchors' sources are not at {args.anchors}: skipped")
        return 0
    if not DATA.is_dir():
        print(f"recorded datasets not found at {DATA}: nothing to benchmark")
        return 1
    try:
        exe = build(args.anchors, args.build_dir)
    except HarnessError as e:
        print(f"bench_anchors: {e}")
        return 1
    print(machine_line(), flush=True)  # after the skips: a skip is one line
    inputs = load_log(LOG)
    n_scans = len(inputs.scans) if args.scans is None else min(args.scans, len(inputs.scans))
    print_settings(
        args, inputs.alphas, n_scans, anchor_commits(args.anchors), build_flags(args.build_dir)
    )
    settings = [
        (model, beams, particles, threads)
        for model in args.models
        for beams in args.beams
        for particles in args.particles
        for threads in args.threads
    ]
    # (setting, library) -> per seed: RMSE and mean time per update
    rmse: dict = {}
    ms: dict = {}
    beams_used = {}
    total = len(args.seed_list) * len(settings) * len(RUNS)
    with tempfile.TemporaryDirectory() as tmp, tqdm(total=total, unit="run") as bar:
        for seed in args.seed_list:
            odom = log_odometry(inputs, seed)
            for beams in args.beams:
                scans = select_scans(inputs.scans, odom, beams, n_scans)
                beams_used[beams] = len(scans.angles)
                path = Path(tmp) / f"input_{beams}.bin"
                write_input(path, harness_input(scans, inputs.grid, inputs.alphas))
                for setting in (s for s in settings if s[1] == beams):
                    model, _, particles, threads = setting
                    for lib, harness, combination in RUNS:
                        bar.set_description(f"seed {seed} {beams} beams {particles} {lib}")
                        bar.update()
                        if lib == "nav2" and (threads > 1 or particles > args.nav2_max_particles):
                            continue  # single-threaded (its one-thread run stands in)
                        run_seed = kiseki_engine_seed(seed) if harness == "kiseki_harness" else seed
                        try:
                            est, sec = run_harness(
                                exe[harness], path, Path(tmp) / "out.bin", particles, run_seed,
                                threads, model, combination,
                            )  # fmt: skip
                        except HarnessError as e:
                            print(f"\nbench_anchors: {e}")
                            return 1
                        rmse.setdefault((setting, lib), []).append(
                            float(ape(est, scans.poses).rmse)
                        )
                        ms.setdefault((setting, lib), []).append(1000 * float(np.mean(sec)))
    rows = []
    for setting in settings:
        model, beams, particles, threads = setting
        row = dict(
            model=model, beams=beams_used[beams], particles=particles, threads=threads,
            scans=n_scans, seeds=len(args.seed_list),
        )  # fmt: skip
        row["nav2_threads"] = 1
        for lib in LIBRARIES:
            key = (setting if lib != "nav2" else (model, beams, particles, 1), lib)
            if key not in ms:  # nav2 above --nav2-max-particles
                row[f"{lib}_ms"] = row[f"{lib}_rmse_m"] = row[f"{lib}_rmse_ci"] = float("nan")
                continue
            row[f"{lib}_ms"] = float(np.mean(ms[key]))
            row[f"{lib}_rmse_m"], row[f"{lib}_rmse_ci"] = interval(rmse[key])
        row["nav2_over_kiseki"] = row["nav2_ms"] / row["kiseki_ms"]
        row["beluga_over_kiseki"] = row["beluga_ms"] / row["kiseki_ms"]
        rows.append(row)
    print_table(rows)
    if args.output:
        with open(args.output, "w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=list(rows[0]))
            writer.writeheader()
            writer.writerows(rows)
        print(f"table written to {args.output}")
    if args.plot:
        plot(rows, args.plot)
        print(f"plot written to {args.plot}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
