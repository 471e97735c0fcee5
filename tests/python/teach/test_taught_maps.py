# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Taught maps against the truth: local maps from depth images add nothing where a column has no
reading (the wall-erasing column rule), the thesis' and the evidence-counting merge rules, the
truth measure of `kiseki.teach.map_truth.taught_map_truth`, and a real Kinect frame."""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest

from kiseki import _core
from kiseki.apps.teach.teaching_files import environment_grid, measure_taught_maps
from kiseki.control import PurePursuit
from kiseki.core import Pose2
from kiseki.sim.scene import load_scene
from kiseki.sim.setup import build_robot, build_sensors
from kiseki.teach.environment_map import EnvironmentMap, build_teaching_map
from kiseki.teach.local_maps import BANDS, LocalMapMaker
from kiseki.teach.map_truth import taught_map_truth


@pytest.fixture(scope="module")
def perfect_teaching(project_data):
    """The factory_turn route driven with the true poses and noise-free depth images, each
    local map merged at the true pose by both rules: what the maps are when nothing but the
    local maps and the merge can go wrong."""
    scene = load_scene(project_data / "worlds" / "factory_turn.yaml")
    setup = build_robot(scene, 0)
    cameras = [s for s in build_sensors(scene, setup, 0, 0.1) if s.kind == "depth_camera"]
    makers = {b: LocalMapMaker([c.device for c in cameras], b) for b in BANDS}
    maps = {
        (rule, b): EnvironmentMap(environment_grid(scene), rule)
        for rule in ("thesis", "evidence")
        for b in BANDS
    }
    route = scene.route
    controller = PurePursuit(route["waypoints"], 0.5, 0.6, 0.1, setup.robot.params.max_accel)
    truths = []
    for _ in range(2000):
        p = setup.robot.pose
        truth = (p.x, p.y, p.theta)
        images = [c.device.render(scene.world, truth, noise=False) for c in cameras]
        for (_, band), env in maps.items():
            env.merge(makers[band].builder(images), Pose2(*truth))
        truths.append(truth)
        if controller.done and not any(setup.robot.velocity):
            break
        v, _, w = controller.command(truth)
        setup.robot.step(v, w, 0.1)
    measured = {
        rule: measure_taught_maps(
            scene, {b: maps[(rule, b)].map() for b in BANDS}, np.array(truths), cameras
        )
        for rule in ("thesis", "evidence")
    }
    return scene, measured


def test_perfect_teaching_erases_almost_no_obstacle_cell(perfect_teaching):
    """The regression test of the column rule: with the old rule (a column without an in-band
    reading was a free ray to the camera's 10 m) the thesis' merge erased 23.7 % (plane) and
    9.6 % (band) of the obstacle cells in reach here, with perfect poses and noise-free images;
    with the new rule 2.6 % and 1.7 %."""
    _, measured = perfect_teaching
    for rule in ("thesis", "evidence"):
        for band in BANDS:
            m = measured[rule][band]
            assert m["obstacle_cells"] > 250 and m["visible_free_cells"] > 2500, (rule, band)
            assert m["false_occupied_share"] < 0.02, (rule, band, m)
    # what remains under the thesis' rule are 5 cm legs: a beam passing beside a leg inside its
    # 0.1 m cell frees the cell for good (L free over M occupied -> free)
    assert measured["thesis"]["band"]["erased_share"] < 0.02
    assert measured["thesis"]["plane"]["erased_share"] < 0.03
    for band in BANDS:
        assert measured["evidence"][band]["erased_share"] < 0.02
        assert (
            measured["evidence"][band]["erased_cells"] <= measured["thesis"][band]["erased_cells"]
        )


def test_truth_measure_counts_what_it_says():
    """A 3 x 1 m room, one sensor at its west end looking east: a hand-made taught map with
    one wall erased and one free patch walled must give those counts exactly."""
    truth = _core.OccupancyGrid(30, 10, 0.1, _core.Pose2(0.0, 0.0, 0.0), 0)
    cells = np.asarray(truth.cells)
    cells[:, 25:] = 100  # a wall 0.5 m thick at x = 2.5-3.0
    taught = _core.OccupancyGrid(np.array(cells), 0.1, _core.Pose2(0.0, 0.0, 0.0))
    t = np.asarray(taught.cells)
    t[:, 25:] = 0  # the whole wall erased
    t[3:6, 10:13] = 100  # a 3 x 3 wall in free space: only its centre has 8 occupied neighbours
    pose = np.array([[0.05, 0.5, 0.0]])
    m = taught_map_truth(taught, truth, pose, hfov=math.radians(170), reach=2.4)
    # in reach: cells within 2.4 m of (0.05, 0.5), ahead of it; the wall starts at 2.5 m: none
    assert m.obstacle_cells == 0 and m.false_occupied_cells == 1
    m = taught_map_truth(taught, truth, pose, hfov=math.radians(170), reach=2.9)
    # wall cells within 2.9 m count; erased are those whose 8 neighbours are free too: not on
    # the grid's border rows or its last column (no neighbour there)
    inside = [
        (i, j)
        for i in range(25, 30)
        for j in range(10)
        if math.hypot((i + 0.5) * 0.1 - 0.05, (j + 0.5) * 0.1 - 0.5) <= 2.9
    ]
    erased = [(i, j) for i, j in inside if 0 < j < 9 and i < 29]
    assert m.obstacle_cells == len(inside) and m.erased_cells == len(erased)
    assert m.erased_share == pytest.approx(len(erased) / len(inside))
    # two sensors at one pose reach the same cells: each counts once
    twice = taught_map_truth(
        taught, truth, np.vstack([pose, pose]), [math.radians(170)] * 2, [2.9, 2.0], [0.0, 0.5]
    )
    assert twice == m
    with pytest.raises(ValueError, match="one value per pose"):
        taught_map_truth(taught, truth, np.vstack([pose, pose]), [1.0, 1.0, 1.0], 2.0)
    with pytest.raises(ValueError, match="sensor_poses"):
        taught_map_truth(taught, truth, np.zeros((0, 3)), 1.0, 1.0)


def test_evidence_rule_keeps_a_wall_that_the_thesis_rule_lets_one_beam_erase():
    """Ten scans of a wall at x = 2 m, then one stray beam through it: the thesis' rule erases
    the wall cell, evidence counting keeps it; a brute-force count gives the same map."""
    angles = np.linspace(-0.5, 0.5, 41)
    wall = (2.03 / np.cos(angles)).astype(np.float32)
    poses = np.zeros((11, 3))
    ranges = np.tile(wall, (11, 1))
    ranges[10] = np.nan
    ranges[10, 20] = 3.5  # straight ahead, through the wall, ending at 3.5 m
    thesis = build_teaching_map(poses, ranges, angles, 30.0, rule="thesis")
    evidence = build_teaching_map(poses, ranges, angles, 30.0, rule="evidence")
    c = thesis.world_to_cell([[2.05, 0.05]])[0]
    assert np.asarray(thesis.cells)[c[1], c[0]] == 0
    assert np.asarray(evidence.cells)[c[1], c[0]] == 100
    # brute force: count free and hit observations per cell from each scan's local map
    free = np.zeros(np.asarray(thesis.cells).shape, int)
    hits = np.zeros_like(free)
    hidden = np.zeros_like(free, bool)
    for k in range(len(poses)):
        b = _core.LocalMapBuilder(8.0, 0.1)
        r = ranges[k].copy()
        b.add_scan(_core.Pose2(), angles, r, 30.0)
        local, hit = np.asarray(b.build().cells), b.hits()
        # L's cell (i, j) has its centre at (-4 + 0.1 (i + 0.5), ...); the pose is the origin
        js, is_ = np.nonzero(local >= 0)
        centres = np.column_stack([-4.0 + 0.1 * (is_ + 0.5), -4.0 + 0.1 * (js + 0.5)])
        for (ci, cj), j, i in zip(thesis.world_to_cell(centres), js, is_, strict=True):
            if local[j, i] == 0:
                free[cj, ci] += 1
            elif hit[j, i]:
                hits[cj, ci] += 1
            else:
                hidden[cj, ci] = True
    expected = np.where(free > hits, 0, np.where((hits > 0) | hidden, 100, -1))
    np.testing.assert_array_equal(np.asarray(evidence.cells), expected)
    with pytest.raises(ValueError, match="merge rule"):
        build_teaching_map(poses, ranges, angles, 30.0, rule="bayes")


def _kinect(shared_data):
    from PIL import Image

    path = shared_data / "depth" / "frame_20121214T142255.814212_depth_mm.png"
    depth = np.asarray(Image.open(path)).astype(np.float32) / 1000.0  # mm -> m, 0 = no data
    # the frame's intrinsics (its XML): fx = fy = 525, cx = 320, cy = 240; Kinect: 0.5-10 m
    return depth, (640, 480, 525.0, 525.0, 320.0, 240.0, 0.5, 10.0)


def _level_optical(x: float, y: float, z: float) -> np.ndarray:
    m = np.eye(4)
    m[:3, :3] = [[0, 0, 1], [-1, 0, 0], [0, -1, 0]]  # optical z forward = robot x
    m[:3, 3] = x, y, z
    return m


def _reference_local_map(depth, camera, optical, z_min, z_max):
    """The column rule in numpy, each column fed to the C++ builder as one beam: a hit at the
    nearest in-band reading, else free to the farthest in-band stretch, else nothing."""
    width, height, fx, fy, cx, cy, dmin, dmax = camera
    tx, ty, tz = optical[:3, 3]
    sensor = _core.Pose2(tx, ty, 0.0)
    builder = _core.LocalMapBuilder(8.0, 0.1)
    v = np.arange(height, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        for u in range(width):
            d = depth[:, u].astype(float)
            ok = (d >= dmin) & (d < dmax)
            gx = (u + 0.5 - cx) / fx
            along = d * math.hypot(gx, 1.0)  # horizontal distance for a level camera
            # heights of the pixel's top and bottom edges above the camera at the reading
            # (optical y points down); at a fraction f of the way they are f times that
            top, bottom = -(v - cy) / fy * d, -(v + 1 - cy) / fy * d
            low, high = np.minimum(top, bottom), np.maximum(top, bottom)
            # tz + f low <= z_max and tz + f high >= z_min, for f in [0, 1]; the camera is
            # inside the band, so both bound f from above only
            up = np.where(low > 0, (z_max - tz) / low, 1.0)
            down = np.where(high < 0, (z_min - tz) / high, 1.0)
            f_hi = np.minimum(np.minimum(up, down), 1.0)
            inside = ok & (f_hi >= 0.0)
            heading = math.atan2(-gx, 1.0)
            hit = inside & (f_hi >= 1.0)
            if hit.any():
                builder.add_scan(sensor, np.array([heading]), [along[hit].min()], 30.0)
            elif inside.any():
                # a no-return beam (range == max_range, both as the float32 the scan holds)
                reach = np.float32((f_hi * along)[inside].max())
                if reach > 0:
                    builder.add_scan(sensor, np.array([heading]), [reach], float(reach))
    return np.asarray(builder.build().cells)


@pytest.mark.parametrize("band", ["plane", "band"])
def test_a_real_kinect_frame_clears_no_space_beyond_what_it_shows(shared_data, band):
    depth, camera = _kinect(shared_data)
    assert (depth == 0).all(axis=0).sum() > 20  # the frame has columns without any reading
    # off the round numbers (0.3 mm above the bands' 0.4 m; a few mm off L's centre), so that
    # no millimetre-quantised reading lies exactly on a band's edge or a cell border, where
    # float rounding in C++ and numpy may decide either way
    optical = _level_optical(0.0137, -0.0071, 0.4003)
    z_min, z_max = BANDS[band]
    builder = _core.LocalMapBuilder(8.0, 0.1)
    builder.add_depth_band(depth, optical, *camera, z_min, z_max)
    local = np.asarray(builder.build().cells)
    # every free cell lies nearer than the farthest reading of the frame (1.71 m) plus a cell
    ys, xs = np.mgrid[0:80, 0:80]
    dist = np.hypot(-4.0 + 0.1 * (xs + 0.5), -4.0 + 0.1 * (ys + 0.5))
    farthest = float(depth[depth > 0].max())
    assert (local == 0).any() and dist[local == 0].max() <= farthest + 0.15
    # the same cells as the column rule written out in numpy
    reference = _reference_local_map(depth, camera, optical, z_min, z_max)
    np.testing.assert_array_equal(local, reference)


def test_teaching_writes_its_maps_against_the_truth(tmp_path, project_data):
    scene = load_scene(project_data / "worlds" / "factory_corridor.yaml")
    from kiseki.apps.teach import teach

    result = teach(scene, tmp_path / "t", seed=1, merge="evidence")
    doc = json.loads((tmp_path / "t" / "map_truth.json").read_text())
    assert doc["merge"] == "evidence" and set(doc["maps"]) == set(BANDS)
    for band, m in doc["maps"].items():
        assert 0.0 <= m["erased_share"] < 0.2 and 0.0 <= m["false_occupied_share"] < 0.2, band
        assert m["erased_cells"] == round(m["erased_share"] * m["obstacle_cells"])
    assert result.truth == doc["maps"]
    # rebuilt from the log (as after a crash): the same rule, the same maps and measures
    from kiseki.apps.teach.teaching import recover

    again = recover(scene, result.log, tmp_path / "r")
    assert again.merge == "evidence" and again.truth == result.truth
    for band in BANDS:
        assert (tmp_path / "r" / f"map_{band}.pgm").read_bytes() == (
            tmp_path / "t" / f"map_{band}.pgm"
        ).read_bytes()
    thesis = recover(scene, result.log, tmp_path / "r2", merge="thesis")
    assert thesis.merge == "thesis"
    assert (tmp_path / "r2" / "map_band.pgm").read_bytes() != (
        tmp_path / "t" / "map_band.pgm"
    ).read_bytes()
    with pytest.raises(ValueError, match="merge rule"):
        teach(scene, tmp_path / "u", merge="bayes")


def test_merge_rules_experiment_on_the_intel_log(shared_data, tmp_path):
    """Real scans: the thesis' rule lets stray beams free wall cells, evidence counting keeps
    more of the endpoints on the map; both maps still track the log (a short prefix here;
    `kiseki experiment run merge-rules` runs the four logs whole)."""
    from kiseki_experiments.harness.runner import run_experiment

    run = run_experiment(
        "merge-rules",
        runs=1,
        overrides=[f"data_dir={shared_data / 'carmen'}", "logs=intel-corrected", "max_scans=150"],
        out=tmp_path / "mr",
        progress=False,
    )
    table = pd.read_csv(run.run_dir / "tables" / "per_log.csv").iloc[0]
    assert table["scans"] == 150
    assert table["endpoints_evidence"] > table["endpoints_thesis"] + 0.02
    assert table["endpoints_log_odds"] > table["endpoints_thesis"]
    for rule in ("thesis", "evidence"):
        assert table[f"position_rmse_{rule}_m"] < 0.6, rule  # odometry alone: metres off


def test_map_from_log_with_evidence_rules_is_the_evidence_teaching_map(shared_data, tmp_path):
    import subprocess
    import sys

    from kiseki import load_map
    from kiseki.datasets import read_carmen_log

    log = shared_data / "carmen" / "aces-corrected.log.gz"
    out = tmp_path / "aces.yaml"
    done = subprocess.run(
        [sys.executable, "-m", "kiseki.cli", "map", "from-log", str(log), "-o", str(out)]
        + ["--rules", "evidence", "--resolution", "0.1"],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr
    scans = read_carmen_log(log).scans
    expected = build_teaching_map(
        scans.poses, scans.ranges, scans.angles, scans.max_range, 0.1, rule="evidence"
    )
    np.testing.assert_array_equal(np.asarray(load_map(out).cells), np.asarray(expected.cells))
