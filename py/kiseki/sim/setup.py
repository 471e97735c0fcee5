# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Builds a scene's robot, odometry and sensors from its file, checking that the robot starts
in free space and that every sensor sits on the robot.

A magnetometer with an ``arm`` mapping is one of the two sensors on the bar of the 3-D mapping
robot's 2-DOF arm (kiseki.sim.magnetic_arm): its ``mount`` is the arm's pivot, and the arm
carries it up to ``heights[1]`` whatever the robot's height. Both sensors of one arm (same
pivot) must give the same bar."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from kiseki.core import derive_seed
from kiseki.sim import robot as robots
from kiseki.sim.collisions import check_free_start
from kiseki.sim.magnetic import MagneticWorld, Magnetometer
from kiseki.sim.magnetic_arm import arm_sensor_from_spec
from kiseki.sim.scene import Scene
from kiseki.sim.sensors import (
    LASER_PRESETS,
    BearingParams,
    BearingSensor,
    DepthCamera,
    DepthCameraParams,
    Laser2D,
    Mount,
    TiltingLaser,
    TiltingLaserParams,
    with_overrides,
)

__all__ = ["RobotSetup", "SensorSetup", "build_robot", "build_sensors"]

ROBOT_KEYS = {"type", "start", "params", "odometry_errors"}
SENSOR_KEYS = {
    "type",
    "name",
    "mount",
    "preset",
    "params",
    "rate_hz",
    "width",
    "height",
    "pitch",
    "targets",
    "arm",
}


@dataclass
class RobotSetup:
    name: str
    kind: str  # "diff_drive" or "omni"
    robot: Any
    odometry: Any
    length: float
    width: float
    height: float


@dataclass
class SensorSetup:
    kind: str
    name: str
    device: Any
    period: float  # seconds between readings
    mount: Mount
    targets: tuple[str, ...] = ()  # bearing sensors: the robots they measure


def _start(scene: Scene, spec: dict) -> np.ndarray:
    start = spec.get("start", [0.0, 0.0, 0.0])
    try:
        x, y, yaw = (float(v) for v in start)
    except (TypeError, ValueError):
        raise ValueError(f"{scene.path}: robot.start must be [x, y, yaw_deg]") from None
    if not all(math.isfinite(v) for v in (x, y, yaw)):
        raise ValueError(f"{scene.path}: robot.start must be finite")
    return np.array([x, y, math.radians(yaw)])


def build_robot(scene: Scene, seed: int, index: int = 0) -> RobotSetup:
    """The robot `index` of the scene (its true motion and its odometry)."""
    name, spec = scene.robot_specs[index]["name"], scene.robot_specs[index]["robot"]
    where = f"{scene.path}: robot" + (f" {name}" if len(scene.robot_specs) > 1 else "")
    unknown = sorted(set(spec) - ROBOT_KEYS)
    if unknown:
        raise ValueError(f"{where}: unknown key(s) {', '.join(unknown)}")
    kind = spec.get("type", "diff_drive")
    pose = _start(scene, spec)
    odo_seed = derive_seed(seed, 1000 + index)
    if kind == "diff_drive":
        params = robots.DiffDriveParams.from_dict(spec.get("params") or {}, where)
        errors = robots.OdometryErrorParams.from_dict(spec.get("odometry_errors") or {}, where)
        setup = RobotSetup(
            name,
            kind,
            robots.DiffDriveRobot(params, pose),
            robots.WheelOdometry(params, errors, odo_seed, pose),
            params.length,
            params.width,
            params.height,
        )
    elif kind == "omni":
        params = robots.OmniParams.from_dict(spec.get("params") or {}, where)
        errors = robots.OmniOdometryErrorParams.from_dict(spec.get("odometry_errors") or {}, where)
        setup = RobotSetup(
            name,
            kind,
            robots.OmniRobot(params, pose),
            robots.OmniOdometry(errors, odo_seed, pose),
            params.length,
            params.width,
            1.2,
        )
    else:
        raise ValueError(f"{where}: type must be diff_drive or omni, got {kind!r}")
    check_free_start(scene, pose, setup.length, setup.width, setup.height)
    return setup


def _mount(spec: dict, where: str, robot: RobotSetup) -> Mount:
    m = spec.get("mount", [0.0, 0.0, 0.5])
    try:
        values = [float(v) for v in m]
    except (TypeError, ValueError):
        raise ValueError(f"{where}: mount must be [x, y, z] or [x, y, z, yaw_deg]") from None
    if len(values) not in (3, 4) or not all(math.isfinite(v) for v in values):
        raise ValueError(f"{where}: mount must be 3 or 4 finite numbers")
    mount = Mount(
        *values[:3], values[3] if len(values) == 4 else 0.0, float(spec.get("pitch", 0.0))
    )
    margin = 0.1
    if (
        abs(mount.x) > robot.length / 2 + margin
        or abs(mount.y) > robot.width / 2 + margin
        or not 0.0 <= mount.z <= robot.height + 0.5
    ):
        raise ValueError(
            f"{where}: mount ({mount.x}, {mount.y}, {mount.z}) lies outside the robot "
            f"({robot.length} x {robot.width} x {robot.height} m)"
        )
    return mount


def _same_bar(arms: dict, mount: Mount, arm: dict, where: str) -> None:
    """Both sensors on one pivot share one bar and are its near and its far sensor."""
    pivot = (mount.x, mount.y, mount.z, mount.yaw_deg)
    bar = {k: v for k, v in arm.items() if k != "sensor"}
    seen, names = arms.setdefault(pivot, (bar, set()))
    if seen != bar:
        raise ValueError(f"{where}: arm differs from the other sensor's on the same pivot")
    if arm["sensor"] in names:
        raise ValueError(f"{where}: arm: a second {arm['sensor']} sensor on the same pivot")
    names.add(arm["sensor"])


def _period(spec: dict, default: float, where: str) -> float:
    rate = spec.get("rate_hz")
    if rate is None:
        return default
    if isinstance(rate, bool) or not isinstance(rate, int | float) or not rate > 0:
        raise ValueError(f"{where}: rate_hz must be positive")
    return 1.0 / float(rate)


def build_sensors(
    scene: Scene, robot: RobotSetup, seed: int, dt: float, index: int = 0
) -> list[SensorSetup]:
    """The sensors of robot `index`; each gets its own seeded stream."""
    out: list[SensorSetup] = []
    magnetic = MagneticWorld.from_dict(scene.magnetic, str(scene.path)) if scene.magnetic else None
    others = {s["name"] for s in scene.robot_specs} - {robot.name}
    arms: dict[tuple, tuple[dict, set]] = {}  # pivot -> (bar, sensors on it)
    for i, spec in enumerate(scene.robot_specs[index]["sensors"]):
        where = f"{scene.path}: sensors[{i}]" + (
            f" of {robot.name}" if len(scene.robot_specs) > 1 else ""
        )
        if not isinstance(spec, dict):
            raise ValueError(f"{where}: each sensor must be a mapping")
        unknown = sorted(set(spec) - SENSOR_KEYS)
        if unknown:
            raise ValueError(f"{where}: unknown key(s) {', '.join(unknown)}")
        kind, name = spec.get("type"), str(spec.get("name", f"sensor{i}"))
        mount = _mount(spec, where, robot)
        s = derive_seed(seed, 100 * index + i)
        targets: tuple[str, ...] = ()
        overrides = dict(spec.get("params") or {})
        if kind == "laser":
            preset = spec.get("preset", "hokuyo_utm30lx")
            if preset not in LASER_PRESETS:
                raise ValueError(f"{where}: unknown preset {preset!r} ({', '.join(LASER_PRESETS)})")
            params = with_overrides(LASER_PRESETS[preset], overrides, where)
            device = Laser2D(params, mount, s)
            period = _period(spec, max(dt, params.period), where)
        elif kind == "depth_camera":
            for key in ("width", "height"):
                if key in spec:
                    overrides[key] = spec[key]
            params = with_overrides(DepthCameraParams(), overrides, where)
            device = DepthCamera(params, mount, s)
            period = _period(spec, max(dt, params.period), where)
        elif kind == "magnetometer":
            if magnetic is None:
                raise ValueError(f"{where}: a magnetometer needs the scene's 'magnetic' section")
            if "arm" in spec:
                device = arm_sensor_from_spec(
                    spec["arm"],
                    magnetic,
                    (mount.x, mount.y, mount.z),
                    math.radians(mount.yaw_deg),
                    s,
                    f"{where}: arm",
                    **overrides,
                )
                _same_bar(arms, mount, spec["arm"], where)
            else:
                device = Magnetometer(
                    magnetic,
                    (mount.x, mount.y, mount.z),
                    math.radians(mount.yaw_deg),
                    seed=s,
                    **overrides,
                )
            period = _period(spec, dt, where)
        elif kind == "bearing":
            targets = tuple(str(t) for t in spec.get("targets") or sorted(others))
            if not targets or not set(targets) <= others:
                raise ValueError(
                    f"{where}: bearing targets must be other robots of the scene "
                    f"({', '.join(sorted(others)) or 'none'}), got {list(targets)}"
                )
            device = BearingSensor(with_overrides(BearingParams(), overrides, where), s)
            period = _period(spec, dt, where)
        elif kind == "tilting_laser":
            device = TiltingLaser(with_overrides(TiltingLaserParams(), overrides, where), s)
            period = _period(spec, 1e9, where)  # by default once, at the start
        else:
            raise ValueError(f"{where}: unknown sensor type {kind!r}")
        if "targets" in spec and kind != "bearing":
            raise ValueError(f"{where}: only bearing sensors take targets")
        if "arm" in spec and kind != "magnetometer":
            raise ValueError(f"{where}: only magnetometers ride on an arm")
        out.append(SensorSetup(kind, name, device, period, mount, targets))
    names = [s.name for s in out]
    if len(set(names)) != len(names):
        raise ValueError(f"{scene.path}: sensor names must be unique, got {names}")
    return out
