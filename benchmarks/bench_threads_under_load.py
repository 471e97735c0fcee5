# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Threads on a busy machine, printed, never asserted: the Monte Carlo engine's update
(likelihood field, 360 beams, Freiburg 079) on one thread and on two, with the machine free
and with other processes keeping the cores busy (a robot's usual state), under OpenMP's
waiting policies. Each setting runs in its own process, because libgomp reads
OMP_WAIT_POLICY once, when it is loaded.

The load: ``--busy`` processes that each run the same engine on two threads in a loop (another
OpenMP program, as a second localizer or a planner on the robot would be): with the default
policy their workers spin between parallel regions and take the cores' time slices. Goal: two
threads never slower than one under the load, and at least 1.7x one with the machine free at
50,000 particles. Beside them the engine's default, threads 0: every core, or one thread while
one is measured faster (its ThreadChooser times the updates with each).

Run: python benchmarks/bench_threads_under_load.py [--scans 15] [--busy 2]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

from timing import machine_line  # beside this file

# workers that spin between parallel regions (as libgomp's default does for its first 300,000
# spins; ACTIVE keeps spinning) and kiseki's default (PASSIVE, set when kiseki is imported)
POLICIES = {"spinning": "ACTIVE", "kiseki": None}
SCRIPT = Path(__file__).resolve()


def child(particles: int, threads: int, scans: int, forever: bool) -> None:
    """In a fresh process (libgomp reads the policy when it loads): bench_mcl's update timing,
    printed as one number; or, as a load, the same updates for ever."""
    sys.path.insert(0, str(SCRIPT.parent))
    from bench_mcl import LOG, time_updates
    from kiseki.datasets import read_carmen_log
    from kiseki.mapping import MapBuildConfig, map_of_log

    log = read_carmen_log(LOG).scans
    grid = map_of_log(log, MapBuildConfig(0.05))
    while True:
        ms = time_updates(log, grid, "likelihood-field", particles, 360, threads, scans)
        if not forever:
            print(json.dumps(ms))
            return


def _environment(policy: str) -> dict:
    env = dict(os.environ)
    env.pop("OMP_WAIT_POLICY", None)
    if POLICIES[policy] is not None:
        env["OMP_WAIT_POLICY"] = POLICIES[policy]
    return env


def _child_args(particles: int, threads: int, scans: int, forever: bool = False) -> list[str]:
    args = [sys.executable, str(SCRIPT), "--child", str(particles), str(threads), str(scans)]
    return args + (["--forever"] if forever else [])


def measure(policy: str, particles: int, threads: int, scans: int) -> float:
    args = _child_args(particles, threads, scans)
    done = subprocess.run(args, capture_output=True, text=True, env=_environment(policy))
    if done.returncode != 0:
        raise SystemExit(done.stderr.strip().splitlines()[-1])
    return float(json.loads(done.stdout.strip().splitlines()[-1]))


def start_load(count: int, particles: int) -> list[subprocess.Popen]:
    """`count` processes each running the engine on two threads with spinning workers, in a
    loop: another OpenMP program whose workers spin between its parallel regions."""
    args, spinning = _child_args(particles, 2, 50, forever=True), _environment("spinning")
    procs = [subprocess.Popen(args, env=spinning, stdout=subprocess.DEVNULL) for _ in range(count)]
    time.sleep(8.0)  # their maps are built and their loops running
    return procs


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scans", type=int, default=15, help="updates timed per setting")
    parser.add_argument("--busy", type=int, default=2, help="loading processes")
    parser.add_argument("--particles", type=int, nargs="+", default=[1000, 10_000, 50_000])
    # a process this script starts: --child PARTICLES THREADS SCANS [--forever]
    parser.add_argument("--child", type=int, nargs=3, help=argparse.SUPPRESS)
    parser.add_argument("--forever", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    print(machine_line(), flush=True)
    if args.child:
        child(*args.child, args.forever)
        return
    sys.path.insert(0, str(SCRIPT.parent))
    from bench_mcl import LOG

    if not LOG.is_file():
        print(f"the Freiburg-079 log is not at {LOG}: skipped")
        return
    print(f"cores: {os.cpu_count()}; load: {args.busy} processes running the engine on 2 threads")
    print(f"{'machine':<8}{'policy':<9}{'particles':>10}{'1 thread ms':>13}{'2 threads ms':>14}"
          f"{'1 / 2':>7}{'chosen ms':>11}{'1 / chosen':>12}")  # fmt: skip
    for machine in ("free", "busy"):
        procs = start_load(args.busy, 10_000) if machine == "busy" else []
        try:
            for policy in POLICIES:
                for n in args.particles:
                    one = measure(policy, n, 1, args.scans)
                    two = measure(policy, n, 2, args.scans)
                    chosen = measure(policy, n, 0, args.scans)
                    print(f"{machine:<8}{policy:<9}{n:>10}{one:>13.2f}{two:>14.2f}"
                          f"{one / two:>7.2f}{chosen:>11.2f}{one / chosen:>12.2f}",
                          flush=True)  # fmt: skip
        finally:
            for p in procs:
                p.kill()
                p.wait()


if __name__ == "__main__":
    main()
