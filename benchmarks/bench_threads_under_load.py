# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Threads on a busy machine, printed, never asserted: the Monte Carlo engine's update
(likelihood field, 360 beams, Freiburg 079) on one thread, on two, and on the engine's default
(threads 0: every core, or one thread while one is measured faster, by its ThreadChooser), with
the machine free and with other processes keeping the cores busy (a robot's usual state), under
OpenMP's waiting policies. Each policy runs in its own process, because libgomp reads
OMP_WAIT_POLICY once, when it is loaded.

The load: ``--busy`` processes that each run the same engine on two threads in a loop (another
OpenMP program, as a second localizer or a planner on the robot would be): with the default
policy their workers spin between parallel regions and take the cores' time slices.

Paired: the three settings are three localizers in one process, each updated on the same scan
in turn (the order rotating scan by scan), so that each scan's three times share the load of
that moment; a load that comes and goes then moves all three, not one setting's median. Per
setting the geometric mean of the per-scan time ratio against one thread, with a 95 % bootstrap
interval over the scans (seed 0), after ``--warm-up`` updates (the chooser tries both thread
counts first).

Criterion, fixed before the runs: "two threads never slower than one" holds for a setting where
the interval's upper end is at most 1.05 (slower by 5 % at most), fails where its lower end
exceeds 1.05, and is undecided otherwise. Control: the same rule applied to the fixed two
threads against spinning workers, where two threads are known to be several times slower, must
say "fails". The other goal: two threads at least 1.7x one at 50,000 particles, machine free.

Run: python benchmarks/bench_threads_under_load.py [--scans 200] [--busy 2]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from timing import machine_line  # beside this file

# workers that spin between parallel regions (as libgomp's default does for its first 300,000
# spins; ACTIVE keeps spinning) and kiseki's default (PASSIVE, set when kiseki is imported)
POLICIES = {"spinning": "ACTIVE", "kiseki": None}
SCRIPT = Path(__file__).resolve()


SETTINGS = {"one": 1, "two": 2, "chosen": 0}  # the localizers' threads (0: the engine's choice)
BAND = 1.05  # "not slower": the time ratio's interval ends at most 5 % above one thread's


def child(particles: int, scans: int, forever: bool) -> None:
    """In a fresh process (libgomp reads the policy when it loads): the three settings' update
    times (ms) on the same scans in turn, printed as one JSON object; or, as a load, two
    threads' updates for ever."""
    sys.path.insert(0, str(SCRIPT.parent))
    from bench_mcl import LOG
    from kiseki.datasets import read_carmen_log
    from kiseki.filters import LocalizeConfig, MclConfig, MonteCarloLocalizer, scan_model
    from kiseki.mapping import MapBuildConfig, map_of_log

    log = read_carmen_log(LOG).scans
    grid = map_of_log(log, MapBuildConfig(0.05))
    names = ["two"] if forever else list(SETTINGS)
    filters, models = {}, {}
    for name in names:
        config = MclConfig(particles=particles, threads=SETTINGS[name], resample_threshold=1.0)
        filters[name] = MonteCarloLocalizer(config, 0, grid)
        filters[name].initialize(log.poses[0], (0.1, 0.1, 0.05))
        models[name] = scan_model("likelihood-field", grid, LocalizeConfig(beams=360))
    times = {name: [] for name in names}
    k = 0
    while forever or k < scans:
        order = names[k % len(names) :] + names[: k % len(names)]
        scan = k % len(log)
        for name in order:
            start = time.perf_counter()
            models[name].set_scan(log.angles, log.ranges[scan], log.max_range)
            filters[name].step(log.poses[scan], lambda m=models[name]: m)
            times[name].append(1000.0 * (time.perf_counter() - start))
        k += 1
    print(json.dumps(times))


def ratio_interval(ratios: np.ndarray, draws: int = 2000) -> tuple[float, float, float]:
    """The geometric mean of per-scan time ratios and its 95 % bootstrap interval (seed 0)."""
    logs = np.log(ratios)
    rng = np.random.default_rng(0)
    means = logs[rng.integers(0, len(logs), (draws, len(logs)))].mean(axis=1)
    lo, hi = np.quantile(means, [0.025, 0.975])
    return float(np.exp(logs.mean())), float(np.exp(lo)), float(np.exp(hi))


def verdict(lo: float, hi: float) -> str:
    """The criterion above: holds, fails or undecided against BAND."""
    return "holds" if hi <= BAND else "fails" if lo > BAND else "undecided"


def _environment(policy: str) -> dict:
    """The environment of a policy: "kiseki" is kiseki's own settings (none of the user's)."""
    env = dict(os.environ)
    env.pop("OMP_WAIT_POLICY", None)
    env.pop("GOMP_SPINCOUNT", None)
    if POLICIES[policy] is not None:
        env["OMP_WAIT_POLICY"] = POLICIES[policy]
    return env


def _child_args(particles: int, scans: int, forever: bool = False) -> list[str]:
    args = [sys.executable, str(SCRIPT), "--child", str(particles), str(scans)]
    return args + (["--forever"] if forever else [])


def measure(policy: str, particles: int, scans: int) -> dict[str, np.ndarray]:
    args = _child_args(particles, scans)
    done = subprocess.run(args, capture_output=True, text=True, env=_environment(policy))
    if done.returncode != 0:
        raise SystemExit(done.stderr.strip().splitlines()[-1])
    times = json.loads(done.stdout.strip().splitlines()[-1])
    return {name: np.asarray(t) for name, t in times.items()}


def start_load(count: int, particles: int) -> list[subprocess.Popen]:
    """`count` processes each running the engine on two threads with spinning workers, in a
    loop: another OpenMP program whose workers spin between its parallel regions."""
    args, spinning = _child_args(particles, 0, forever=True), _environment("spinning")
    procs = [subprocess.Popen(args, env=spinning, stdout=subprocess.DEVNULL) for _ in range(count)]
    time.sleep(8.0)  # their maps are built and their loops running
    return procs


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scans", type=int, default=200, help="updates timed per setting")
    parser.add_argument("--warm-up", type=int, default=10, help="first updates not counted")
    parser.add_argument("--busy", type=int, default=2, help="loading processes")
    parser.add_argument("--particles", type=int, nargs="+", default=[1000, 10_000, 50_000])
    # a process this script starts: --child PARTICLES SCANS [--forever]
    parser.add_argument("--child", type=int, nargs=2, help=argparse.SUPPRESS)
    parser.add_argument("--forever", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    print(machine_line(), flush=True)
    if args.child:
        child(*args.child, args.forever)
        return
    if args.scans < 10 or not 0 <= args.warm_up < args.scans:
        parser.error("--scans must be at least 10 and --warm-up in 0..scans-1")
    sys.path.insert(0, str(SCRIPT.parent))
    from bench_mcl import LOG

    if not LOG.is_file():
        print(f"the Freiburg-079 log is not at {LOG}: skipped")
        return
    print(
        f"cores: {os.cpu_count()}; load: {args.busy} processes running the engine on 2 threads;"
        f" {args.scans - args.warm_up} paired updates per row after {args.warm_up}"
    )
    print(
        "ms per update, median: one / two / chosen; time ratios against one thread: geometric "
        "mean [95 % interval] and the verdict of 'not slower than one' (at most 1.05x)"
    )
    for machine in ("free", "busy"):
        procs = start_load(args.busy, 10_000) if machine == "busy" else []
        try:
            for policy in POLICIES:
                for n in args.particles:
                    t = {k: v[args.warm_up :] for k, v in measure(policy, n, args.scans).items()}
                    medians = " / ".join(f"{np.median(t[k]):.2f}" for k in SETTINGS)
                    cells = []
                    for name in ("two", "chosen"):
                        g, lo, hi = ratio_interval(t[name] / t["one"])
                        cells.append(f"{name} {g:.2f}x [{lo:.2f}, {hi:.2f}] {verdict(lo, hi)}")
                    print(f"{machine:<5} {policy:<9} {n:>7}: {medians} ms; " + "; ".join(cells),
                          flush=True)  # fmt: skip
        finally:
            for p in procs:
                p.kill()
                p.wait()


if __name__ == "__main__":
    main()
