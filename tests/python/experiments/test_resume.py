# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Resuming an experiment run: after a real kill it equals an uninterrupted run, and with
--runs N it extends the run to what a fresh run of N trials gives."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import pandas as pd
import yaml

from _helpers.experiment_runs import cli, frame
from kiseki_experiments.harness.runner import run_experiment


def test_resume_after_kill_equals_an_uninterrupted_run(tmp_path):
    args = [
        sys.executable,
        "-m",
        "kiseki.cli",
        "experiment",
        "run",
        "corridor-scans",
        "--runs",
        "6",
        "--set",
        "scan_spacing=0.03",
    ]  # about a second per trial (0.4 s at the default 0.1 m: the kill could miss the run);
    # resume's equality does not depend on the scans per trial: a third as many as at 0.01 m
    proc = subprocess.Popen(
        [*args, "--out", "killed"],
        cwd=tmp_path,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    log = tmp_path / "killed" / "trials.jsonl"
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline:
        if log.exists() and len(log.read_bytes().splitlines()) >= 2:
            break
        time.sleep(0.02)
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    finished = len(log.read_bytes().splitlines())
    assert 2 <= finished < 6, "the kill must land mid-run"
    assert not (tmp_path / "killed" / "trials.parquet").exists()
    resumed = subprocess.run(
        [*args[:4], "run", "corridor-scans", "--resume", "--out", "killed"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
    )
    assert resumed.returncode == 0, resumed.stderr
    assert f"{6 - finished} run now" in resumed.stdout.replace("\n", " ")
    # the uninterrupted reference is not about the process: run in-process, as the command does
    full = run_experiment(
        "corridor-scans", runs=6, overrides=[args[-1]], out=tmp_path / "full", progress=False
    )
    assert full.failed == 0
    pd.testing.assert_frame_equal(frame(tmp_path / "killed"), frame(tmp_path / "full"))


def test_resume_with_more_runs_extends_a_run_to_what_a_fresh_run_gives(tmp_path):
    args = ["experiment", "run", "corridor-scans", "--set", "scan_spacing=0.3"]
    first = cli(*args, "--runs", "2", "--out", "grown", cwd=tmp_path)
    assert first.returncode == 0, first.stderr
    grown = cli(*args[:3], "--resume", "--runs", "4", "--out", "grown", cwd=tmp_path)
    assert grown.returncode == 0, grown.stderr
    assert "2 run now" in grown.stdout.replace("\n", " ")
    fresh = run_experiment(
        "corridor-scans", runs=4, overrides=[args[-1]], out=tmp_path / "fresh", progress=False
    )
    assert fresh.failed == 0
    pd.testing.assert_frame_equal(frame(tmp_path / "grown"), frame(tmp_path / "fresh"))
    saved = yaml.safe_load((tmp_path / "grown" / "config.yaml").read_text())
    assert saved["runs"] == 4  # a later --resume continues the run of 4
    # fewer trials than the run holds would drop finished ones: refused in one line
    fewer = cli(*args[:3], "--resume", "--runs", "3", "--out", "grown", cwd=tmp_path)
    assert fewer.returncode == 1
    lines = fewer.stderr.strip().splitlines()
    assert len(lines) == 1 and "would drop trials: the run has 4" in lines[0], fewer.stderr
