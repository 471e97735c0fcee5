# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``kiseki localize --budget-ms``: the choice reported and saved, the calibrated cost model
written and given back for the same output byte for byte (on another thread count), and bad
input refused in one line."""

from __future__ import annotations

import json

import pytest
import yaml

from _helpers.cli_main import kiseki
from kiseki.datasets import read_carmen_log
from kiseki.filters import CostModel, choose_counts
from kiseki.io.ros_map import save_map
from kiseki.mapping import build_map


@pytest.fixture(scope="module")
def intel_map(shared_data, tmp_path_factory):
    log = shared_data / "carmen" / "intel-corrected.log.gz"
    scans = read_carmen_log(log).scans
    grid = build_map(scans.poses, scans.ranges, scans.angles, scans.max_range)
    return log, save_map(grid, tmp_path_factory.mktemp("map") / "intel.yaml")


def test_budget_is_chosen_saved_and_replayed_byte_for_byte(
    intel_map, tmp_path, monkeypatch, capsys
):
    log, map_yaml = intel_map
    common = [
        "localize", log, "--map", map_yaml, "--particles", "1500", "--beams", "60",
        "--budget-ms", "0.8", "--odometry-noise", "0.1", "--seed", "4",
    ]  # fmt: skip
    status, out, err = kiseki(
        monkeypatch, capsys, *common, "--threads", "1", "-o", tmp_path / "a.csv"
    )
    assert status == 0, err
    cost_file = tmp_path / "a.cost.json"
    cost = CostModel.load(cost_file)
    saved = yaml.safe_load((tmp_path / "a.config.yaml").read_text())
    choice = choose_counts(0.8, cost, 100, 1500, 60, 30, 0.8)
    assert saved["budget"]["particles"] == choice.particles
    assert saved["budget"]["beams"] == choice.beams
    assert saved["cost_model"] == json.loads(cost_file.read_text())
    assert saved["budget_ms"] == 0.8 and saved["particles"] == 1500  # what was asked for
    assert f"{choice.particles:,} particles x {choice.beams} beams" in out
    again = ["--cost-model", cost_file, "--threads", "2", "-o", tmp_path / "b.csv"]
    status, out, err = kiseki(monkeypatch, capsys, *common, *again)
    assert status == 0, err
    assert (tmp_path / "b.csv").read_bytes() == (tmp_path / "a.csv").read_bytes()
    assert not (tmp_path / "b.cost.json").exists() and str(cost_file) in out


def test_bad_budget_input_is_refused_in_one_line(intel_map, tmp_path, monkeypatch, capsys):
    log, map_yaml = intel_map
    base = ["localize", log, "--map", map_yaml, "-o", tmp_path / "t.csv"]
    (tmp_path / "broken.json").write_text("{ not json")
    (tmp_path / "negative.json").write_text(
        json.dumps({**CostModel(1.0, 1e-4, 1e-6).to_dict(), "fixed_ms": -1.0})
    )
    cases = [
        (["--budget-ms", "0"], "--budget-ms"),
        (["--budget-ms", "-5"], "--budget-ms"),
        (["--budget-ms", "ten"], "--budget-ms"),
        (["--budget-ms", "20", "--cost-model", tmp_path / "none.json"], "cannot read"),
        (["--budget-ms", "20", "--cost-model", tmp_path / "broken.json"], "not JSON"),
        (["--budget-ms", "20", "--cost-model", tmp_path / "negative.json"], "fixed_ms"),
        (["--cost-model", tmp_path / "broken.json"], "only with --budget-ms"),
        (["--budget-ms", "20", "--global"], "--global"),
        (["--beam-skip", "--method", "beam"], "--beam-skip"),
    ]
    for extra, needle in cases:
        status, out, err = kiseki(monkeypatch, capsys, *base, *extra)
        assert status != 0, extra
        lines = err.strip().splitlines()
        assert len(lines) == 1 and needle in lines[0], (extra, err)
        if "cost-model" in map(str, extra) and needle != "only with --budget-ms":
            assert str(extra[-1]) in lines[0]  # the file is named
        assert "Traceback" not in err and not (tmp_path / "t.csv").exists()
