# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Builds a scene's robot, odometry and sensors from its file, checking that the robot starts
in free space and that every sensor sits on the robot.

A magnetometer with an ``arm`` mapping is one of the two sensors on the bar of the 3-D mapping
robot's 2-DOF arm (kiseki.sim.magnetic_arm): its ``mount`` is the arm's pivot, and the arm
carries it up to ``heights[1]`` whatever the robot's height. Both sensors of one arm (same
pivot) must give the same bar.

Each robot and sensor entry, with the rules that depend on the rest of the scene (the sensor
count, unique names, bearing targets, a magnetometer's magnetic section), is checked when the
scene is loaded (kiseki.sim.setup_schema.check_robots), so a problem reads
``FILE: robots[1].sensors[0].rate_hz: must be ..., got VALUE``; the mount on the robot and one
bar per pivot are checked here with the same form of message. The entries are read again
through their models here to build them."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from kiseki._support.counts import check_count
from kiseki._support.real_numbers import check_number
from kiseki._support.schema import SchemaError, location_text, parse
from kiseki.core import check_seed, derive_seed
from kiseki.sim.collisions import check_free_start
from kiseki.sim.magnetic import MagneticWorld, Magnetometer
from kiseki.sim.magnetic_arm import arm_sensor_from_spec
from kiseki.sim.odometry import OmniOdometry, WheelOdometry
from kiseki.sim.robot import DiffDriveRobot, OmniRobot
from kiseki.sim.scene import Scene
from kiseki.sim.sensors import BearingSensor, DepthCamera, Laser2D, Mount
from kiseki.sim.setup_schema import (
    ROBOT_MODELS,
    SENSOR_MODELS,
    BearingSpec,
    DepthCameraSpec,
    DiffDriveSpec,
    LaserSpec,
    MagnetometerSpec,
    RobotKind,
    SensorKind,
    TiltingLaserSpec,
)
from kiseki.sim.tilting_laser import TiltingLaser

__all__ = ["RobotSetup", "SensorSetup", "build_robot", "build_sensors"]


@dataclass
class RobotSetup:
    name: str
    kind: str  # "diff_drive" or "omni"
    robot: Any
    odometry: Any
    length: float
    width: float
    height: float

    @property
    def footprint(self) -> tuple[float, float]:
        """(length, width) in m: the robot's body seen from above, centred on its pose."""
        return (self.length, self.width)


@dataclass
class SensorSetup:
    kind: str
    name: str
    device: Any
    period: float  # seconds between readings
    mount: Mount
    targets: tuple[str, ...] = ()  # bearing sensors: the robots they measure


def _robot_at(scene: Scene, index: int) -> tuple[str | int, ...]:
    """Where robot ``index`` is in the scene file: ``robot`` or ``robots[index]``."""
    index = check_count(index, f"{scene.path}: robot index", 0, len(scene.robot_specs) - 1)
    single = len(scene.robot_specs) == 1 and scene.robot_specs[0]["name"] == "robot"
    return ("robot",) if single else ("robots", index)


def _fail(scene: Scene, at: tuple[str | int, ...], problem: str) -> SchemaError:
    return SchemaError(f"{scene.path}: {location_text(at)}: {problem}")


def build_robot(scene: Scene, seed: int, index: int = 0) -> RobotSetup:
    """The robot `index` of the scene (its true motion and its odometry)."""
    seed = check_seed(seed)
    at = _robot_at(scene, index)
    name, spec = scene.robot_specs[index]["name"], scene.robot_specs[index]["robot"]
    kind = parse(RobotKind, spec, scene.path, at=at).type
    checked = parse(ROBOT_MODELS[kind], spec, scene.path, at=at)
    x, y, yaw_deg = checked.start
    pose = np.array([x, y, math.radians(yaw_deg)])
    odo_seed = derive_seed(seed, 1000 + index)
    if isinstance(checked, DiffDriveSpec):
        params, errors = checked.params, checked.odometry_errors
        setup = RobotSetup(
            name,
            kind,
            DiffDriveRobot(params, pose),
            WheelOdometry(params, errors, odo_seed, pose),
            params.length,
            params.width,
            params.height,
        )
    else:
        omni, omni_errors = checked.params, checked.odometry_errors
        setup = RobotSetup(
            name,
            kind,
            OmniRobot(omni, pose),
            OmniOdometry(omni_errors, odo_seed, pose),
            omni.length,
            omni.width,
            1.2,
        )
    check_free_start(scene, pose, setup.length, setup.width, setup.height)
    return setup


def _mount(spec: Any, scene: Scene, at: tuple[str | int, ...], robot: RobotSetup) -> Mount:
    values = list(spec.mount)
    mount = Mount(*values[:3], values[3] if len(values) == 4 else 0.0, spec.pitch, spec.roll)
    margin = 0.1
    if (
        abs(mount.x) > robot.length / 2 + margin
        or abs(mount.y) > robot.width / 2 + margin
        or not 0.0 <= mount.z <= robot.height + 0.5
    ):
        raise _fail(
            scene,
            (*at, "mount"),
            f"lies outside the robot ({robot.length} x {robot.width} x {robot.height} m, "
            f"{margin} m around it and 0.5 m above), got {values}",
        )
    return mount


def _same_bar(arms: dict, mount: Mount, arm: dict, fail) -> None:
    """Both sensors on one pivot share one bar and are its near and its far sensor."""
    pivot = (mount.x, mount.y, mount.z, mount.yaw_deg)
    bar = {k: v for k, v in arm.items() if k != "sensor"}
    seen, names = arms.setdefault(pivot, (bar, set()))
    if seen != bar:
        raise fail("differs from the other sensor's on the same pivot")
    if arm["sensor"] in names:
        raise fail(f"a second {arm['sensor']} sensor on the same pivot")
    names.add(arm["sensor"])


def build_sensors(
    scene: Scene, robot: RobotSetup, seed: int, dt: float, index: int = 0
) -> list[SensorSetup]:
    """The sensors of robot `index`; each gets its own seeded stream."""
    seed = check_seed(seed)
    check_number(dt, f"{scene.path}: dt", 0.0, low_open=True, unit="s")
    robot_at = _robot_at(scene, index)
    out: list[SensorSetup] = []
    magnetic = (
        MagneticWorld.from_dict(
            scene.magnetic, str(scene.path), at=("magnetic",), variant=scene.variant
        )
        if scene.magnetic
        else None
    )
    others = {s["name"] for s in scene.robot_specs} - {robot.name}
    arms: dict[tuple, tuple[dict, set]] = {}  # pivot -> (bar, sensors on it)
    sensors_at = (*robot_at, "sensors") if robot_at != ("robot",) else ("sensors",)
    for i, raw in enumerate(scene.robot_specs[index]["sensors"]):
        at = (*sensors_at, i)
        kind = parse(SensorKind, raw, scene.path, at=at).type
        spec = parse(SENSOR_MODELS[kind], raw, scene.path, at=at)
        name = spec.name if spec.name is not None else f"sensor{i}"
        mount = _mount(spec, scene, at, robot)
        s = derive_seed(seed, 100 * index + i)
        targets: tuple[str, ...] = ()
        if isinstance(spec, LaserSpec):
            assert spec.params is not None  # the preset's when not given
            device: Any = Laser2D(spec.params, mount, s)
            default = max(dt, spec.params.period)
        elif isinstance(spec, DepthCameraSpec):
            camera = spec.camera
            device, default = DepthCamera(camera, mount, s), max(dt, camera.period)
        elif isinstance(spec, MagnetometerSpec):
            assert magnetic is not None  # load_scene checks that the scene has a field
            position, yaw = (mount.x, mount.y, mount.z), math.radians(mount.yaw_deg)
            if spec.arm is not None:
                where = f"{scene.path}: {location_text((*at, 'arm'))}"
                device = arm_sensor_from_spec(
                    spec.arm, magnetic, position, yaw, s, where, **spec.params
                )
                _same_bar(arms, mount, spec.arm, lambda p, a=at: _fail(scene, (*a, "arm"), p))
            else:
                device = Magnetometer(magnetic, position, yaw, seed=s, **spec.params)
            default = dt
        elif isinstance(spec, BearingSpec):
            targets = tuple(spec.targets or sorted(others))  # checked by load_scene
            device, default = BearingSensor(spec.params, s), dt
        else:
            assert isinstance(spec, TiltingLaserSpec)
            device = TiltingLaser(spec.params, s)
            default = 1e9  # by default once, at the start
        period = default if spec.rate_hz is None else 1.0 / spec.rate_hz
        out.append(SensorSetup(kind, name, device, period, mount, targets))
    return out
