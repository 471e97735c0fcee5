# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``kiseki relocalize``: the hypotheses it prints are the library's for that scan, the best
one is where the run's robot was, its plot draws the best one where it lies, and a scan the log
does not have is one line, exit 1."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from _helpers.cli_main import kiseki
from _helpers.pixels import blobs, rgb
from _helpers.room_log import STEPS, room, write_inputs
from kiseki.datasets import open_scans
from kiseki.filters import RelocalizeConfig, relocalize
from kiseki.io.ros_map import save_map


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


def test_the_plot_shows_the_best_hypothesis_where_it_lies_on_the_map(inputs, monkeypatch, capsys):
    args = ("relocalize", "room.yaml", "log.mcap", "--scan", "30", "--hypotheses", "1", "--json")
    code, out, err = kiseki(monkeypatch, capsys, *args, "--plot", "h.png")
    assert code == 0, err
    best = json.loads(out)[0]
    image = rgb(inputs / "h.png")
    # black: the room's outer wall (its extent, -1..5 m by -2..2 m, gives the scale), then the
    # pillar (cells x 60..65, y 30..39: centre 2.15, -0.25 m) the anchor; rows grow downwards
    (_, walls_size), (pillar, _), *_ = blobs(image, (0, 0, 0), tol=40)
    (dot, _), *_ = blobs(image, (214, 39, 40), tol=30)  # matplotlib's tab:red
    x = 2.15 + 6.0 * (dot[0] - pillar[0]) / walls_size[0]
    y = -0.25 - 4.0 * (dot[1] - pillar[1]) / walls_size[1]
    assert math.hypot(x - best["x"], y - best["y"]) < 0.03  # 6 pixels


def test_a_map_of_another_place_is_warned_of(inputs, monkeypatch, capsys):
    """From the best hypothesis the log's own map holds nearly every endpoint on a wall: no
    warning. A map with the room's walls moved away (a grid of pillars 3 m apart, another
    building) holds few: one warning line naming it, as kiseki localize gives."""
    code, _, err = kiseki(
        monkeypatch, capsys, "relocalize", "room.yaml", "log.mcap", "--scan", "10"
    )
    assert code == 0 and "warning" not in err
    grid = room()
    other = np.zeros_like(np.asarray(grid.cells))  # free everywhere
    other[::60, ::60] = 100  # a pillar every 60 cells
    grid.cells[:] = other
    save_map(grid, inputs / "other.yaml")
    code, _, err = kiseki(
        monkeypatch, capsys, "relocalize", "other.yaml", "log.mcap", "--scan", "10"
    )
    assert code == 0
    warnings = [line for line in err.splitlines() if "warning" in line]
    assert len(warnings) == 1 and "other.yaml at the estimated poses" in warnings[0]
