# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""magnav-fig-5-4 on one seed with a small filter: its tables agree with its own trial records
and the scene's stated stretch, and the SD ratios of Fig. 5.6 are below a half even with 60
particles."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from kiseki_experiments.harness.paths import WORLDS
from kiseki_experiments.harness.records import unpack
from kiseki_experiments.harness.runner import run_experiment
from kiseki_experiments.magnav.magnav_fig_5_4 import blind_stretch
from kiseki_experiments.magnav.magnav_fig_5_4_claims import CLAIMS, OFF_PATH


def test_one_small_run_reports_what_its_trial_measured(tmp_path):
    run = run_experiment(
        "magnav-fig-5-4",
        runs=1,
        out=tmp_path / "f",
        overrides=["particles=60", "beams=20", "distance=35"],
        progress=False,
    )
    assert run.failed == 0 and run.runs == 1
    trials = pd.read_parquet(run.run_dir / "trials.parquet")
    (record,) = trials.to_dict("records")
    lo, hi = blind_stretch(str(WORLDS / "magnetic_lidar_path.yaml"))
    assert (record["blind_lo"], record["blind_hi"]) == (lo, hi) == (-40.45, 29.6)
    summary = pd.read_csv(run.run_dir / "tables" / "summary.csv").set_index("method")
    assert list(summary.index) == ["odometry", "laser", "magnetic"]
    for m in summary.index:
        truth = unpack(record[f"{m}_truth"])  # every 5th step
        blind = (truth[:, 0] > lo) & (truth[:, 0] < hi)
        recorded = summary.loc[m, "blind_max_xt"]
        assert recorded == pytest.approx(record[f"{m}_blind_max_xt"])
        assert np.abs(truth[blind, 1]).max() <= recorded + 1e-6
        assert np.abs(truth[blind, 1]).max() > recorded - 0.05  # 0.5 s at 0.6 m/s apart
    assert np.isnan(summary.loc["odometry", "blind_sd_y"])
    assert summary.loc["laser", "resets"] == 0.0 < summary.loc["magnetic", "resets"]
    claims = pd.read_csv(run.run_dir / "claims.csv").set_index("claim")
    assert list(claims.index) == [c.claim for c in CLAIMS]
    assert (claims["trials"] == 1).all()
    value = {c.key: float(str(claims.loc[c.claim, "measured_value"]).split()[0]) for c in CLAIMS}
    # one run: no interval, except that 0 of 1 already excludes a share of 0.8
    verdict = {c.key: claims.loc[c.claim, "verdict"] for c in CLAIMS}
    assert verdict == {
        c.key: "fails" if c.key == "both-reach-goal" else "inconclusive" for c in CLAIMS
    }
    for axis, key in (("y", "blind_sd_y"), ("theta", "blind_sd_theta_deg")):
        ratio = record[f"magnetic_{key}"] / record[f"laser_{key}"]  # the ratio of its record
        assert value[f"sd_{axis}"] == pytest.approx(ratio, rel=1e-3)
        assert ratio < 0.5  # Fig. 5.6's contrast shows even with 60 particles
    blind = record["magnetic_blind_max_xt"] / record["laser_blind_max_xt"]
    assert value["proposed-deviates-less"] == pytest.approx(blind, rel=1e-3)
    assert value["resets-many"] == pytest.approx(record["magnetic_resets"], rel=1e-3)
    assert value["odometry-leaves"] == float(record["odometry_max_xt"] > OFF_PATH)
    assert value["both-reach-goal"] == 0.0  # stopped after 35 m: no goal
    for name in ("trajectories", "gates", "sd"):
        (png,) = (run.run_dir / "figures").glob(f"*{name}.png")
        assert png.stat().st_size > 20_000


def test_a_sweep_keeps_its_scene_until_the_file_changes(tmp_path):
    # the runs of a sweep share the scene read once (magnav_lidar_drive); a scene file changed
    # since (here its route speed, one byte longer) is read again, not served from the cache
    from kiseki_experiments.magnav.magnav_lidar_drive import load

    scene = tmp_path / "path.yaml"
    text = (WORLDS / "magnetic_lidar_path.yaml").read_text()
    scene.write_text(text)
    first = load(scene, 0)[0]
    assert load(scene, 1)[0] is first
    assert float(first.route["speed"]) == 0.6
    scene.write_text(text.replace("speed: 0.6", "speed: 0.55"))
    again = load(scene, 0)[0]
    assert again is not first and float(again.route["speed"]) == 0.55
    with pytest.raises(FileNotFoundError, match="scene file not found"):
        load(tmp_path / "gone.yaml", 0)
