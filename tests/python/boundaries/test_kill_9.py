# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""kill -9 at seeded random points of a teaching run and of an experiment sweep: what was
taught or finished before the kill is kept, and `--resume` goes on to the uninterrupted result."""

from __future__ import annotations

import signal
import subprocess
import time

import numpy as np

from _helpers.injection import (
    CHUNK,
    KISEKI,
    SWEEP,
    TIMEOUT,
    check_taught_prefix,
    digests,
    same_results,
)


def test_kill_9_while_teaching_keeps_the_steps_taught(tmp_path, scene, taught):
    # killed once the log has grown to a seeded share of the uninterrupted run's log
    size = (taught["folder"] / "teach.mcap").stat().st_size
    share = np.random.default_rng(11).uniform(0.1, 0.8)
    cli = [*KISEKI.split(), "teach", str(scene), "-o", str(tmp_path / "t"), "--seed", "0"]
    proc = subprocess.Popen(cli, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    log = tmp_path / "t" / "teach.mcap"
    deadline = time.monotonic() + 120
    while proc.poll() is None and time.monotonic() < deadline:
        if log.exists() and log.stat().st_size >= share * size:
            break
        time.sleep(0.01)
    assert proc.poll() is None, "the teaching run ended before the kill point"
    proc.kill()
    assert proc.wait() == -signal.SIGKILL  # killed mid-run, not finished
    killed = digests(tmp_path / "t")
    assert list(killed) == ["teach.mcap"]
    # --resume takes the seed the log records (--seed does not apply with it)
    resume = [*cli[: cli.index("--seed")], "--resume"]
    done = subprocess.run(resume, capture_output=True, text=True, timeout=TIMEOUT)
    assert done.returncode == 0, done.stderr
    assert digests(tmp_path / "t")["teach.mcap"] == killed["teach.mcap"]
    n = check_taught_prefix(tmp_path / "t", done.stdout, taught)
    assert n * size / taught["steps"] >= share * size - 2 * CHUNK


def test_kill_9_in_an_experiment_sweep_keeps_the_finished_trials(tmp_path, swept):
    # killed a seeded share of a trial after a seeded number of trials has finished
    rng = np.random.default_rng(23)
    after, share = int(rng.integers(1, 4)), rng.uniform(0.0, 1.0)
    import pandas as pd

    per_trial = pd.read_parquet(swept / "timings.parquet")["trial_seconds"].mean()
    cli = [*KISEKI.split(), "experiment", "run"]
    proc = subprocess.Popen(
        [*cli, *SWEEP, "--out", str(tmp_path / "e")],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    log = tmp_path / "e" / "trials.jsonl"
    deadline = time.monotonic() + 120
    while proc.poll() is None and time.monotonic() < deadline:
        if log.exists() and log.read_bytes().count(b"\n") >= after:
            time.sleep(share * per_trial)
            break
        time.sleep(0.005)
    assert proc.poll() is None, "the sweep ended before the kill point"
    proc.kill()
    assert proc.wait() == -signal.SIGKILL
    kept = log.read_bytes()
    finished = kept.count(b"\n")
    assert after <= finished <= 4
    resumed = subprocess.run(
        [*cli, "corridor-scans", "--resume", "--out", str(tmp_path / "e")],
        capture_output=True,
        text=True,
        timeout=TIMEOUT,
    )
    assert resumed.returncode == 0, resumed.stderr
    assert f"({4 - finished} run now" in " ".join(resumed.stdout.split())  # rich wraps at 80
    assert log.read_bytes().startswith(kept)  # the finished trials kept as they were
    same_results(tmp_path / "e", swept)
