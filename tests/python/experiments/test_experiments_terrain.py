# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Paper 003's experiments (terrain-env-a, terrain-env-b, terrain-corridor) on tiny configs
(coarse-to-fine search, one seed), the object-cell labelling against the scene's boxes, and
the corridor scene against the numbers its file states."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from _helpers.scene_boxes import near_small_boxes
from kiseki.sim.pose6 import PAPER_MOVES
from kiseki.sim.scene import load_scene
from kiseki.terrain import attitude_matrix
from kiseki_experiments.harness.runner import run_experiment
from kiseki_experiments.terrain.terrain_common import local_maps, object_cells, start_pose
from kiseki_experiments.terrain.terrain_envs import _rise

WORLDS = Path(__file__).resolve().parents[3] / "data" / "worlds"
TINY = ["search=coarse-to-fine", "exact_gyro_rows=true", "removals=hough", "variant_costs=mean"]


def _run(name, tmp_path, extra=()):
    run = run_experiment(name, runs=1, overrides=[*TINY, *extra], out=tmp_path / name,
                         progress=False)  # fmt: skip
    assert run.failed == 0
    trials = pd.read_parquet(run.run_dir / "trials.parquet")
    return run, trials


def test_env_a_finds_the_papers_move_with_an_exact_gyro(tmp_path):
    run, trials = _run("terrain-env-a", tmp_path)
    row = trials.iloc[0]
    # with the gyro's error removed, the frames are right only if the estimate is the move
    est = np.array([row["exact_hough_x"], row["exact_hough_y"], row["exact_hough_z"]])
    assert np.linalg.norm(est - [0.35, 0.30, 0.05]) <= 0.06
    summary = pd.read_csv(run.run_dir / "tables" / "summary.csv")
    first = summary.iloc[0]
    # the paper's eq. 4 (a sum) is the first row; kiseki's mean cost is a row beside it
    assert (first["removal"], first["gyro"], first["cost"]) == ("hough", "with error",
                                                                 "eq. 4 (sum)")  # fmt: skip
    assert first["error_mean_cm"] == pytest.approx(100 * row["hough_error"])
    mean = summary[summary["cost"] == "kiseki (mean cost)"].iloc[0]
    assert mean["error_mean_cm"] == pytest.approx(100 * row["meancost_hough_error"])
    paper = pd.read_csv(run.run_dir / "tables" / "paper_vs_kiseki.csv")
    assert paper.iloc[1][["x_cm", "y_cm", "z_cm"]].tolist() == [32, 26, 6]
    assert (run.run_dir / "figures" / "terrain_env_a.png").stat().st_size > 20_000


def test_object_cells_lie_on_the_small_objects():
    scene = str(WORLDS / "rubble_b.yaml")
    maps = local_maps(scene, PAPER_MOVES["B"], 3, 10.0)  # the current map: tilted, gyro error
    mask = object_cells(scene, maps.current, maps.poses[1], maps.gyro[1])
    points, cells = maps.current.to_points()
    # the level frame back to the sensor's (the gyro's reading), then the true pose
    pose, level = maps.poses[1], attitude_matrix(*maps.gyro[1])
    world = points @ level @ pose[:3, :3].T + pose[:3, 3]
    on = mask.reshape(-1)[cells]
    assert on.sum() > 200
    near = near_small_boxes(scene, world, 0.03)
    # brute force: every labelled cell's point lies on a small object's box (3 cm margin: the
    # cell's 1 deg quantisation), and nearly every point on one is labelled
    assert near[on].mean() > 0.98
    assert on[near & (world[:, 2] > 0.02)].mean() > 0.9  # the floor beside them is not
    floor = np.abs(world[:, 2]) < 0.005
    assert floor.sum() > 1000 and on[floor].mean() < 0.02


def test_env_b_measures_the_removed_object_cells(tmp_path):
    run, trials = _run("terrain-env-b", tmp_path, ["removals=hough,none"])
    row = trials.iloc[0]
    assert row["object_cells"] > 200
    assert 0.0 <= row["hough_objects_removed"] <= 1.0
    assert row["none_objects_removed"] == 0.0 and row["none_others_removed"] == 0.0
    # the Hough step takes out most of the walls (the other cells), far more than the objects
    # (the objects' cells are checked against the boxes above): at least 5 times the share
    assert row["hough_others_removed"] > 0.5
    assert row["hough_others_removed"] >= 5 * row["hough_objects_removed"]
    assert 0.0 <= row["hough_objects_removed_above_4cm"] <= row["hough_objects_removed"]
    # environment A's move on the same seed: the paired contrast of the paper's A and B
    assert row["contrast_a_sum_error"] >= 0 and "contrast_a_mean_error" in row
    seeds = pd.read_csv(run.run_dir / "tables" / "per_seed.csv")
    assert seeds["env_a_hough_sum_error_cm"].iloc[0] == pytest.approx(
        100 * row["contrast_a_sum_error"]
    )


def test_corridor_scene_matches_its_stated_geometry():
    scene = load_scene(WORLDS / "terrain_corridor.yaml")
    sensor = start_pose(scene)[:3, 3]
    np.testing.assert_allclose(sensor, [6.7, 0.7, 0.5])
    dirs = np.array([[0, 1, 0], [0, -1, 0], [0, 0, 1], [-1, 0, 0], [1, 0, 0.0]])
    r = np.asarray(scene.world.cast_many(np.tile(sensor, (5, 1)), dirs, 20.0))
    # 1.2 m wide inside, ceiling underside at 2.4 m, end walls 6.6 and 7.2 m away (beyond 5 m)
    np.testing.assert_allclose(r, [0.6, 0.6, 1.9, 6.6, 7.2], atol=1e-9)
    tops = {(4.8, 0.4): 0.10, (5.6, 1.0): 0.06, (7.6, 0.5): 0.15, (8.3, 0.9): 0.08,
            (9.0, 0.35): 0.12, (9.6, 1.05): 0.07}  # fmt: skip
    origins = np.array([[x, y, 1.0] for x, y in tops])
    down = np.tile([0.0, 0.0, -1.0], (len(tops), 1))
    np.testing.assert_allclose(
        1.0 - np.asarray(scene.world.cast_many(origins, down, 5.0)), list(tops.values()), atol=1e-9
    )


def test_corridor_reports_the_along_track_error_per_removal(tmp_path):
    run, trials = _run("terrain-corridor", tmp_path, ["removals=none,hough"])
    table = pd.read_csv(run.run_dir / "tables" / "along_track.csv")
    assert table["removal"].tolist() == ["none", "hough"] * 3  # sum, exact gyro, mean cost
    assert table["cost"].tolist()[::2] == ["eq. 4 (sum)", "eq. 4 (sum)", "kiseki (mean cost)"]
    row = trials.iloc[0]
    for m in ("none", "hough"):
        got = table[(table["removal"] == m) & (table["gyro"] == "with error")]
        assert got["along_mean_cm"].iloc[0] == pytest.approx(100 * abs(row[f"{m}_along"]))
        assert row[f"{m}_along"] == pytest.approx(row[f"{m}_x"] - 0.35)


@pytest.mark.parametrize(
    ("override", "message"),
    [("removals=planes", "removals must be some of"), ("search=random", "search must be")],
)
def test_bad_config_is_refused_before_the_trials(tmp_path, override, message):
    with pytest.raises(ValueError, match=message):
        run_experiment("terrain-env-a", runs=1, overrides=[override], out=tmp_path / "x",
                       progress=False)  # fmt: skip


def test_cost_rise_matches_a_closed_form():
    """A quadratic bowl 1 + (x - 0.36)^2 + 100 (y - 0.1)^2 + z^2 on the paper's grid: 10 cm
    from the minimum the cost rises by 0.01 along x and by 1.0 across (relative to 1)."""
    x, y, z = np.meshgrid(np.arange(36) * 0.02, np.arange(51) * 0.02 - 0.5,
                          np.arange(31) * 0.02 - 0.3, indexing="ij")  # fmt: skip
    costs = 1 + (x - 0.36) ** 2 + 100 * (y - 0.1) ** 2 + z**2
    np.testing.assert_allclose(_rise(costs, 0.02), (0.01, 1.0), rtol=1e-9)
    costs[23, :, :] = np.inf  # x = 0.46 m not scored: the other side alone
    np.testing.assert_allclose(_rise(costs, 0.02), (0.01, 1.0), rtol=1e-9)
    assert all(np.isnan(v) for v in _rise(None, 0.02))


def test_global_map_reports_the_drift_of_a_multi_move_run(tmp_path):
    """terrain-global-map on 3 moves: the drift table is the trial's own numbers, the claim
    follows the 10 % criterion, and the saved global map is a readable OctoMap."""
    from kiseki import _core

    run = run_experiment(
        "terrain-global-map", runs=1, overrides=["moves=3", "search=coarse-to-fine"],
        out=tmp_path / "gm", progress=False,
    )  # fmt: skip
    assert run.failed == 0
    row = pd.read_parquet(run.run_dir / "trials.parquet").iloc[0]
    assert row["travelled_m"] == pytest.approx(3 * 0.35, abs=0.05)
    assert row["drift_share"] == pytest.approx(row["final_error_m"] / row["travelled_m"])
    assert row["final_error_m"] < 0.35  # far better than no motion estimate at all
    claims = pd.read_csv(run.run_dir / "claims.csv").set_index("claim")
    drift = claims.filter(like="10 % of the distance", axis=0).iloc[0]
    assert float(drift["measured_value"].split()[0]) == pytest.approx(row["drift_share"], 1e-3)
    assert drift["verdict"] == "inconclusive"  # one seed: no interval, no verdict
    tree = _core.OctreeWorld.read_binary(str(run.run_dir / "figures" / "terrain_global_map.bt"))
    assert tree.occupied_leaves > 1000


def test_global_map_control_places_every_stop_at_the_start(tmp_path):
    """motion=zero (the drift claim's control): the final error is the straight distance from
    the first stop to the last, recomputed here from the simulated stops."""
    from kiseki.sim.terrain_moves import terrain_stops

    run = run_experiment(
        "terrain-global-map", runs=1, seed=4, overrides=["moves=2", "motion=zero"],
        out=tmp_path / "zero", progress=False,
    )  # fmt: skip
    row = pd.read_parquet(run.run_dir / "trials.parquet").iloc[0]
    stops = terrain_stops(WORLDS / "rubble_a.yaml", 2, int(row["seed"]), 0.35)
    true = np.array([s.sensor[:3, 3] for s in stops])
    assert row["final_error_m"] == pytest.approx(np.linalg.norm(true[-1] - true[0]), abs=1e-9)
    assert row["drift_share"] > 0.9  # the route bends a little: far above the 10 % criterion
    # more moves than the route holds: the message names the scene (it named nothing)
    legs = np.diff(np.array(load_scene(WORLDS / "rubble_a.yaml").route["waypoints"]), axis=0)
    route = float(np.hypot(legs[:, 0], legs[:, 1]).sum())
    with pytest.raises(ValueError) as caught:
        terrain_stops(WORLDS / "rubble_a.yaml", 200, 0, 0.35)
    assert str(caught.value) == (
        f"{WORLDS / 'rubble_a.yaml'}: the route is {route:.2f} m long: at most "
        f"{int(route / 0.35 + 1e-9)} moves of 0.35 m"
    )
