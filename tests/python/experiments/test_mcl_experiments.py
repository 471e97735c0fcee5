# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The localization engine's experiments with few trials: the kidnapped robot in simulation
(resetting recovers, the reliability estimate falls without recovery), the log splice, and
excursions of the space observation model on a real log."""

from __future__ import annotations

import numpy as np
import pandas as pd

from kiseki.core import Pose2
from kiseki.scans import LaserScans
from kiseki_experiments.harness.runner import run_experiment
from kiseki_experiments.mcl.mcl_excursions import excursions
from kiseki_experiments.mcl.mcl_kidnapping import splice


def test_splice_carries_the_robot_and_keeps_the_odometry_smooth() -> None:
    n = 50
    poses = np.column_stack([np.arange(n) * 0.1, np.zeros(n), np.zeros(n)])
    odometry = poses + [5.0, 1.0, 0.0]  # another frame, the same increments
    ranges = np.arange(n, dtype=np.float32)[:, None].repeat(3, 1)
    scans = LaserScans(np.arange(n) * 0.1, poses, odometry, ranges, np.zeros(3), 10.0)
    out = splice(scans, k=20, j=40, before=10, after=5)
    assert len(out) == 15
    np.testing.assert_array_equal(out.ranges[:, 0], [*range(10, 20), *range(40, 45)])
    np.testing.assert_allclose(out.poses[10], poses[40])  # the truth jumps 2 m
    steps = [
        Pose2(*a).between(Pose2(*b)).x for a, b in zip(out.odometry, out.odometry[1:], strict=False)
    ]
    np.testing.assert_allclose(steps, 0.1, atol=1e-12)  # the odometry does not see it
    assert np.all(np.diff(out.times) > 0)


def test_excursions_are_counted_to_their_return() -> None:
    e = np.array([0.1, 0.6, 0.7, 0.2, 0.9, 0.1, 0.6, 0.8])
    assert excursions(e, 0.5) == [2, 1, -1]
    assert excursions(np.zeros(5), 0.5) == []


def test_kidnapped_robot_recovers_with_resetting_and_says_when_it_is_lost(tmp_path) -> None:
    run = run_experiment("mcl-kidnapping", runs=4, seed=3, out=tmp_path / "k", progress=False)
    assert run.failed == 0
    table = pd.read_csv(run.run_dir / "tables" / "recovery.csv").set_index("recovery")
    # 4 trials: the 50-trial run is the experiment's; here the order must show
    assert table.loc["resetting", "recovered"] == 1.0
    assert table.loc["resetting", "recovered"] > table.loc["none", "recovered"]
    # the trials of short jumps (2.1, 2.2 m) take 19 and 139 updates, the others 3
    assert table.loc["resetting", "median_recovery_scans"] <= 20
    # without recovery the filter stays lost, and its reliability estimate falls
    assert table.loc["none", "recovered"] < 1.0
    assert table.loc["none", "reliability_before"] > 0.9
    # the mean over the 10 updates from the jump: with r <- r + 0.1 (s - r) from r = 1 it is
    # at least mean(0.9^1..0.9^10) = 0.586 even if no scan agrees; below 0.65, nearly none did
    assert table.loc["none", "reliability_after"] < 0.65
    assert (run.run_dir / "figures" / "kidnapping.png").stat().st_size > 10_000
    assert (run.run_dir / "figures" / "reliability_roc.png").stat().st_size > 5_000


def test_space_observation_excursions_return_on_a_real_log(shared_data, tmp_path) -> None:
    run = run_experiment(
        "mcl-excursions",
        runs=1,
        seed=0,
        overrides=["logs=intel-corrected", "max_scans=400"],
        out=tmp_path / "x",
        progress=False,
    )
    assert run.failed == 0
    table = pd.read_csv(run.run_dir / "tables" / "per_log.csv")
    so = table[table["method"] == "space-observation"].iloc[0]
    assert so["longest_scans"] != -1 and so["longest_scans"] <= 20
    lf = table[table["method"] == "likelihood-field"].iloc[0]
    assert lf["rmse_mean_m"] < 0.1 < so["rmse_mean_m"] + 0.5  # both track; the field closer


def test_kld_adapts_the_count_from_global_start_to_tracking(shared_data, tmp_path) -> None:
    run = run_experiment(
        "mcl-kld",
        runs=1,
        seed=0,
        overrides=["logs=aces-corrected", "max_scans=250", "max_particles=20000"],
        out=tmp_path / "kld",
        progress=False,
    )
    assert run.failed == 0
    table = pd.read_csv(run.run_dir / "tables" / "kld.csv").set_index("way")
    trials = pd.read_parquet(run.run_dir / "trials.parquet")
    counts = trials["kld_counts"].iloc[0]
    assert counts[-1] == 1000  # a converged cloud fills few bins: the minimum
    assert table.loc["fixed", "mean_particles"] == 20000
    assert table.loc["kld", "mean_particles"] < 0.2 * table.loc["fixed", "mean_particles"]
    assert table.loc["kld", "converged"] == table.loc["fixed", "converged"] == 1
