# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``kiseki experiment run PATTERN --out DIR``: every matching experiment into DIR/NAME; with
--resume, the started ones finished and the others started (a stopped all-experiments run goes
on where it stopped); the report reads that layout."""

from __future__ import annotations

import pandas as pd

from _helpers.cli_main import kiseki

BOTH = "*-[fs][ic][ga][4n]*"  # corridor-scans and speed-fig4, nothing else (checked below)


def test_a_stopped_pattern_run_resumes_and_the_report_reads_it(tmp_path, monkeypatch, capsys):
    out = tmp_path / "full"
    run = ("experiment", "run")
    status, text, err = kiseki(monkeypatch, capsys, *run, "speed-fig4*", "--out", out)
    assert status == 0, err
    first = pd.read_parquet(out / "speed-fig4" / "trials.parquet")
    assert len(first) == 65 and not (out / "corridor-scans").exists()
    status, text, err = kiseki(monkeypatch, capsys, *run, BOTH, "--out", out, "--resume")
    assert status == 0, err
    assert sorted(p.name for p in out.iterdir()) == ["corridor-scans", "speed-fig4"]
    lines = text.replace("\n", " ")
    assert f"corridor-scans: no run in {out / 'corridor-scans'} yet: starting one" in lines
    assert "10 trials (10 run now, 0 failed)" in lines  # corridor-scans, all of its trials
    assert "65 trials (0 run now, 0 failed)" in lines  # speed-fig4: nothing left to run
    # the finished experiment's trials are the ones of its first run, untouched
    pd.testing.assert_frame_equal(pd.read_parquet(out / "speed-fig4" / "trials.parquet"), first)
    status, text, err = kiseki(
        monkeypatch, capsys, "experiment", "report", "--results", out, "-o", tmp_path / "R.md",
        "--json",
    )  # fmt: skip
    assert status == 0, err
    report = (tmp_path / "R.md").read_text(encoding="utf-8")
    missing = report.split("Missing experiments (")[1].split("\n")[0]
    assert "corridor-scans" not in missing and "speed-fig4" not in missing
    assert "exp1-corridor" in missing
    assert "Result: `corridor-scans`, 10 trials, 0 failed" in report


def test_a_pattern_refuses_options_that_name_one_experiment(tmp_path, monkeypatch, capsys):
    for extra in (["--runs", "3"], ["--set", "x=1"], ["--resume", "--seed", "2"]):
        status, _, err = kiseki(
            monkeypatch, capsys, "experiment", "run", BOTH, "--out", tmp_path / "x", *extra
        )
        assert status != 0 and "a pattern runs several experiments" in err
        assert len(err.strip().splitlines()) == 1
    assert not (tmp_path / "x").exists()
