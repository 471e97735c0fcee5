# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The experiment harness: determinism across executors, resume after a real kill, failures
recorded, results folder, reproduction report, and bad input."""

from __future__ import annotations

import errno
import math
from pathlib import Path

import pandas as pd
import pytest
import yaml

from _helpers.experiment_runs import cli, frame
from kiseki.core import derive_seed
from kiseki.errors import KisekiError
from kiseki_experiments.harness import base, registry
from kiseki_experiments.harness.config import ConfigError, apply_overrides
from kiseki_experiments.harness.report import write_reproduction
from kiseki_experiments.harness.runner import run_experiment
from kiseki_experiments.harness.verdict import VERDICT_COLUMNS, Control, Criterion
from kiseki_experiments.mapping.corridor_scans import CorridorScansConfig


def test_serial_and_two_worker_local_cluster_give_identical_records(tmp_path):
    args = ["experiment", "run", "corridor-scans", "--runs", "6", "--seed", "11"]
    serial = cli(*args, "--out", "serial", cwd=tmp_path)
    parallel = cli(*args, "--out", "dask", "--workers", "2", cwd=tmp_path)
    assert serial.returncode == 0, serial.stderr
    assert parallel.returncode == 0, parallel.stderr
    a, b = frame(tmp_path / "serial"), frame(tmp_path / "dask")
    pd.testing.assert_frame_equal(a, b)
    assert (tmp_path / "serial" / "trials.parquet").read_bytes() == (
        tmp_path / "dask" / "trials.parquet"
    ).read_bytes()
    assert list(a["seed"]) == [derive_seed(11, i) for i in range(6)]
    # the verdicts too: the bootstrap's generator comes from the run's seed, not the executor
    assert (tmp_path / "serial" / "claims.csv").read_bytes() == (
        tmp_path / "dask" / "claims.csv"
    ).read_bytes()
    assert a["lateral_offset"].nunique() == 6  # the seeds reach the trials
    workers = pd.read_parquet(tmp_path / "dask" / "timings.parquet")["worker"].nunique()
    assert workers == 2  # both workers of the LocalCluster took trials


def test_carmen_maps_serial_equals_local_cluster(shared_data, tmp_path):
    # serial = cluster does not depend on which logs are mapped: the three small ones (0.3-0.7 s
    # each) give both workers trials; freiburg-079 (4,791 scans, 4 s) is left out
    args = ["experiment", "run", "carmen-maps", "--runs", "3"]
    args += ["--set", "logs=intel-corrected,aces-corrected,csail-corrected"]
    serial = cli(*args, "--out", "s", cwd=tmp_path)
    parallel = cli(*args, "--workers", "2", "--out", "p", cwd=tmp_path)
    assert serial.returncode == 0 and parallel.returncode == 0, serial.stderr + parallel.stderr
    pd.testing.assert_frame_equal(frame(tmp_path / "s"), frame(tmp_path / "p"))
    claims = pd.read_csv(tmp_path / "s" / "claims.csv")
    intel = claims[claims["claim"].str.endswith("[intel-corrected]")].iloc[0]
    assert intel["verdict"] == "holds" and intel["ci_low"] >= 0.9
    assert (tmp_path / "s" / "claims.csv").read_bytes() == (
        tmp_path / "p" / "claims.csv"
    ).read_bytes()


def _flaky_experiment() -> base.Experiment:
    def trial(config, index, seed):
        if index % 3 == 1:
            raise RuntimeError(f"trial {index} broke")
        return base.TrialOutput({"value": float(seed % 1000)})

    def analyze(config, trials, timings, figures):
        ok = trials[trials["error"].isna()]
        return base.Analysis(tables={"ok": ok}, notes=f"{len(ok)} values recorded")

    return base.Experiment(
        "flaky",
        "test paper",
        "Table 0",
        "fails every third trial",
        CorridorScansConfig,
        trial,
        analyze,
        default_runs=6,
    )


def test_failing_trials_are_recorded_and_the_sweep_continues(tmp_path, monkeypatch):
    real = registry._registry()
    monkeypatch.setattr(registry, "_registry", lambda: {**real, "flaky": _flaky_experiment()})
    result = run_experiment("flaky", out=tmp_path / "run", progress=False)
    assert (result.runs, result.failed) == (6, 2)
    trials = frame(tmp_path / "run")
    assert trials["error"].notna().tolist() == [False, True, False, False, True, False]
    assert "RuntimeError: trial 1 broke" in trials.loc[1, "error"]
    assert "2 failed" in (tmp_path / "run" / "report.md").read_text()
    manifest = yaml.safe_load((tmp_path / "run" / "manifest.json").read_text())
    assert manifest["trials_failed"] == 2 and manifest["seed"] == 0


def test_results_folder_latest_link_and_reproduction_report(tmp_path):
    done = cli("experiment", "run", "corridor-scans", "--runs", "5", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    latest = tmp_path / "results" / "corridor-scans" / "latest"
    assert latest.is_symlink()
    for name in (
        "config.yaml",
        "manifest.json",
        "trials.parquet",
        "claims.csv",
        "report.md",
        "tables/summary.csv",
        "figures/precision_vs_offset.png",
    ):
        assert (latest / name).is_file(), name
    saved = yaml.safe_load((latest / "config.yaml").read_text())
    assert saved["runs"] == 5 and saved["config"]["range_noise_sd"] == 0.01
    claims = pd.read_csv(latest / "claims.csv")
    assert list(claims.columns) == VERDICT_COLUMNS
    # every rebuilt cell of 5 seeds lies by a wall: the interval [1, 1] is inside >= 0.99
    assert claims["verdict"].tolist() == ["holds"] and claims["ci_low"].iloc[0] >= 0.99
    done = cli("experiment", "report", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    text = (tmp_path / "REPRODUCTION.md").read_text()
    assert "1 claims: 1 hold, 0 fail, 0 inconclusive, 0 not yet migrated" in text
    assert "decided: 100 %" in text
    missing = text.split("Missing experiments (")[1].split("\n")[0]
    assert "carmen-maps" in missing and "corridor-scans" not in missing
    assert "rebuilt occupied cells lie within 1.5 cells of a true obstacle" in text


def test_reproduction_report_with_carmen_maps(shared_data, tmp_path):
    assert cli("experiment", "run", "carmen-maps", cwd=tmp_path).returncode == 0
    totals, missing = write_reproduction(tmp_path / "results", tmp_path / "R.md")
    claims = pd.read_csv(tmp_path / "results" / "carmen-maps" / "latest" / "claims.csv")
    # each log's share of endpoints against 0.90 (intel 0.964 and csail 0.953 hold, aces 0.896
    # and freiburg 0.886 fail, as measured): the verdict is the side of 0.90 its Wilson
    # interval lies on, and the interval holds the measured share
    measured = claims["measured_value"].astype(float)
    assert ((claims["ci_low"] <= measured) & (measured <= claims["ci_high"])).all()
    expected = ["holds" if lo >= 0.90 else "fails" for lo in claims["ci_low"]]
    assert claims["verdict"].tolist() == expected
    holding = sorted(c.split("[")[1].rstrip("]") for c in claims["claim"][measured >= 0.90])
    assert holding == ["csail-corrected", "intel-corrected"]
    assert (totals["claims"], totals["holds"], totals["fails"]) == (4, 2, 2)
    assert "corridor-scans" in missing and "carmen-maps" not in missing
    text = (tmp_path / "R.md").read_text()
    assert "4 claims: 2 hold, 2 fail, 0 inconclusive, 0 not yet migrated" in text
    for row in claims.itertuples():  # every claim is a table row with its interval and verdict
        interval = f"{row.measured_value:g} [{row.ci_low:.4g}, {row.ci_high:.4g}]"
        assert f"| {row.claim} | {row.paper_value} | {interval} | {row.unit} |" in text
        assert f"| {row.verdict} | {row.trials} |" in text


def test_overrides_are_typed():
    c = apply_overrides(CorridorScansConfig(), ["range_noise_sd=0.02", "scan_spacing=0.2"])
    assert (c.range_noise_sd, c.scan_spacing) == (0.02, 0.2)
    with pytest.raises(ConfigError, match="--set: noise: unknown config key"):
        apply_overrides(CorridorScansConfig(), ["noise=1"])
    with pytest.raises(ConfigError, match="range_noise_sd: must be a valid number, got 'loud'"):
        apply_overrides(CorridorScansConfig(), ["range_noise_sd=loud"])


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["experiment", "run", "no-such-thing"], "unknown experiment 'no-such-thing'"),
        (["experiment", "run", "corridor-scans", "--set", "noise=1"], "unknown config key"),
        (
            ["experiment", "run", "corridor-scans", "--set", "scan_spacing=wide"],
            "scan_spacing: must be a valid number, got 'wide'",
        ),
        (["experiment", "run", "corridor-scans", "--set", "scan_spacing"], "key=value"),
        (["experiment", "run", "corridor-scans", "--runs", "0"], "--runs"),
        (
            ["experiment", "run", "fig-3-14", "--runs", "1000000000000", "--out", "r"],
            "kiseki: error: --runs must be an integer in 1..100,000, got 1000000000000",
        ),
        (
            ["experiment", "run", "corridor-scans", "--scheduler", "tcp://127.0.0.1:9"],
            "cannot reach the Dask scheduler at tcp://127.0.0.1:9",
        ),
        (["experiment", "run", "corridor-scans", "--scheduler", "localhost"], "tcp://HOST:PORT"),
        (["experiment", "run", "corridor-scans", "--resume", "--out", "nothing"], "no config"),
    ],
)
def test_bad_input_is_one_line_and_non_zero(tmp_path, args, needle):
    done = cli(*args, cwd=tmp_path)
    assert done.returncode == 1, done.stdout + done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0], done.stderr


@pytest.mark.parametrize(
    ("claims", "manifest", "needle"),
    [
        (None, None, "nonexistent: results folder not found"),
        ("claim,value\nx,1\n", "{}", "corridor-scans/latest/claims.csv: no column paper_value"),
        (b"\xff\xfe\x00garbage\x81", "{}", "corridor-scans/latest/claims.csv: not a claims"),
        ("claim,holds\nx,True\n", "[1,", "corridor-scans/latest/manifest.json: not a JSON"),
        ("claim,holds\nx,True\n", "{}", "corridor-scans/latest/manifest.json: a manifest needs"),
        # hand-edited: a traceback ('NoneType' object is not subscriptable), or printed as read
        (
            "claim,holds\nx,True\n",
            '{"trials": 1, "trials_failed": 0, "git": null}',
            "manifest.json: git must hold commit (text or null) and dirty",
        ),
        (
            "claim,holds\nx,True\n",
            '{"trials": 1, "trials_failed": 0, "git": {"commit": null, "dirty": "no"}}',
            "manifest.json: git must hold commit (text or null) and dirty",
        ),
        (
            "claim,holds\nx,True\n",
            '{"trials": -5, "trials_failed": 100, "git": {"commit": null}}',
            "manifest.json: trials and trials_failed must be counts",
        ),
        (
            "claim,holds\nx,True\n",
            '{"trials": "many", "trials_failed": 0, "git": {"commit": null}}',
            "manifest.json: trials and trials_failed must be counts",
        ),
    ],
)
def test_report_refuses_a_missing_folder_and_broken_results_in_one_line(
    tmp_path, claims, manifest, needle
):
    results = tmp_path / "results"
    if claims is not None:
        latest = results / "corridor-scans" / "latest"
        latest.mkdir(parents=True)
        write = latest.joinpath("claims.csv")
        write.write_bytes(claims) if isinstance(claims, bytes) else write.write_text(claims)
        latest.joinpath("manifest.json").write_text(manifest)
    where = "nonexistent" if claims is None else str(results)
    done = cli("experiment", "report", "--results", where, "-o", "R.md", cwd=tmp_path)
    assert done.returncode == 1, done.stdout + done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0], done.stderr
    assert not (tmp_path / "R.md").exists()  # no report of 0 claims


def test_report_refuses_a_latest_link_outside_the_results_in_one_line(tmp_path):
    """Was Python's raw relative_to message ("'/.../elsewhere' is not in the subpath of ...")."""
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    elsewhere.joinpath("claims.csv").write_text("claim,holds\nx,True\n")
    elsewhere.joinpath("manifest.json").write_text(
        '{"trials": 1, "trials_failed": 0, "git": {"commit": null}}'
    )
    latest = tmp_path / "results" / "exp1-corridor" / "latest"
    latest.parent.mkdir(parents=True)
    latest.symlink_to(elsewhere)
    done = cli("experiment", "report", "--results", "results", "-o", "R.md", cwd=tmp_path)
    assert done.returncode == 1, done.stdout + done.stderr
    assert done.stderr.splitlines() == [
        f"kiseki: error: {Path('results', 'exp1-corridor', 'latest')}: the link points outside "
        f"--results ({elsewhere})"
    ]
    assert not (tmp_path / "R.md").exists()


def test_a_run_whose_every_trial_fails_says_so_and_resumes_after_the_fix(tmp_path, monkeypatch):
    broken = {"yes": True}

    def trial(config, index, seed):
        if broken["yes"]:
            raise FileNotFoundError(f"input {index} is missing")
        return base.TrialOutput({"value": float(index)})

    def analyze(config, trials, timings, figures):  # needs the records: KeyError without them
        return base.Analysis(evidence=[base.Evidence.of("values", trials["value"])])

    criterion = Criterion("1", "<=", 5.0, "the trials' indices", bounds=(0.0, math.inf))
    spec = base.ClaimSpec("values", "the values", "index", criterion, Control("c", ("x=1",), 3))
    experiment = base.Experiment(
        "doomed", "test paper", "Table 0", "fails until fixed", CorridorScansConfig, trial, analyze,
        default_runs=3, claims=(spec,),
    )  # fmt: skip
    real = registry._registry()
    monkeypatch.setattr(registry, "_registry", lambda: {**real, "doomed": experiment})
    out = tmp_path / "run"
    with pytest.raises(KisekiError, match="every one of its 3 trials failed") as err:
        run_experiment("doomed", out=out, progress=False)
    assert "FileNotFoundError: input 0 is missing" in str(err.value) and str(out) in str(err.value)
    assert "\n" not in str(err.value)
    trials = frame(out)
    assert len(trials) == 3 and trials["error"].notna().all()
    report = (out / "report.md").read_text()
    assert "Every trial failed" in report and "input 0 is missing" in report
    assert yaml.safe_load((out / "manifest.json").read_text())["trials_failed"] == 3
    assert not (out / "claims.csv").exists()
    with pytest.raises(KisekiError, match="already holds trials"):  # no silent rerun over it
        run_experiment("doomed", out=out, progress=False)
    broken["yes"] = False  # the cause fixed: --resume runs the failed trials again
    result = run_experiment("doomed", out=out, resume=True, progress=False)
    assert (result.runs, result.failed, result.executed) == (3, 0, 3)
    assert frame(out)["value"].tolist() == [0.0, 1.0, 2.0]
    assert pd.read_csv(out / "claims.csv")["measured_value"].tolist() == [1.0]  # mean of 0, 1, 2


def test_an_analysis_error_is_raised_as_it_is_not_as_a_disk_problem(tmp_path, monkeypatch):
    missing = tmp_path / "inputs" / "reference.csv"

    def trial(config, index, seed):
        return base.TrialOutput({"value": float(index)})

    disk_full = {"yes": False}

    def analyze(config, trials, timings, figures):  # reads an input that is not there
        if disk_full["yes"]:  # or draws a figure on a full disk
            raise OSError(errno.ENOSPC, "No space left on device", str(figures / "a.png"))
        raise FileNotFoundError(errno.ENOENT, "No such file or directory", str(missing))

    experiment = base.Experiment(
        "needs_input", "test paper", "Table 0", "reads an input", CorridorScansConfig, trial,
        analyze, default_runs=2,
    )  # fmt: skip
    real = registry._registry()
    monkeypatch.setattr(registry, "_registry", lambda: {**real, "needs_input": experiment})
    with pytest.raises(FileNotFoundError) as err:
        run_experiment("needs_input", out=tmp_path / "run", progress=False)
    assert (err.value.errno, err.value.filename) == (errno.ENOENT, str(missing))
    assert str(err.value) == f"[Errno 2] No such file or directory: '{missing}'"  # not reworded
    log = (tmp_path / "run" / "trials.jsonl").read_text(encoding="utf-8")
    assert len(log.splitlines()) == 2  # the trials are logged all the same
    assert not (tmp_path / "run" / "claims.csv").exists()
    assert not list((tmp_path / "run").glob(".figures.*"))
    disk_full["yes"] = True  # a full disk while drawing is the results' problem: --resume
    with pytest.raises(OSError, match=r"trials are kept .* --resume") as full:
        run_experiment("needs_input", out=tmp_path / "run", resume=True, progress=False)
    assert full.value.errno == errno.ENOSPC and str(tmp_path / "run") in str(full.value)


def test_the_manifest_names_the_checkout_the_trials_ran_from(tmp_path, monkeypatch):
    """The commit recorded is the one when the trials started; a checkout that moved while they
    ran makes the manifest dirty and keeps the state at the end beside it."""
    import json

    from kiseki_experiments.harness import manifest, runner

    start = {"commit": "a" * 40, "dirty": False}
    end = {"commit": "b" * 40, "dirty": False}
    monkeypatch.setattr(runner, "git_state", lambda: dict(start))
    monkeypatch.setattr(manifest, "git_state", lambda: dict(end))
    run_experiment("corridor-scans", runs=2, out=tmp_path / "moved", progress=False)
    git = json.loads((tmp_path / "moved" / "manifest.json").read_text())["git"]
    assert git == {"commit": "a" * 40, "dirty": True, "changed_during_run": end}
    monkeypatch.setattr(manifest, "git_state", lambda: dict(start))
    run_experiment("corridor-scans", runs=2, out=tmp_path / "still", progress=False)
    git = json.loads((tmp_path / "still" / "manifest.json").read_text())["git"]
    assert git == start
    # what a run writes is what a new run refuses to replace (RUN_FILES, and trials.jsonl)
    written = {p.name for p in (tmp_path / "still").iterdir()}
    assert written == {*runner.RUN_FILES, "trials.jsonl"}


@pytest.mark.parametrize("name", ["config.yaml", "report.md", "tables"])
def test_a_new_run_keeps_the_users_files_in_its_out_folder(tmp_path, name):
    """--out . in a folder holding the user's config.yaml or report.md replaced them (only
    trials.jsonl, an earlier run's, was looked for); every file a run writes is looked for
    now, before the run starts, and a run's own folder is still resumed (test above)."""
    from kiseki_experiments.harness.runner import RUN_FILES

    mine = tmp_path / name
    if name == "tables":
        mine.mkdir()
        (mine / "mine.csv").write_text("the user's own")
    else:
        mine.write_text("the user's own")
    with pytest.raises(KisekiError) as err:
        run_experiment("corridor-scans", runs=1, out=tmp_path, progress=False)
    assert str(err.value) == (
        f"--out {tmp_path} holds {name}, which this command would replace: give a new or "
        "empty folder (or --resume, to continue a run interrupted there)"
    )
    assert sorted(p.name for p in tmp_path.iterdir()) == [name]  # nothing written
    assert name in RUN_FILES
