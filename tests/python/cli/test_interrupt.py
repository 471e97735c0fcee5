# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Ctrl-C and SIGTERM during long commands (issue 17 item 4): one line saying what was written
completely before the interruption, exit 130 / 143, nothing partial left, and an interrupted
experiment resumes where it stopped."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from kiseki._support.interrupt import left_behind


def test_the_line_lists_what_was_written_or_says_nothing_was():
    assert left_behind([]) == (
        "kiseki: interrupted before any output was written (no partial file is left)"
    )
    two = [Path("a/map.pgm"), Path("a/map.yaml")]
    assert left_behind(two, "run it again") == (
        "kiseki: interrupted; written completely before it: a/map.pgm, a/map.yaml; "
        "no partial file is left; run it again"
    )
    many = [Path(f"t{i}.csv") for i in range(7)]
    assert left_behind(many).startswith(
        "kiseki: interrupted; 7 files were written completely before it (t0.csv ... t6.csv)"
    )


def _trials(path: Path) -> list[dict]:
    if not path.exists():
        return []
    return [json.loads(line) for line in path.read_text().splitlines() if line.strip()]


@pytest.mark.parametrize(("signum", "code"), [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_an_interrupted_experiment_says_so_and_resumes_the_missing_trials(tmp_path, signum, code):
    out = tmp_path / "run"
    command = [sys.executable, "-m", "kiseki.cli", "experiment", "run", "corridor-scans"]
    proc = subprocess.Popen(
        [*command, "--runs", "3", "--seed", "3", "--out", str(out)],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        cwd=tmp_path,
    )
    deadline = time.monotonic() + 240
    while time.monotonic() < deadline and not _trials(out / "trials.jsonl"):
        time.sleep(0.05)
    proc.send_signal(signum)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == code, err
    (line,) = [x for x in err.splitlines() if x.startswith("kiseki:")]
    assert line.startswith("kiseki: interrupted; written completely before it: "), line
    assert str(out / "config.yaml") in line and "--resume --out" in line
    assert "Traceback" not in err
    finished = _trials(out / "trials.jsonl")
    assert 1 <= len(finished) < 3 and all(t["error"] is None for t in finished)
    assert not [p.name for p in out.iterdir() if p.name.startswith(".")]  # no temporary file

    resumed = subprocess.run(
        [*command, "--resume", "--out", str(out)],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=240,
    )
    assert resumed.returncode == 0, resumed.stderr
    assert f"3 trials ({3 - len(finished)} run now, 0 failed)" in resumed.stdout
    assert sorted(t["trial"] for t in _trials(out / "trials.jsonl")) == [0, 1, 2]
    assert (out / "report.md").exists()


def _exit_143(signum, frame):
    raise SystemExit(143)  # as the CLI's SIGTERM handler does


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_during_a_record_arrives_after_it(tmp_path, signum):
    """A signal raised while a message is being added is delivered once the record is whole,
    so the summary written on close counts exactly the messages in the file (a SIGTERM that
    landed inside the mcap writer once left 'the summary counts 46 messages, the file has 38')."""
    from kiseki.io.runlog import RunWriter, read_run

    previous = signal.signal(signal.SIGTERM, _exit_143)
    finished = []
    path = tmp_path / "run.mcap"
    try:
        with pytest.raises((KeyboardInterrupt, SystemExit)), RunWriter(path) as writer:
            writer.write_pose("/ground_truth", 0.0, (0.0, 0.0, 0.0))
            add = writer._writer.add_message

            def add_then_signal(*args, **kwargs):
                os.kill(os.getpid(), signum)  # would interrupt right here without the mask
                add(*args, **kwargs)
                finished.append(True)

            writer._writer.add_message = add_then_signal
            writer.write_pose("/ground_truth", 0.1, (1.0, 0.0, 0.0))
            writer.write_pose("/ground_truth", 0.2, (2.0, 0.0, 0.0))  # never reached
    finally:
        signal.signal(signal.SIGTERM, previous)
    assert finished == [True]  # the record was completed before the interruption
    run = read_run(path)  # raises when the summary and the file disagree
    assert run.topics()["/ground_truth"][1] == 2 and not run.truncated
