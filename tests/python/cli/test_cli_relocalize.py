# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``kiseki relocalize``: the hypotheses it prints are the library's for that scan, the best
one is where the run's robot was, and a scan the log does not have is one line, exit 1."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from _helpers.cli_main import kiseki
from _helpers.room_log import STEPS, room, write_inputs
from kiseki.datasets import open_scans
from kiseki.filters import RelocalizeConfig, relocalize


@pytest.fixture
def inputs(tmp_path: Path, monkeypatch) -> Path:
    monkeypatch.chdir(write_inputs(tmp_path))
    return tmp_path


def test_prints_the_librarys_hypotheses_and_finds_the_robot(inputs, monkeypatch, capsys):
    code, out, err = kiseki(
        monkeypatch, capsys, "relocalize", "room.yaml", "log.mcap", "--scan", "10",
        "--hypotheses", "3", "--threads", "1", "--json",
    )  # fmt: skip
    assert code == 0, err
    doc = json.loads(out)
    scans = open_scans(inputs / "log.mcap")
    want = relocalize(
        room(), scans.angles, scans.ranges[10], scans.max_range, RelocalizeConfig(hypotheses=3)
    )
    assert [d["rank"] for d in doc] == [1, 2, 3]
    assert [(d["x"], d["y"], d["score"]) for d in doc] == [(h.x, h.y, h.score) for h in want]
    truth = (np.linspace(0.0, 2.0, STEPS)[10], -1.0, 0.0)  # the run's robot at scan 10
    best = doc[0]
    assert math.hypot(best["x"] - truth[0], best["y"] - truth[1]) < 0.05
    assert abs(best["theta_deg"]) < 1.0
    assert best["error_m"] == pytest.approx(math.hypot(best["x"] - truth[0], best["y"] + 1.0))
    code, out, err = kiseki(
        monkeypatch, capsys, "relocalize", "room.yaml", "log.mcap", "--scan", "10"
    )
    assert code == 0, err
    lines = out.splitlines()  # piped: a header and one tab-separated line per hypothesis
    assert lines[0].split("\t") == ["rank", "x", "y", "theta_deg", "score", "error_m",
                                    "heading_error_deg"]  # fmt: skip
    assert len(lines) == 1 + RelocalizeConfig().hypotheses


def test_a_scan_the_log_does_not_have_is_one_line_and_exit_1(inputs, monkeypatch, capsys):
    code, out, err = kiseki(
        monkeypatch, capsys, "relocalize", "room.yaml", "log.mcap", "--scan", "40"
    )
    assert code == 1 and out == ""
    assert err.strip().splitlines() == [
        f"kiseki: error: --scan 40: log.mcap has {STEPS} scans (0..{STEPS - 1})"
    ]
