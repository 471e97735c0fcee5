# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Scenes, range sensors and the simulation loop: geometry against closed forms, noise models
against their parameters, every scene of data/worlds loads, renders and runs."""

from __future__ import annotations

import dataclasses
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml
from mcap.reader import make_reader

from kiseki import _core, load_map
from kiseki.datasets import open_scans
from kiseki.io.runlog import read_run
from kiseki.mapping import endpoint_agreement
from kiseki.sim.primitives import BoxList
from kiseki.sim.render import render_scene
from kiseki.sim.run import SimConfig, simulate
from kiseki.sim.scene import load_scene
from kiseki.sim.sensors import (
    LASER_PRESETS,
    DepthCamera,
    DepthCameraParams,
    Laser2D,
    Mount,
)
from kiseki.sim.tilting_laser import TiltingLaser, TiltingLaserParams

WORLDS = sorted((Path(__file__).resolve().parents[3] / "data" / "worlds").glob("*.yaml"))


def wall_world(x: float) -> _core.BoxWorld:
    """A wide wall whose front face is the plane x = `x`, and a floor at z = 0."""
    boxes = BoxList.empty()
    boxes.add([x + 0.5, 0.0, 2.0], [1.0, 40.0, 4.0])
    boxes.add([0.0, 0.0, -0.05], [80.0, 80.0, 0.1])
    return _core.BoxWorld(*boxes.arrays())


@pytest.mark.parametrize("path", WORLDS, ids=[p.stem for p in WORLDS])
def test_every_scene_loads_renders_and_runs(path, tmp_path):
    scene = load_scene(path)
    png = render_scene(scene, tmp_path / "scene.png")
    assert png.read_bytes()[:4] == b"\x89PNG"
    grid = scene.ground_truth(0.3, 0.5)
    assert 0 < np.mean(grid.cells == 100) < 0.9
    out = tmp_path / "run.mcap"
    summary = simulate(scene, out, SimConfig(duration=1.0, seed=3), progress=False)
    assert summary.steps == 10
    with out.open("rb") as f:
        reader = make_reader(f)
        counts = dict.fromkeys((c.topic for c in reader.get_summary().channels.values()), 0)
        channels = reader.get_summary().channels
        schemas = reader.get_summary().schemas
        for _, channel, _ in reader.iter_messages():
            counts[channel.topic] += 1
    assert counts["/map"] == 1
    several = len(scene.robot_specs) > 1
    for spec in scene.robot_specs:
        prefix = f"/{spec['name']}" if several else ""
        assert counts[f"{prefix}/ground_truth"] == counts[f"{prefix}/odom"] == 11
        for sensor in spec["sensors"]:
            topic = f"{prefix}/{sensor['name']}"
            expected = 1 if sensor["type"] == "tilting_laser" else 11
            assert counts[topic] == expected, topic
    for c in channels.values():  # Foxglove's messages protobuf, kiseki's own JSON
        foxglove = schemas[c.schema_id].name.startswith("foxglove.")
        assert c.message_encoding == ("protobuf" if foxglove else "json"), c.topic
    assert {c.message_encoding for c in channels.values()} == {"json", "protobuf"}


def test_factory_route_stops_within_a_tenth_of_a_metre_of_p2(tmp_path):
    scene = load_scene(WORLDS[[p.stem for p in WORLDS].index("factory_corridor")])
    summary = simulate(scene, tmp_path / "run.mcap", SimConfig(seed=0), progress=False)
    assert summary.reached_goal
    x, y, _ = summary.final_pose
    assert math.hypot(x - 13.0, y) <= 0.1
    ox, oy, _ = summary.final_odometry  # odometry drifts: mostly sideways after a heading error
    assert 0.01 < math.hypot(ox - x, oy - y) < 1.0


def test_laser_range_noise_dropouts_and_max_range():
    grid = load_scene(WORLDS[[p.stem for p in WORLDS].index("speed_corridor")]).ground_truth(
        0.25, 0.35
    )
    params = LASER_PRESETS["hokuyo_utm30lx"]
    truth = grid.cast_scans(np.array([[0.0, 0.0, 0.0]]), params.angles, max_range=30.0)[0]
    laser = Laser2D(params, Mount(), seed=4)
    scans = np.array([laser.scan(grid, (0.0, 0.0, 0.0))[1] for _ in range(300)])
    hit = truth < 30.0
    err = (scans[:, hit] - truth[hit]).ravel()
    assert abs(err.std() / 0.01 - 1) < 0.03 and abs(err.mean()) < 4 * 0.01 / math.sqrt(err.size)
    assert (scans[:, ~hit] == 30.0).all() and (~hit).any()
    drop = Laser2D(
        LASER_PRESETS["speed_lrf"].__class__(
            **{**LASER_PRESETS["speed_lrf"].__dict__, "dropout_probability": 0.05}
        ),
        Mount(),
        seed=5,
    )
    ranges = np.array([drop.scan(grid, (0.0, 1.0, math.pi / 2))[1] for _ in range(200)])
    assert (
        abs(
            np.mean(ranges == 4.0)
            - np.mean(
                grid.cast_scans(
                    np.array([[0.0, 1.0, math.pi / 2]]), drop.params.angles, max_range=4.0
                )
                >= 4.0
            )
            - 0.05
        )
        < 0.02
    )  # dropouts add ~5 % max-range returns


@pytest.mark.parametrize("z", [1.0, 2.0, 3.0, 4.5, 6.0])
def test_depth_noise_grows_with_depth_squared(z):
    params = DepthCameraParams(width=160, height=120)
    camera = DepthCamera(params, Mount(0.0, 0.0, 1.0), seed=int(z * 10))
    world = wall_world(z)
    clean = camera.render(world, (0.0, 0.0, 0.0), noise=False)
    noisy = np.concatenate([camera.render(world, (0.0, 0.0, 0.0)).ravel() for _ in range(5)])
    centre = np.tile(np.abs(clean.ravel() - z) < 1e-6, 5) & (noisy > 0)
    fb = params.native_focal * params.baseline
    sigma_d = math.sqrt(params.disparity_sd**2 + params.disparity_step**2 / 12)
    predicted = z * z * sigma_d / fb  # first-order propagation of disparity noise
    measured = (noisy[centre] - z).std()
    assert measured == pytest.approx(predicted, rel=0.15)
    assert (params.depth_step(z) > 0.05) == (z > 4.3)


def test_depth_camera_sees_table_tops_sideways():
    scene = load_scene(WORLDS[[p.stem for p in WORLDS].index("factory_corridor")])
    camera = DepthCamera(DepthCameraParams(), Mount(0.0, 0.29, 0.4, 90.0), seed=0)
    depth = camera.render(scene.world, (1.8, 0.0, 0.0), noise=False)  # beside the workbench
    # the workbench at y = 0.75..1.45 has its top at 0.81..0.85 m: pixels above the optical
    # axis see its near edge 0.75 - 0.29 = 0.46 m away... below min range (0.5 m): no return;
    # the wall behind it (y = 1.5) is 1.21 m away through the legs' gap.
    valid = depth[depth > 0]
    assert valid.min() >= 0.5 and np.isclose(np.median(valid), 1.21, atol=0.15)
    # every pixel against one ray cast into the world through its centre from the mounted
    # camera (pinhole: fx = w / 2 / tan(hfov / 2), centre at (w / 2, h / 2)); z-depth = range /
    # |ray| with the ray's z at 1, and 0 outside [min_range, max_range)
    pose = camera.optical_pose((1.8, 0.0, 0.0))
    # the mount 0.29 m left of the robot, 0.4 m up, turned 90 deg left: the optical axis along
    # +y, the image's right along +x, its down along -z (by hand)
    np.testing.assert_allclose(pose[:3, 3], [1.8, 0.29, 0.4], atol=1e-12)
    np.testing.assert_allclose(pose[:3, :3], [[1, 0, 0], [0, 0, 1], [0, -1, 0]], atol=1e-12)
    fx, fy, cx, cy = camera.intrinsics()
    v, u = np.mgrid[0 : depth.shape[0], 0 : depth.shape[1]]
    rays = np.stack([(u + 0.5 - cx) / fx, (v + 0.5 - cy) / fy, np.ones(u.shape)], -1).reshape(-1, 3)
    norm = np.linalg.norm(rays, axis=1)
    directions = (rays / norm[:, None]) @ pose[:3, :3].T
    origins = np.tile(pose[:3, 3], (len(rays), 1))
    ranges = np.asarray(scene.world.cast_many(origins, directions, 10.0 * norm.max()))
    z = np.minimum(ranges, 10.0 * norm) / norm
    want = np.where((z >= 0.5) & (z < 10.0), z, 0.0).reshape(depth.shape)
    np.testing.assert_allclose(depth, want, rtol=0, atol=1e-5)


def test_tilting_laser_follows_equation_two():
    # eq. 2's magnitudes with theta < 0 looking down (kiseki.sim.tilting_laser says why)
    exact = dict(noise_sd=0.0, gyro_sd_deg=0.0, gyro_bias_sd_deg_s=0.0, gyro_arw_deg_rt_s=0.0)
    params = TiltingLaserParams(**exact)
    laser = TiltingLaser(params, seed=0)
    sensor = np.eye(4)
    sensor[2, 3] = 1.0  # 1 m above the floor, looking along +x at a wall at x = 3
    ranges, gyro = laser.scan(wall_world(3.0), sensor, 100.0)
    tilt, scan = params.grid()
    i0, j0 = int(np.argmin(np.abs(tilt))), int(np.argmin(np.abs(scan)))
    assert ranges[i0, j0] == pytest.approx(3.0, abs=1e-9)  # horizontal ray hits the wall
    i30 = int(np.argmin(np.abs(tilt + math.radians(30))))
    assert ranges[i30, j0] == pytest.approx(1.0 / math.sin(math.radians(30)), abs=1e-9)  # floor
    down = int(np.argmin(np.abs(tilt + math.radians(90))))
    assert ranges[down, j0] == pytest.approx(1.0, abs=1e-9)  # straight down
    up = int(np.argmin(np.abs(tilt - math.radians(30))))
    assert ranges[up, j0] == pytest.approx(3.0 / math.cos(math.radians(30)), abs=1e-9)  # wall
    np.testing.assert_allclose(gyro, 0.0, atol=1e-12)


@pytest.mark.parametrize(
    ("patch", "match"),
    [
        ({"colour": "red"}, "colour: unknown key"),
        (
            {"objects": [{"type": "box", "center": [1, 1], "size": [1, -1, 1]}]},
            r"objects\[0\]\.size\[1\]: must be greater than 0, got -1",
        ),
        ({"objects": [{"type": "teapot", "center": [1, 1]}]}, "unknown type"),
        (
            {"objects": [{"type": "wall", "from": [0, 0], "to": [1, 0], "hue": 3}]},
            r"objects\[0\]\.hue: unknown key",
        ),
        ({"robot": {"type": "diff_drive", "start": [0.5, 0.0, 0.0]}}, "overlaps an obstacle"),
        (
            {"sensors": [{"type": "laser", "name": "s", "mount": [3.0, 0.0, 0.4]}]},
            "outside the robot",
        ),
        ({"sensors": [{"type": "sonar", "name": "s", "mount": [0.0, 0.0, 0.4]}]}, "unknown sensor"),
        (
            {
                "sensors": [
                    {"type": "laser", "name": "s", "mount": [0.0, 0.0, 0.4], "params": {"beams": 0}}
                ]
            },
            "beams",
        ),
        ({"robot": {"type": "tank"}}, "diff_drive or omni"),
        ({"robots": [{"name": "a", "start": [2, 2, 0]}]}, "not both"),
        ({"sensors": [{"type": "bearing", "name": "b", "targets": ["ghost"]}]}, "other robots"),
        ({"point_robots": "yes"}, "point_robots"),
        (
            {"objects": [{"type": "shelf", "center": [2, 2], "size": [1, 0.4], "levels": 3000}]},
            r"objects\[0\]\.levels: must be less than or equal to 50, got 3000",
        ),
        (
            {"objects": [{"type": "shelf", "center": [2, 2], "size": [1, 0.4], "items": 3000}]},
            r"objects\[0\]\.items: must be less than or equal to 100, got 3000",
        ),
        ({"bounds": [1, 2]}, r"bounds: must be a mapping, got \[1, 2\]"),
        ({"bounds": {"max": [4, 4, 2]}}, r"bounds\.min: missing"),
        (
            {"grid_resolution": 1.0e-9},
            r"grid_resolution: resolution 1e-09 m .* limit of 1e\+08 cells, got 1e-09",
        ),
        (
            {"grid_resolution": 100.0},
            r"grid_resolution: .*at least 2 cells across are needed, got 100\.0",
        ),
    ],
)
def test_bad_scenes_are_rejected_with_the_file_named(tmp_path, patch, match):
    doc = {
        "name": "t",
        "bounds": {"min": [-2, -2, -0.1], "max": [4, 4, 2]},
        "floor": True,
        "objects": [{"type": "box", "center": [0.5, 0.0], "size": [0.4, 0.4, 1.0]}],
        "robot": {"type": "diff_drive", "start": [2.0, 2.0, 0.0]},
        "route": {"waypoints": [[2, 2], [3, 2]]},
    }
    doc.update(patch)
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(doc))
    with pytest.raises(ValueError, match=match) as info:
        simulate(load_scene(path), tmp_path / "r.mcap", SimConfig(duration=0.5), progress=False)
    assert "bad.yaml" in str(info.value)


def test_cli_run_render_and_bad_commands(tmp_path):
    scene = WORLDS[[p.stem for p in WORLDS].index("speed_corner")]
    cmd = [sys.executable, "-m", "kiseki.cli", "sim"]
    (tmp_path / "cmd.csv").write_text("t,vx,vy,w\n0,0.3,0,0\n2,0,0,0.5\n")
    done = subprocess.run(
        [
            *cmd,
            "run",
            str(scene),
            "-o",
            str(tmp_path / "r.mcap"),
            "--controller",
            "commands",
            "--commands",
            str(tmp_path / "cmd.csv"),
            "--duration",
            "3",
        ],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr
    done = subprocess.run(
        [*cmd, "render", str(tmp_path / "r.mcap"), "-o", str(tmp_path / "r.gif")],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "r.gif").read_bytes()[:6] in (b"GIF89a", b"GIF87a")
    (tmp_path / "nan.csv").write_text("t,vx,vy,w\n0,nan,0,0\n")
    done = subprocess.run(
        [
            *cmd,
            "run",
            str(scene),
            "-o",
            str(tmp_path / "n.mcap"),
            "--controller",
            "commands",
            "--commands",
            str(tmp_path / "nan.csv"),
        ],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 1
    assert f"{tmp_path / 'nan.csv'}:2: vx: must be a finite number, got 'nan'" in done.stderr
    done = subprocess.run(
        [*cmd, "run", str(scene), "-o", str(tmp_path / "r.mcap")], capture_output=True, text=True
    )
    assert done.returncode == 1 and "exists" in done.stderr  # nothing overwritten by accident


def test_a_simulated_run_replays_through_the_dataset_interface(tmp_path):
    scene = load_scene(WORLDS[[p.stem for p in WORLDS].index("factory_corridor")])
    simulate(scene, tmp_path / "run.mcap", SimConfig(duration=6.0, seed=2), progress=False)
    scans = open_scans(tmp_path / "run.mcap")
    assert scans.ranges.shape == (61, 1081) and scans.max_range == 30.0
    np.testing.assert_allclose(scans.poses[0], [0.45, 0.0, 0.0], atol=1e-9)  # laser 0.45 m ahead
    assert np.abs(scans.odometry[-1, :2] - scans.poses[-1, :2]).max() < 0.5
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "kiseki.cli",
            "map",
            "from-log",
            str(tmp_path / "run.mcap"),
            "-o",
            str(tmp_path / "m.yaml"),
        ],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr
    grid = load_map(tmp_path / "m.yaml")
    share = endpoint_agreement(grid, scans.poses, scans.ranges, scans.angles, scans.max_range)
    assert share > 0.99


def test_mutual_bearings_of_three_robots_match_the_geometry(tmp_path):
    # The paper's robots are points: its leapfrog plan drives r3 0.54 m past r2's centre and
    # later r2 straight through r3 (both on the rail x = 1); the scene says point_robots, so
    # their bodies do not collide with each other (they would: see below).
    scene = load_scene(WORLDS[[p.stem for p in WORLDS].index("coop_three_robots")])
    summary = simulate(scene, tmp_path / "coop.mcap", SimConfig(seed=7), progress=False)
    assert summary.reached_goal and summary.collision is None
    solid = dataclasses.replace(scene, point_robots=False)
    stopped = simulate(solid, tmp_path / "solid.mcap", SimConfig(seed=7), progress=False)
    assert not stopped.reached_goal
    assert {stopped.collision.robot, stopped.collision.hit} == {"r2", "r3"}
    run = read_run(tmp_path / "coop.mcap")
    truth = {n: run.messages(f"/{n}/ground_truth") for n in ("r1", "r2", "r3")}
    errors, hidden = [], 0
    for observer in ("r1", "r2", "r3"):
        for i, (_, msg) in enumerate(run.messages(f"/{observer}/bearings")):
            me = truth[observer][i][1]["pose"]
            x, y = me["position"]["x"], me["position"]["y"]
            yaw = 2 * math.atan2(me["orientation"]["z"], me["orientation"]["w"])
            for target, measured in zip(msg["targets"], msg["bearings"], strict=True):
                other = truth[target][i][1]["pose"]["position"]
                (third,) = {"r1", "r2", "r3"} - {observer, target}
                c = truth[third][i][1]["pose"]["position"]
                # the third robot's body (0.3 m) on the line of sight hides the target
                a, b, q = (
                    np.array([x, y]),
                    np.array([other["x"], other["y"]]),
                    np.array([c["x"], c["y"]]),
                )
                lam = np.clip((q - a) @ (b - a) / ((b - a) @ (b - a)), 0, 1)
                blocked = np.linalg.norm(q - a - lam * (b - a)) < 0.3
                assert (measured is None) == blocked, (observer, target, i)
                if measured is None:
                    hidden += 1
                    continue
                expected = math.atan2(other["y"] - y, other["x"] - x) - yaw
                errors.append(math.remainder(measured - expected, 2 * math.pi))
    assert hidden > 0  # r3 drives between r1 and r2
    errors = np.degrees(errors)
    assert len(errors) > 300
    assert abs(errors.std() - 0.1) < 0.1 * 4 / math.sqrt(2 * len(errors)) + 0.005
    assert abs(errors.mean()) < 4 * 0.1 / math.sqrt(len(errors))


def test_scene_files_of_random_bytes_are_named_and_yaml_1_2_numbers_read(tmp_path):
    path = tmp_path / "noise.yaml"
    path.write_bytes(bytes(range(256)) * 4)
    with pytest.raises(ValueError, match=r"noise\.yaml: not a scene file \(not UTF-8 text\)"):
        load_scene(path)
    text = WORLDS[[p.stem for p in WORLDS].index("factory_corridor")].read_text()
    assert "grid_resolution: 0.05\n" in text
    path.write_text(text.replace("grid_resolution: 0.05\n", "grid_resolution: 2.5e-2\n"))
    assert load_scene(path).grid_resolution == 0.025  # YAML 1.1 would read a string
