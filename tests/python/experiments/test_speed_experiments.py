# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Paper 004's experiments with few trials: Fig. 4's sweep against the geometry, the three
situations' claims, the pedestrian encounters' construction and outcomes, and the prior map."""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

from kiseki.core import Random
from kiseki.grid import OCCUPIED, UNKNOWN
from kiseki.sim.scene import load_scene
from kiseki_experiments.harness.runner import run_experiment
from kiseki_experiments.speed.speed_common import WORLDS, prior_map
from kiseki_experiments.speed.speed_pedestrian import (
    HALF_BODY,
    PedestrianConfig,
    _encounter,
    _reference,
)


def test_prior_map_is_the_inside_of_the_building():
    grid = prior_map(WORLDS / "speed_corner.yaml")
    cells = grid.cells

    def at(x, y):
        c = grid.world_to_cell(np.array([[x, y]]))[0]
        return int(cells[c[1], c[0]])

    assert at(0.0, -3.0) == 0  # the approach corridor
    assert at(4.0, 1.15) == 0  # the side corridor
    assert at(-1.4, 0.0) == UNKNOWN  # behind the left wall
    assert at(3.0, -2.0) == UNKNOWN  # inside the corner's block
    assert at(1.2, -2.0) == OCCUPIED  # the wall itself
    # the box of situation 2 is not on the map (teach variant)
    crossroad = prior_map(WORLDS / "speed_crossroad.yaml")
    c = crossroad.world_to_cell(np.array([[-1.45, 4.5]]))[0]
    assert crossroad.cells[c[1], c[0]] == 0


def test_fig4_sweep_follows_the_geometry(tmp_path):
    run = run_experiment("speed-fig4", out=tmp_path / "f4", progress=False)
    assert run.failed == 0 and run.runs == 13 * 5  # 5 sweeps of the 13 poses
    sweep = pd.read_csv(run.run_dir / "tables" / "sweep.csv")
    np.testing.assert_allclose(sweep["phi_deg"], np.arange(0, 61, 5), atol=1e-6)
    np.testing.assert_allclose(sweep["corner_distance_m"], 1.5, atol=1e-9)
    np.testing.assert_allclose(sweep["v_ref"], 0.5 * sweep["ratio"])
    # at phi = 0 the side corridor opens beside the robot: almost nothing ahead is hidden; from
    # further back the corner hides more of it, so the limit falls from 10 deg on
    assert sweep["ratio"].iloc[0] > 0.95
    assert (np.diff(sweep["v_ref"].to_numpy()[2:]) < 0).all()
    assert sweep["v_ref"].iloc[-1] < 0.8 * sweep["v_ref"].iloc[0]
    claims = pd.read_csv(run.run_dir / "claims.csv").set_index("claim")
    assert (claims["verdict"] == "holds").all(), claims[["measured_value", "verdict"]]
    # the spread over phi is (max - min) / v_max of each sweep: its interval holds the mean's
    spread = claims.iloc[0]
    mean = (sweep["v_ref"].max() - sweep["v_ref"].min()) / 0.5
    assert spread["ci_low"] - 0.01 <= mean <= spread["ci_high"] + 0.01
    assert (run.run_dir / "figures" / "speed_fig4.png").stat().st_size > 20_000


def test_situations_reproduce_the_papers_statements_in_one_repeat(tmp_path):
    # one drive of each run (the claims' intervals need 5 repeats: the default run and the
    # negative controls have them); each claim's single value is on its criterion's side
    run = run_experiment(
        "speed-situations", out=tmp_path / "s", overrides=["repeats=1"], progress=False
    )
    assert run.failed == 0 and run.runs == 7
    claims = pd.read_csv(run.run_dir / "claims.csv")
    assert len(claims) == 5 and (claims["trials"] == 1).all()
    assert (claims["verdict"] == "inconclusive").all()  # no interval from one value
    value = claims["measured_value"].str.split(" ").str[0].astype(float)
    threshold = claims["criterion"].str.split(" ").str[1].astype(float)
    below = claims["criterion"].str.startswith("<=")
    assert ((below & (value <= threshold)) | (~below & (value >= threshold))).all(), claims
    runs = pd.read_csv(run.run_dir / "tables" / "runs.csv")
    assert runs["reached"].all() and runs["collision"].isna().all()
    # the width term in the 1.5 m corridor: f(1.5) = 0.727 of method 1's speed there
    s3 = runs[runs["situation"] == 3].set_index("method")
    assert s3.loc["occlusion-width", "duration_s"] > s3.loc["occlusion", "duration_s"] + 3
    for k in (1, 2, 3):
        assert (run.run_dir / "figures" / f"speed_situation{k}.png").is_file()


def test_pedestrian_is_in_the_robots_path_when_its_front_arrives():
    config = PedestrianConfig()
    t, y, route = _reference(config.scene, tuple(config.goal), "none", config.max_duration)
    assert route == pytest.approx(16.5, abs=0.5)  # 8 m at 0.5 m/s, with the ramps
    reach = HALF_BODY + config.radius
    for seed in range(20):
        person = _encounter(config, "none", Random(seed))
        lane = person.start[1]
        assert config.crossing[0] + 0.35 <= lane <= config.crossing[1] - 0.35
        t_in = t[np.nonzero(np.abs(y - lane) <= reach)[0][0]]
        x, _ = person.position(t_in)
        assert abs(x) <= reach + 1e-9  # in the robot's column when its front reaches the lane
        x0, _ = person.position(0.0)
        assert abs(x0) >= reach  # it starts outside the robot's corridor column
        assert math.hypot(*person.velocity) == pytest.approx(1.4)


def test_pedestrian_encounters_end_in_a_recorded_outcome(tmp_path):
    run = run_experiment(
        "speed-pedestrian",
        runs=2,
        out=tmp_path / "p",
        overrides=["methods=none,occlusion"],
        progress=False,
    )
    assert run.failed == 0
    table = pd.read_csv(run.run_dir / "tables" / "safety.csv").set_index("method")
    assert set(table.index) == {"none", "occlusion"}
    assert (table["clear"] + table["stopped"] + table["collisions"] == 2).all()
    # method 1 drives the route slower: the price of its safety
    assert table.loc["occlusion", "route_time_s"] > table.loc["none", "route_time_s"]
    trials = pd.read_parquet(run.run_dir / "trials.parquet")
    hit = trials["none_outcome"] == "collision"
    assert (trials.loc[hit, "none_contact_speed"] >= 0.05).all()


def test_a_pattern_runs_every_matching_experiment(tmp_path):
    kiseki = [sys.executable, "-m", "kiseki.cli", "experiment", "run"]
    done = subprocess.run(
        [*kiseki, "speed-fig*", "--out", str(tmp_path)], capture_output=True, text=True
    )
    assert done.returncode == 0, done.stderr
    claims = pd.read_csv(tmp_path / "speed-fig4" / "claims.csv")
    assert (claims["verdict"] == "holds").all()
    for args, message in [
        (["nothing-*"], "no experiment matches"),
        (["speed-*", "--runs", "2"], "no --runs"),
        (["speed-*", "--set", "v_max=1"], "no --runs or --set"),
    ]:
        bad = subprocess.run([*kiseki, *args], capture_output=True, text=True)
        assert bad.returncode == 1 and message in bad.stderr, bad.stderr


def test_pedestrian_scene_copy_keeps_the_scene_file_untouched():
    scene = load_scene(WORLDS / "speed_crossroad.yaml")
    assert scene.pedestrians == []
