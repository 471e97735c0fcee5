# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What the experiment runner and report take from a user and from a results folder: a run the
preflight refuses leaves no folder, claims the report cannot count are refused in one line, and
a run made without a git checkout is read."""

from __future__ import annotations

import pytest

from _helpers.experiment_runs import cli


@pytest.mark.parametrize(
    ("change", "needle"),
    [
        ({"verdict": "maybe"}, "claims.csv row 2: verdict must be one of"),
        ({"trials": "abc"}, "claims.csv row 2: trials must be a count"),
        ({"ci_high": "inf"}, "claims.csv row 2: trials must be a count and the interval finite"),
    ],
)
def test_report_refuses_claims_it_cannot_count_in_one_line(tmp_path, change, needle):
    """A verdict of "maybe" was tallied as nothing ("2 claims: 0 hold, 0 fail, 0
    inconclusive"); trials "abc" said "invalid literal for int()" without naming the file."""
    from kiseki_experiments.harness.verdict import VERDICT_COLUMNS

    row = {c: "" for c in VERDICT_COLUMNS} | {"claim": "x", "verdict": "holds", "trials": "5"}
    row |= {"ci_low": "0.1", "ci_high": "0.2"} | change
    latest = tmp_path / "results" / "corridor-scans" / "latest"
    latest.mkdir(parents=True)
    latest.joinpath("claims.csv").write_text(
        ",".join(VERDICT_COLUMNS) + "\n" + ",".join(row[c] for c in VERDICT_COLUMNS) + "\n"
    )
    latest.joinpath("manifest.json").write_text(
        '{"trials": 5, "trials_failed": 0, "git": {"commit": null}}'
    )
    done = cli("experiment", "report", "--results", "results", "-o", "R.md", cwd=tmp_path)
    assert done.returncode == 1, done.stdout + done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0], done.stderr


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (
            ["mcl-excursions", "--set", "sensor_reset_proposal=foo"],
            "sensor_reset_proposal must be one of uniform, matcher, got 'foo'",
        ),
        (["speed-pedestrian", "--set", "goal=1"], "goal must be two numbers x,y (m), got [1.0]"),
        (["exp1-corridor", "--set", "methods="], "--set: methods: list should have at least 1"),
    ],
)
def test_a_refused_run_leaves_no_results_folder(tmp_path, args, needle):
    """Each failed in every trial (or after one), leaving a results folder with a config.yaml
    and no result; the preflight now runs before the folder is made."""
    done = cli("experiment", "run", *args, "--runs", "1", "--out", "r", cwd=tmp_path)
    assert done.returncode == 1, done.stdout + done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0], done.stderr
    assert not (tmp_path / "r").exists()


def test_report_reads_a_run_made_without_a_git_checkout(tmp_path):
    """manifest.git_state writes commit and dirty null without a checkout (a tarball, an image
    without .git): the report reads such a run."""
    latest = tmp_path / "results" / "corridor-scans" / "latest"
    latest.mkdir(parents=True)
    latest.joinpath("claims.csv").write_text("claim,holds\nx,True\n")
    latest.joinpath("manifest.json").write_text(
        '{"trials": 1, "trials_failed": 0, "git": {"commit": null, "dirty": null}}'
    )
    done = cli("experiment", "report", "--results", "results", "-o", "R.md", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert "commit unknown" in (tmp_path / "R.md").read_text()
