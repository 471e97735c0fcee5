# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The exp1-corridor and exp3-boxes experiments from the CLI, with few trials on a 3 m
corridor (the factory corridor's route shortened, P0 -> P1 -> P2): every claim and table
recomputed from the raw trials, the 0.1 m stop rule met in every run, and the unknown boxes
really in the played-back world."""

from __future__ import annotations

import hashlib
import subprocess
import sys

import pandas as pd
import pytest
import yaml

from kiseki.core import derive_seed


@pytest.fixture
def short_corridor(tmp_path, project_root):
    doc = yaml.safe_load((project_root / "data" / "worlds" / "factory_corridor.yaml").read_text())
    doc["route"]["waypoints"] = [[0.0, 0.0], [1.5, 0.0], [3.0, 0.0]]
    path = tmp_path / "short_corridor.yaml"
    path.write_text(yaml.safe_dump(doc))
    return path


def run(name: str, runs: int, scene, cwd) -> tuple[pd.DataFrame, pd.DataFrame]:
    done = subprocess.run(
        [sys.executable, "-m", "kiseki.cli", "experiment", "run", name, "--runs", str(runs)]
        + ["--seed", "0", "--set", f"scene={scene}", "--set", "particles=200", "--out", "r"],
        cwd=cwd,
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr
    trials = pd.read_parquet(cwd / "r" / "trials.parquet")
    assert trials["error"].isna().all() and len(trials) == runs
    assert list(trials["seed"]) == [derive_seed(0, i) for i in range(runs)]
    claims = pd.read_csv(cwd / "r" / "claims.csv", keep_default_na=False)
    return trials, claims.set_index("claim")


def test_exp1_corridor_claims_follow_from_its_trials(tmp_path, short_corridor):
    trials, claims = run("exp1-corridor", 2, short_corridor, tmp_path)
    taught = hashlib.sha1(short_corridor.read_bytes()).hexdigest()
    assert (trials["scene_sha1"] == taught).all() and (trials["scene_variant"] == "").all()
    stop = trials["proposal2_stop_error"]
    assert (stop <= 0.1).all() and (trials["proposal2_reached"]).all()  # the thesis' rule
    # the stop error is the distance of the true rest from where P2 was taught
    dx, dy = trials["proposal2_stop_dx"], trials["proposal2_stop_dy"]
    assert stop.tolist() == pytest.approx((dx**2 + dy**2) ** 0.5)
    # the claim: the share within 0.1 m (Wilson), recomputed from the trials; 2 runs do not
    # decide it
    within = int((stop <= 0.1).sum())
    row = claims.loc["the stops at P2 are within 0.1 m (share of runs)"]
    assert row["measured_value"] == f"{within / 2:.4g} ({within}/2)"
    assert row["verdict"] == "inconclusive" and row["trials"] == 2
    loc = (trials["proposal2_P2_loc_dx"] ** 2 + trials["proposal2_P2_loc_dy"] ** 2) ** 0.5
    odo = (trials["proposal2_P2_odo_dx"] ** 2 + trials["proposal2_P2_odo_dy"] ** 2) ** 0.5
    assert len(claims) == 1
    table = pd.read_csv(tmp_path / "r" / "tables" / "errors_at_waypoints.csv").set_index("point")
    for point in ("P1", "P2"):
        for kind in ("loc", "odo"):
            for axis in ("dx", "dy"):
                mean = trials[f"proposal2_{point}_{kind}_{axis}"].mean()
                assert table.loc[point, f"{kind}_{axis}_mean"] == pytest.approx(mean, abs=1e-12)
    # a table row, not a claim (no control fails it): odometry's minus localization's error
    assert table.loc["P2", "odo_minus_loc_mean_m"] == pytest.approx((odo - loc).mean())


def test_exp3_boxes_are_in_the_played_back_world(tmp_path, short_corridor):
    trials, claims = run("exp3-boxes", 1, short_corridor, tmp_path)
    t = trials.iloc[0]
    # the trial records that it played back in a named, changed copy of the taught scene
    assert t["scene_variant"] == "exp3-boxes"
    assert t["scene_sha1"] != hashlib.sha1(short_corridor.read_bytes()).hexdigest()
    assert t["proposal2_stop_error"] <= 0.1 and t["proposal2_reached"]
    assert 0 <= t["final_leg_boxes_left"] + t["final_leg_boxes_right"] <= 3
    # the control run (same teaching and seeds, no boxes) stops elsewhere: the cameras saw them
    with_boxes = (t["proposal2_stop_dx"], t["proposal2_stop_dy"])
    without = (t["proposal2_nobox_stop_dx"], t["proposal2_nobox_stop_dy"])
    assert with_boxes != without
    # the declared claims: the run's value, no interval from one run (inconclusive), and the
    # trials that would decide it priced
    for what, column, threshold in (("stop", "stop_error", 0.09), ("estimate", "estimate_error",
                                                                    0.08)):  # fmt: skip
        row = claims.loc[f"proposal 2 with unknown boxes: {what} error mean at most the thesis' "
                         "plus its SD"]  # fmt: skip
        assert row["measured_value"].startswith(f"{t[f'proposal2_{column}']:.4g} ")
        assert row["criterion"].startswith(f"<= {threshold:g} (")
        assert row["verdict"] == "inconclusive" and row["trials"] == 1


def test_exp3_with_kisekis_ray_model_stops_by_the_rule_and_its_claim_is_the_paired_difference(
    tmp_path, short_corridor
):
    """ray=true plays the same run (teaching, boxes, seeds) again with kiseki's ray space
    observation model on the cameras' local map read as a scan: it stops within the thesis'
    0.1 m too, and the claim's value is the mean of the per-run differences."""
    done = subprocess.run(
        [sys.executable, "-m", "kiseki.cli", "experiment", "run", "exp3-boxes", "--runs", "1"]
        + ["--seed", "0", "--set", f"scene={short_corridor}", "--set", "particles=200"]
        + ["--set", "ray=true", "--out", "r"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr
    t = pd.read_parquet(tmp_path / "r" / "trials.parquet").iloc[0]
    assert t["proposal2_ray_stop_error"] <= 0.1 and t["proposal2_ray_reached"]
    claims = pd.read_csv(tmp_path / "r" / "claims.csv", keep_default_na=False)
    row = claims[claims["claim"].str.startswith("with unknown boxes, kiseki's ray")].iloc[0]
    difference = t["proposal2_ray_stop_error"] - t["proposal2_stop_error"]
    assert row["measured_value"].startswith(f"{difference:.4g} ")
    assert row["verdict"] == "inconclusive"  # one run gives no interval


def test_a_refused_route_has_no_stop_sd_and_raises_no_warning():
    """layouts-exp2-exp3 records a refused route as a stop error of inf (it never stopped): its
    mean is inf, its SD is undefined (NaN), and neither warns; the other methods' are as
    pandas computes them."""
    import warnings
    from types import SimpleNamespace

    import numpy as np

    from kiseki_experiments.teach.teach_playback_tables import stop_table

    trials = pd.DataFrame({"conventional_stop_error": [np.inf, np.inf, 0.2],
                           "proposal2_stop_error": [0.05, 0.07, 0.04]})  # fmt: skip
    for m in ("conventional", "proposal2"):
        trials[f"{m}_estimate_error"] = 0.1
        trials[f"{m}_stop_dx"], trials[f"{m}_stop_dy"] = 0.01, 0.02
    config = SimpleNamespace(methods=["conventional", "proposal2"])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        table = stop_table(config, trials).set_index("method")
    assert table.loc["conventional", "stop_error_mean_m"] == np.inf
    assert np.isnan(table.loc["conventional", "stop_error_sd_m"])
    sd = trials["proposal2_stop_error"].std(ddof=1)
    assert table.loc["proposal2", "stop_error_sd_m"] == pytest.approx(sd, rel=1e-12)
    assert table.loc["conventional", "stops_within_0.1m"] == 0
