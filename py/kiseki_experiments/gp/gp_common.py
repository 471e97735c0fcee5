# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What the gp-* experiments share (thesis ``002_74cea16d239c028f.txt``, chapter 6): the
simulated scenes, the robots' surveys turned into GP training data in the world frame, the
hyperparameters found on a compact patch of a survey and the 2-D floor map.

Frames: a magnetometer reads in its own frame (x forward, y right, z down, the thesis' 3DM-DH,
see :mod:`kiseki.sim.magnetic`); maps hold the field in the world frame (x east, y north, z up),
so the readings are turned back with the pose the survey knew (the thesis' LIDAR MCL; here the
simulator's true pose, its error is not modelled)."""

from __future__ import annotations

import functools
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from kiseki.gp import ExactGP, HyperparameterFit, SquaredExponential, fit_hyperparameters
from kiseki.magnetic.field_map import MagneticFieldMap
from kiseki.sim.magnetic import DEFAULT_NOISE_SD, MagneticWorld
from kiseki.sim.magnetic_survey import poses_along_route, route_stops
from kiseki.sim.scene import Scene, load_scene
from kiseki.sim.setup import build_robot, build_sensors
from kiseki_experiments.harness.paths import WORLDS
from kiseki_experiments.harness.records import load_average

__all__ = [
    "FLOOR",
    "HALL",
    "SENSOR_NOISE",
    "WORLDS",
    "FloorMap",
    "Survey",
    "arm_to_world",
    "floor_map_2d",
    "free_mask",
    "magnetic_world",
    "patch_hyperparameters",
    "robot_magnetometers",
    "sensor_to_world",
    "survey_2d",
    "survey_3d",
    "voxel_average",
]

HALL = WORLDS / "magnetic_hall.yaml"
FLOOR = WORLDS / "magnetic_floor.yaml"
#: The 3DM-DH's noise, "about 0.01 G" (thesis sec. 6.3.2), the simulator's default.
SENSOR_NOISE = DEFAULT_NOISE_SD


def magnetic_world(scene: Scene) -> MagneticWorld:
    if not scene.magnetic:
        raise ValueError(f"{scene.path}: the scene has no 'magnetic' section")
    return MagneticWorld.from_dict(
        scene.magnetic, str(scene.path), at=("magnetic",), variant=scene.variant
    )


def sensor_to_world(readings: np.ndarray, headings: np.ndarray) -> np.ndarray:
    """(n, 3) readings of a level sensor (x forward, y right, z down) on robots heading
    ``headings`` (n,) rad -> the world frame: y and z flipped (body frame), then Rz(theta)."""
    r = np.asarray(readings, dtype=float)
    c, s = np.cos(headings), np.sin(headings)
    bx, by, bz = r[:, 0], -r[:, 1], -r[:, 2]
    return np.column_stack([c * bx - s * by, s * bx + c * by, bz])


def arm_to_world(readings, headings, yaw, pitch) -> np.ndarray:
    """Readings of a sensor on the 2-DOF arm's bar (kiseki.sim.magnetic_arm: the body frame
    turned by Rz(yaw) Ry(-pitch), then y and z flipped) -> the world frame."""
    r = np.asarray(readings, dtype=float)
    xa, y1, za = r[:, 0], -r[:, 1], -r[:, 2]
    cp, sp, cy, sy = np.cos(pitch), np.sin(pitch), np.cos(yaw), np.sin(yaw)
    x1, bz = cp * xa - sp * za, sp * xa + cp * za  # Ry(-pitch)
    bx, by = cy * x1 - sy * y1, sy * x1 + cy * y1  # Rz(yaw)
    return sensor_to_world(np.column_stack([bx, -by, -bz]), headings)


def robot_magnetometers(scene: Scene, robot: str, seed: int) -> list:
    """The magnetometers (kiseki.sim.setup.SensorSetup) of the scene's robot named `robot`,
    each with its own noise stream from `seed`."""
    names = [spec["name"] for spec in scene.robot_specs]
    if robot not in names:
        raise ValueError(f"{scene.path}: no robot {robot!r} (robots: {', '.join(names)})")
    index = names.index(robot)
    setup = build_robot(scene, seed, index)
    sensors = [s for s in build_sensors(scene, setup, seed, 0.1, index) if s.kind == "magnetometer"]
    if not sensors:
        raise ValueError(f"{scene.path}: robot {robot!r} carries no magnetometer")
    return sensors


def _route(scene: Scene, robot: str) -> tuple[np.ndarray, float]:
    spec = next(s for s in scene.robot_specs if s["name"] == robot)
    route = spec["route"]
    if "waypoints" not in route:
        raise ValueError(f"{scene.path}: robot {robot!r} has no route")
    return np.asarray(route["waypoints"], dtype=float), route["speed"]


@dataclass(frozen=True)
class Survey:
    """GP training data: positions (n, d) m and the field (n, 3) G in the world frame, with the
    number of raw readings behind them and the robot's time and travel."""

    positions: np.ndarray
    field: np.ndarray
    readings: int
    duration: float  # s
    length: float  # m


def _share(share: float) -> float:
    if not 0 < share <= 1:
        raise ValueError(f"share: the part of the route surveyed must lie in (0, 1], got {share}")
    return float(share)


def survey_2d(
    scene: Scene, seed: int, step: float = 0.1, robot: str = "mapper_2d", share: float = 1.0
) -> Survey:
    """The 2-D robot's survey (thesis sec. 6.5.1): a stop every `step` m of its route (of the
    first `share` of it), every magnetometer read there (with its noise); rows ordered stop by
    stop."""
    waypoints, speed = _route(scene, robot)
    poses, travel = route_stops(waypoints, step)
    keep = max(2, int(np.ceil(_share(share) * len(poses))))
    poses, travel = poses[:keep], travel[:keep]
    times = travel / speed
    xy, field = [], []
    for sensor in robot_magnetometers(scene, robot, seed):
        device = sensor.device
        xy.append(device.sensor_positions(poses)[:, :2])
        field.append(sensor_to_world(device.read_many(poses, times), poses[:, 2]))
    positions = np.stack(xy, axis=1).reshape(-1, 2)
    values = np.stack(field, axis=1).reshape(-1, 3)
    return Survey(positions, values, len(values), float(times[-1]), float(travel[-1]))


def voxel_average(positions: np.ndarray, field: np.ndarray, voxel: float):
    """(centres (k, 3), mean field (k, 3), readings per voxel (k,)) of the voxels of size
    `voxel` aligned on the world origin that hold readings, in the order they were first
    entered (the thesis stores its 3-D readings in 0.2 m voxels, sec. 6.5.2)."""
    keys = np.floor(positions / voxel + 1e-9).astype(np.int64)
    unique, first, inverse, counts = np.unique(
        keys, axis=0, return_index=True, return_inverse=True, return_counts=True
    )
    inverse = inverse.reshape(-1)
    sums = np.zeros((len(unique), 3))
    np.add.at(sums, inverse, field)
    order = np.argsort(first)
    centres = (unique[order] + 0.5) * voxel
    return centres, (sums / counts[:, None])[order], counts[order]


def survey_3d(
    scene: Scene,
    seed: int,
    rate_hz: float = 10.0,
    voxel: float = 0.2,
    robot: str = "mapper_3d",
    share: float = 1.0,
) -> Survey:
    """The 3-D robot's survey (thesis sec. 6.5.2): both sensors of the arm read at `rate_hz`
    while the robot drives (the first `share` of) its route at its speed (turns in place take
    no time here), turned to the world frame and averaged in `voxel` voxels; positions are the
    voxels' centres."""
    waypoints, speed = _route(scene, robot)
    length = float(np.linalg.norm(np.diff(waypoints, axis=0), axis=1).sum())
    times = np.arange(0.0, _share(share) * length / speed, 1.0 / rate_hz)
    poses = poses_along_route(waypoints, np.minimum(times * speed, length))
    xyz, field = [], []
    for sensor in robot_magnetometers(scene, robot, seed):
        device = sensor.device
        if not hasattr(device, "arm"):
            raise ValueError(f"{scene.path}: {sensor.name} of {robot} is not on an arm")
        yaw, pitch = device.arm.joint_angles(times)
        xyz.append(device.sensor_positions(poses, times))
        field.append(arm_to_world(device.read_many(poses, times), poses[:, 2], yaw, pitch))
    positions, values = np.vstack(xyz), np.vstack(field)
    centres, means, _ = voxel_average(positions, values, voxel)
    return Survey(centres, means, len(values), float(times[-1]), float(times[-1] * speed))


def patch_hyperparameters(
    x: np.ndarray,
    y: np.ndarray,
    points: int,
    *,
    noise_sd: float,
    restarts: int,
    seed: int,
    patches: int = 5,
) -> HyperparameterFit:
    """Eq. 6.11's maximum on `points` samples taken as `patches` runs of consecutive samples
    spread evenly over the survey (rows in the order they were taken): each run keeps the
    0.1-0.25 m neighbours that tell the noise from the field, which a random subsample of a
    450 m^2 floor loses, and the runs see several parts of the floor. BFGS starts at the
    sensor's noise (the thesis takes sigma_n as known, eq. 6.1), the data's spread and
    l = 0.5 m, then `restarts` random starts: the default data-driven start lands on this
    floor in the l -> 0 optimum that calls the whole field noise (log likelihood 9,313
    against 10,813 at l = 0.36 m, sigma_n = 0.00996 G)."""
    n = len(x)
    take = max(1, min(points, n) // patches)
    runs = [chunk[:take] for chunk in np.array_split(np.arange(n), patches)]
    chosen = np.concatenate(runs)
    spread = float(np.sqrt(np.mean(np.var(y[chosen], axis=0))))
    initial = SquaredExponential(max(spread, noise_sd), 0.5, noise_sd)
    return fit_hyperparameters(
        x[chosen], y[chosen], initial=initial, restarts=restarts, seed=seed, max_points=len(chosen)
    )


def free_mask(scene: Scene, centres: np.ndarray, height: float) -> np.ndarray:
    """(n,) bool: which (n, 2+) points lie in free space at `height` (not in a wall, pillar or
    the shaft), on the scene's ground truth of that height band."""
    grid = scene.ground_truth(max(0.0, height - 0.05), height + 0.05)
    cells = grid.world_to_cell(np.asarray(centres, dtype=float)[:, :2])
    inside = (
        (cells[:, 0] >= 0)
        & (cells[:, 0] < grid.width)
        & (cells[:, 1] >= 0)
        & (cells[:, 1] < grid.height)
    )
    free = np.zeros(len(cells), dtype=bool)
    c = cells[inside]
    free[inside] = grid.cells[c[:, 1], c[:, 0]] == 0
    return free


@dataclass(frozen=True)
class FloorMap:
    """The 2-D floor map with what it was made from and what it cost."""

    field_map: MagneticFieldMap
    survey: Survey
    hyperparameters: HyperparameterFit
    seconds: dict  # hyperparameters_s, fit_s, predict_s (wall), cpu_s, load (1-min average)


def floor_map_2d(
    scene_file: str,
    seed: int,
    resolution: float = 0.1,
    hyper_points: int = 1000,
    restarts: int = 2,
    noise_sd: float = SENSOR_NOISE,
    share: float = 1.0,
    step: float = 0.1,
) -> FloorMap:
    """The thesis' 2-D map (secs. 6.5.1, 6.6.1): mapper_2d's survey, hyperparameters on a
    patch of it, the exact GP of mx, my, mz on every reading (one shared kernel, one Cholesky
    factorisation) and its mean and variance (eqs. 6.8, 6.9) on a `resolution` grid over the
    scene at the sensors' height; `share`: the part of the route surveyed, `step`: metres of
    travel between readings (the thesis: 0.1)."""
    return _floor_map_2d(
        str(scene_file), seed, resolution, hyper_points, restarts, noise_sd, share, step
    )


@functools.lru_cache(maxsize=2)  # gp-mcl's trials share one map per process
def _floor_map_2d(scene_file, seed, resolution, hyper_points, restarts, noise_sd, share, step):
    scene = load_scene(scene_file)
    survey = survey_2d(scene, seed, step, share=share)
    start, cpu = time.perf_counter(), time.process_time()
    hyper = patch_hyperparameters(
        survey.positions,
        survey.field,
        hyper_points,
        noise_sd=noise_sd,
        restarts=restarts,
        seed=seed,
    )
    fitted = time.perf_counter()
    gp = ExactGP.fit(survey.positions, survey.field, hyper.kernel)
    factorised = time.perf_counter()
    lo, hi = scene.bounds
    height = _sensor_height(scene)
    fmap = MagneticFieldMap.from_gp(
        gp,
        lo[:2],
        hi[:2],
        resolution,
        height=height,
        units="G",
        provenance={"data": {"source": Path(scene_file).name, "points": len(survey.field)}},
    )
    seconds = {
        "hyperparameters_s": fitted - start,
        "fit_s": factorised - fitted,
        "predict_s": time.perf_counter() - factorised,
        "cpu_s": time.process_time() - cpu,  # every thread of the process
        "load": load_average(),
    }
    return FloorMap(fmap, survey, hyper, seconds)


def _sensor_height(scene: Scene, robot: str = "mapper_2d") -> float:
    spec = next(s for s in scene.robot_specs if s["name"] == robot)
    heights = {float(s["mount"][2]) for s in spec["sensors"] if s.get("type") == "magnetometer"}
    if len(heights) != 1:
        raise ValueError(f"{scene.path}: {robot}'s magnetometers are not at one height")
    return heights.pop()
