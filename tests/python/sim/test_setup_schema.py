# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The robots and sensors sections of a scene file (kiseki.sim.setup_schema, checked by
kiseki.sim.setup): the scenes of data/worlds build the robots and sensors written out here, every
limit is enforced with the limit in the message, and a wrong value is named with its path."""

from __future__ import annotations

import copy
import math
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from kiseki.core import Random, derive_seed
from kiseki.sim.robot_params import DiffDriveParams, OdometryErrorParams, OmniParams
from kiseki.sim.scene import load_scene
from kiseki.sim.sensors import (
    LASER_PRESETS,
    BearingParams,
    DepthCameraParams,
    Mount,
)
from kiseki.sim.setup import build_robot, build_sensors
from kiseki.sim.tilting_laser import TiltingLaserParams

ROOT = Path(__file__).resolve().parents[3]
WORLDS = ROOT / "data" / "worlds"

BASE = {
    "name": "t",
    "bounds": {"min": [-2, -2, -0.1], "max": [4, 4, 2]},
    "floor": True,
    "objects": [{"type": "box", "center": [0.5, 0.0], "size": [0.4, 0.4, 1.0]}],
    "robot": {"type": "diff_drive", "start": [2.0, 2.0, 0.0]},
    "sensors": [{"type": "laser", "name": "scan", "mount": [0.3, 0.0, 0.4]}],
    "route": {"waypoints": [[2, 2], [3, 2]]},
}


def _build(tmp_path, edit=None, index=0, seed=0):
    doc = copy.deepcopy(BASE)
    if edit is not None:
        edit(doc)
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(doc))
    scene = load_scene(path)
    robot = build_robot(scene, seed, index)
    return robot, build_sensors(scene, robot, seed, 0.1, index)


def _sensor(**keys):
    return lambda d: d["sensors"][0].update(keys)


def _two_robots(d):
    sensors = [{"type": "bearing", "name": "b", "targets": ["a"]}]
    d.pop("robot"), d.pop("sensors"), d.pop("route")
    d["robots"] = [
        {"name": "a", "start": [2, 2, 0], "route": {"waypoints": [[2, 2], [3, 2]]}},
        {"name": "b", "start": [2, 3.5, 0], "sensors": sensors, "route": {}},
    ]


# ------------------------------------------------------------------- the scenes of data/worlds


def _scene(name):
    return load_scene(WORLDS / f"{name}.yaml")


def test_factory_corridor_builds_its_agv_laser_and_two_cameras():
    scene = _scene("factory_corridor")
    robot = build_robot(scene, 7)
    sensors = build_sensors(scene, robot, 7, 0.1)
    assert (robot.kind, robot.robot.params) == ("diff_drive", DiffDriveParams())
    assert robot.odometry.error_params == OdometryErrorParams()
    assert (robot.length, robot.width, robot.height) == (1.05, 0.58, 0.99)
    assert [s.name for s in sensors] == ["scan", "depth_left", "depth_right"]
    laser, left, right = sensors
    assert laser.device.params == LASER_PRESETS["hokuyo_utm30lx"] and laser.period == 0.1
    assert laser.mount == Mount(0.45, 0.0, 0.4, 0.0, 0.0)
    assert left.device.params == DepthCameraParams(width=160, height=120)
    assert right.mount == Mount(0.0, -0.29, 0.4, -90.0, 0.0) and right.period == 0.1
    # each sensor's own stream: derive_seed(seed, 100 * robot + sensor)
    for i, s in enumerate(sensors):
        assert list(s.device.rng.normal(0, 1, 3)) == list(Random(derive_seed(7, i)).normal(0, 1, 3))


def test_magnetic_floor_builds_both_mappers_and_the_arm():
    scene = _scene("magnetic_floor")
    small = build_robot(scene, 0, 0)
    assert small.robot.params == DiffDriveParams(length=0.7, width=0.6, height=0.5)
    assert small.robot.pose.x == 1.2 and small.robot.pose.y == 7.5
    big = build_robot(scene, 0, 1)
    sensors = build_sensors(scene, big, 0, 0.05, 1)
    assert [(s.kind, s.name, s.period) for s in sensors] == [
        ("laser", "scan", 0.05),
        ("magnetometer", "arm_near", 0.1),  # rate_hz: 10
        ("magnetometer", "arm_far", 0.1),
    ]
    assert sensors[1].mount == Mount(0.4, 0.0, 1.05)


def test_coop_speed_and_rubble_scenes():
    coop = _scene("coop_three_robots")
    robot = build_robot(coop, 3, 1)
    assert robot.kind == "omni" and robot.robot.params == OmniParams()
    assert robot.robot.pose.theta == pytest.approx(math.pi / 2)
    (bearing,) = build_sensors(coop, robot, 3, 0.1, 1)
    assert bearing.targets == ("r1", "r3") and bearing.device.params == BearingParams()
    speed = _scene("speed_corner")
    (laser,) = build_sensors(speed, build_robot(speed, 0), 0, 0.05)
    assert laser.device.params == LASER_PRESETS["speed_lrf"] and laser.period == 0.1
    rubble = _scene("rubble_a")
    (tilt,) = build_sensors(rubble, build_robot(rubble, 0), 0, 0.1)
    assert tilt.device.params == TiltingLaserParams() and tilt.period == 1e9


def test_params_override_the_preset_and_defaults(tmp_path):
    _, (laser,) = _build(tmp_path, _sensor(preset="sick_lms", params={"beams": 181}, rate_hz=5))
    assert laser.device.params == LASER_PRESETS["sick_lms"].__class__(
        "sick_lms", 180.0, 181, 8.0, 0.005, period=1 / 37.5
    )
    assert laser.period == 0.2
    camera = {"type": "depth_camera", "name": "c", "width": 80, "params": {"max_range": 5}}
    _, (cam,) = _build(tmp_path, lambda d: d.update(sensors=[camera]))
    assert cam.device.params == DepthCameraParams(width=80, max_range=5.0)
    robot, _ = _build(tmp_path, lambda d: d["robot"].update(params=None, odometry_errors={}))
    assert robot.robot.params == DiffDriveParams()  # an empty section keeps the defaults


# ------------------------------------------------------------------------------------- limits


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (_sensor(params={"beams": 10_001}), r"sensors\[0\]\.params\.beams: .*10000, got 10001"),
        (_sensor(rate_hz=1000.5), r"sensors\[0\]\.rate_hz: .* 1000, got 1000\.5"),
        (
            _sensor(params={"max_range": 1e4}),
            r"sensors\[0\]\.params\.max_range: .* 1000, got 10000\.0",
        ),
        (
            lambda d: d.update(sensors=[{"type": "depth_camera", "height": 5000}]),
            r"sensors\[0\]\.height: .*4096, got 5000",
        ),
        (
            lambda d: d.update(sensors=[{"type": "depth_camera", "width": 700}]),
            r"sensors\[0\]: width 700 must be at most params.native_width 640",
        ),
        (
            lambda d: d.update(sensors=[{"type": "tilting_laser", "params": {"step_deg": 0.15}}]),
            r"sensors\[0\]\.params: step_deg 0\.15 gives 1,202,201 rays .* 1,000,000",
        ),
        (
            lambda d: d.update(sensors=[{"type": "bearing", "name": f"b{i}"} for i in range(51)]),
            r"sensors: at most 50 sensors per robot, got 51",
        ),
    ],
)
def test_limits_are_enforced_with_the_limit_named(tmp_path, edit, message):
    with pytest.raises(ValueError, match=rf"^\S*bad\.yaml: {message}"):
        _build(tmp_path, edit)


def test_a_sweep_at_the_limit_is_taken(tmp_path):
    # 0.15 deg: 1001 x 1201 = 1,202,201 rays is over; 0.2 deg: 751 x 901 = 676,651 is under
    sweep = {"type": "tilting_laser", "params": {"step_deg": 0.2}}
    _, (tilt,) = _build(tmp_path, lambda d: d.update(sensors=[sweep]))
    tilt_angles, scan_angles = tilt.device.params.grid()
    assert len(tilt_angles) * len(scan_angles) == tilt.device.params.ray_count == 676_651


# ---------------------------------------------------------------- wrong values, named by path


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (lambda d: d["robot"].update(start=[0, math.nan, 0]), r"robot\.start\[1\]: .*finite"),
        (lambda d: d["robot"].update(start=[0, 0]), r"robot\.start: .*at least 3 items"),
        (lambda d: d["robot"].update(type="tank"), r"robot\.type: must be diff_drive or omni"),
        (lambda d: d["robot"].update(colour=1), r"robot\.colour: unknown key"),
        (
            lambda d: d["robot"].update(params={"max_speed": "fast"}),
            r"robot\.params\.max_speed: must be a valid number, got 'fast'",
        ),
        (
            lambda d: d["robot"].update(type="omni", odometry_errors={"slip_distance_coeff": 1}),
            r"robot\.odometry_errors\.slip_distance_coeff: unknown key",
        ),
        (_sensor(type="sonar"), r"sensors\[0\]\.type: unknown sensor type, must be one of laser"),
        (_sensor(rate_hz="10"), r"sensors\[0\]\.rate_hz: must be a valid number, got '10'"),
        (_sensor(mount=[0, 0, math.inf]), r"sensors\[0\]\.mount\[2\]: .*finite number, got inf"),
        (_sensor(name=5), r"sensors\[0\]\.name: must be a valid string, got 5"),
        (_sensor(preset="lms"), r"sensors\[0\]\.preset: must be one of sick_lms, hokuyo"),
        (_sensor(params={"beams": 1.5}), r"sensors\[0\]\.params\.beams: .*integer, got 1\.5"),
        (
            _sensor(params={"dropout_probability": 1.0}),
            r"sensors\[0\]\.params\.dropout_probability: .*less than 1",
        ),
        # options of another sensor type
        (_sensor(targets=["x"]), r"sensors\[0\]\.targets: unknown key"),
        (_sensor(width=10), r"sensors\[0\]\.width: unknown key"),
        (_sensor(arm={"sensor": "near"}), r"sensors\[0\]\.arm: unknown key"),
        (
            lambda d: d.update(sensors=[{"type": "bearing", "preset": "sick_lms"}]),
            r"sensors\[0\]\.preset: unknown key",
        ),
        # what depends on the rest of the scene
        (_sensor(mount=[3.0, 0, 0.4]), r"sensors\[0\]\.mount: lies outside the robot"),
        (
            lambda d: d["sensors"].append({"type": "laser", "name": "scan"}),
            r"sensors: sensor names must be unique, got \['scan', 'scan'\]",
        ),
        (
            lambda d: d.update(sensors=[{"type": "bearing", "targets": ["ghost"]}]),
            r"sensors\[0\]\.targets: must be other robots of the scene \(none\)",
        ),
        (
            lambda d: d.update(sensors=[{"type": "magnetometer"}]),
            r"sensors\[0\]: a magnetometer needs the scene's 'magnetic' section",
        ),
    ],
)
def test_a_wrong_value_is_named_with_its_path(tmp_path, edit, message):
    with pytest.raises(ValueError, match=rf"^\S*bad\.yaml: {message}"):
        _build(tmp_path, edit)


def test_several_robots_are_named_by_their_place_in_robots(tmp_path):
    robot, (bearing,) = _build(tmp_path, _two_robots, index=1)
    assert robot.name == "b" and bearing.targets == ("a",)

    def bad_rate(d):
        _two_robots(d)
        d["robots"][1]["sensors"][0]["rate_hz"] = -1

    with pytest.raises(ValueError, match=r"bad\.yaml: robots\[1\]\.sensors\[0\]\.rate_hz: "):
        _build(tmp_path, bad_rate, index=1)

    def bad_params(d):
        _two_robots(d)
        d["robots"][0]["params"] = {"width": math.nan}

    with pytest.raises(ValueError, match=r"bad\.yaml: robots\[0\]\.params\.width: .*, got nan"):
        _build(tmp_path, bad_params, index=0)


@pytest.mark.parametrize("seed", [-1, 2**64, True, 1.0, "1"])
def test_seeds_outside_0_to_2_64_are_refused(tmp_path, seed):
    with pytest.raises(ValueError, match=r"seed must be an integer in \[0, 2\*\*64\), got "):
        _build(tmp_path, seed=seed)


def test_the_largest_seed_is_taken(tmp_path):
    robot, (laser,) = _build(tmp_path, seed=2**64 - 1)
    assert laser.device.params == LASER_PRESETS["hokuyo_utm30lx"]


# ------------------------------------------------------- checked when the scene is loaded


def _load(tmp_path, edit):
    doc = copy.deepcopy(BASE)
    edit(doc)
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(doc))
    return load_scene(path)


def _second_robot_rate(d):
    _two_robots(d)
    d["robots"][1]["sensors"][0]["rate_hz"] = -1


LASER = {"type": "laser"}


def _targets_itself(d):
    _two_robots(d)
    d["robots"][1]["sensors"][0]["targets"] = ["b"]


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (_sensor(rate_hz=-1), r"sensors\[0\]\.rate_hz: must be greater than 0, got -1$"),
        (_second_robot_rate, r"robots\[1\]\.sensors\[0\]\.rate_hz: must be .* than 0, got -1$"),
        (lambda d: d["robot"].update(type="tank"), r"robot\.type: must be diff_drive or omni"),
        (
            lambda d: d.update(sensors=[{"type": "bearing", "name": f"b{i}"} for i in range(51)]),
            r"sensors: at most 50 sensors per robot, got 51$",
        ),
        (
            lambda d: d["sensors"].append({"type": "laser", "name": "scan"}),
            r"sensors: sensor names must be unique, got \['scan', 'scan'\]$",
        ),
        (  # an unnamed sensor is sensor<index>
            lambda d: d["sensors"].extend([{"type": "laser", "name": "sensor2"}, LASER]),
            r"sensors: sensor names must be unique, got \['scan', 'sensor2', 'sensor2'\]$",
        ),
        (
            lambda d: d.update(sensors=[{"type": "bearing", "targets": ["ghost"]}]),
            r"sensors\[0\]\.targets: must be other robots of the scene \(none\), got \['ghost'\]$",
        ),
        (
            lambda d: d.update(sensors=[{"type": "bearing"}]),  # all others: none here
            r"sensors\[0\]\.targets: must be other robots of the scene \(none\), got \[\]$",
        ),
        (
            _targets_itself,
            r"robots\[1\]\.sensors\[0\]\.targets: must be other robots of the scene \(a\), got",
        ),
        (
            lambda d: d.update(sensors=[{"type": "magnetometer"}]),
            r"sensors\[0\]: a magnetometer needs the scene's 'magnetic' section, got",
        ),
    ],
)
def test_robots_and_sensors_are_checked_when_the_scene_is_loaded(tmp_path, edit, message):
    with pytest.raises(ValueError, match=rf"^\S*bad\.yaml: {message}"):
        _load(tmp_path, edit)


def test_sim_show_refuses_a_bad_sensor_in_one_line(tmp_path):
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump({**BASE, "sensors": [{"type": "laser", "rate_hz": -1}]}))
    done = subprocess.run(
        [sys.executable, "-m", "kiseki.cli", "sim", "show", str(path), "-o", "s.png"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
    )
    assert done.returncode == 1 and not (tmp_path / "s.png").exists()
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and f"{path}: sensors[0].rate_hz: " in lines[0], done.stderr
    assert lines[0].endswith("must be greater than 0, got -1")
