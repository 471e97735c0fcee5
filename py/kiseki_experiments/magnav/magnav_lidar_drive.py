# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The closed-loop runs of the magnetic-navigation thesis' ch. 5 simulation (sec. 5.3) on a
scene such as data/worlds/magnetic_lidar_path.yaml: the simulator is the data source, the
localizer is :class:`kiseki.magnetic.lidar_mcl.MagneticLidarMcl`.

* :func:`teach_heading_map`: the route driven by pure pursuit on the true pose (the mapping
  run), its magnetometer readings averaged into the linear map's 0.1 m nodes with the run's
  true positions and headings (the thesis' simulation "maps this field" along the route; its
  map frame is the occupancy grid's, here the simulator's);
* :func:`drive`: the route driven by pure pursuit on one method's estimate ("autonomous
  movement based on the localization result", sec. 5.3): ``odometry`` (the wheel odometry
  alone), ``laser`` (MCL with the beam model) or ``magnetic`` (the same MCL with the heading
  correction). Every method has the same robot, odometry error model, sensors and seed; the
  laser and the magnetometer read at 10 Hz, one step each 0.1 s.

A process keeps the last scene file it read (and its rasterised grids) and the last beam model
built on it: the runs of a sweep share them instead of rebuilding them (about 4 s of a 6 s
trial); a changed scene file is read again.
"""

from __future__ import annotations

import functools
import math
import os
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from kiseki.control import PurePursuit
from kiseki.core import derive_seed
from kiseki.magnetic.lidar_mcl import LidarMclConfig, MagneticLidarMcl, PathHeadingMap
from kiseki.magnetic.linear_map import LinearMagneticMap, build_linear_map, path_identity
from kiseki.sim.scene import Scene, load_scene
from kiseki.sim.setup import build_robot, build_sensors

__all__ = ["DRIVE_METHODS", "LOOKAHEAD", "DriveResult", "drive", "load", "teach_heading_map"]

DRIVE_METHODS = ("odometry", "laser", "magnetic")
LOOKAHEAD = 2.0
"""m: pure pursuit's look-ahead on the estimate (our choice; the thesis prints none)."""
GOAL = 1.0
"""m: a run reaches the goal when the route is done by its estimate and the true pose is this
near the last waypoint."""
DT = 0.1  # s: 10 Hz, the thesis' laser and magnetometer rate (sec. 3.3.2)


@functools.lru_cache(maxsize=1)
def _scene(path: str, stamp: tuple[int, int]) -> Scene:
    del stamp  # part of the key: the file's modification time and size
    return load_scene(path)


def _scene_key(scene_path: str | os.PathLike) -> tuple[str, tuple[int, int]]:
    path = Path(scene_path)
    if not path.is_file():
        load_scene(path)  # raises its own error for a missing file
    stat = path.stat()
    return str(path.resolve()), (stat.st_mtime_ns, stat.st_size)


@functools.lru_cache(maxsize=1)
def _beam_model(key: tuple, z: float, sigma_d: float, beams: int, mount: tuple):
    """The filters' beam model on the grid of the laser's height ``z`` (as :func:`load`)."""
    grid = _scene(*key).ground_truth(z - 0.02, z + 0.02)
    return MagneticLidarMcl.beam_model(grid, LidarMclConfig(sigma_d=sigma_d, beams=beams), mount)


def load(scene_path: str | os.PathLike, seed: int):
    """(scene, robot setup, laser, magnetometer, grid at the laser's height) for ``seed``."""
    return _load(scene_path, _scene_key(scene_path), seed)


def _load(scene_path: str | os.PathLike, key: tuple, seed: int):
    scene = _scene(*key)
    setup = build_robot(scene, seed)
    sensors = build_sensors(scene, setup, seed, DT)
    lasers = [s for s in sensors if s.kind == "laser"]
    mags = [s for s in sensors if s.kind == "magnetometer"]
    if len(lasers) != 1 or len(mags) != 1:
        raise ValueError(f"{scene_path}: the robot needs one laser and one magnetometer")
    if "waypoints" not in scene.route:
        raise ValueError(f"{scene_path}: the scene has no route")
    laser = lasers[0]
    grid = scene.ground_truth(laser.mount.z - 0.02, laser.mount.z + 0.02)
    return scene, setup, laser, mags[0], grid


def _pursuit(scene, setup) -> PurePursuit:
    route = np.asarray(scene.route["waypoints"], dtype=np.float64)
    speed = float(scene.route["speed"])
    return PurePursuit(route, speed, LOOKAHEAD, 0.3, setup.robot.params.max_accel)


def _pose(p) -> np.ndarray:
    return np.array([p.x, p.y, p.theta])


def teach_heading_map(scene_path: str | os.PathLike, seed: int = 0) -> LinearMagneticMap:
    """The mapping run's linear map, with positions (see the module text)."""
    scene, setup, _, mag, _ = load(scene_path, seed)
    pursuit = _pursuit(scene, setup)
    truth, readings = [], []
    for k in range(int(3 * pursuit.cum[-1] / (float(scene.route["speed"]) * DT))):
        pose = _pose(setup.robot.pose)
        truth.append(pose)
        readings.append(mag.device.read(pose, k * DT))
        if pursuit.done:
            break
        v, _, w = pursuit.command(pose)
        setup.robot.step(v, w, DT)
    truth = np.array(truth)
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(truth[:, :2], axis=0).T))])
    return build_linear_map(
        s,
        np.array(readings),
        truth[:, 2],
        path_id=path_identity(scene.route["waypoints"]),
        position=truth[:, :2],
        provenance={"scene": str(scene_path), "seed": str(seed)},
    )


@dataclass(frozen=True)
class DriveResult:
    method: str
    times: np.ndarray  # (n,) s
    truth: np.ndarray  # (n, 3)
    odometry: np.ndarray  # (n, 3)
    estimate: np.ndarray  # (n, 3) what the robot steered by
    sd: np.ndarray  # (n, 3) particles' SD in x, y, theta (NaN for odometry)
    reset: np.ndarray  # (n,) bool: heading reset this step (eq. 5.6)
    r: np.ndarray  # (n, 2) r_z, r_theta (NaN: no map node)
    ess: np.ndarray  # (n,) before resampling
    resampled: np.ndarray  # (n,) bool
    reached_goal: bool  # see GOAL
    localizer_s: float = 0.0  # wall time spent in the localizer's steps


def drive(
    scene_path: str | os.PathLike,
    method: str,
    heading_map: LinearMagneticMap | None,
    config: LidarMclConfig,
    seed: int,
    max_distance: float | None = None,
) -> DriveResult:
    """One closed-loop run of ``method`` (see :data:`DRIVE_METHODS`) with the robot, odometry
    and sensor noise of ``seed``; ``max_distance`` m of travel ends it early (tests)."""
    if method not in DRIVE_METHODS:
        raise ValueError(f"drive: method must be one of {', '.join(DRIVE_METHODS)}, got {method!r}")
    key = _scene_key(scene_path)
    scene, setup, laser, mag, grid = _load(scene_path, key, seed)
    pursuit = _pursuit(scene, setup)
    angles = laser.device.params.angles
    max_range = float(laser.device.params.max_range)
    start = _pose(setup.robot.pose)
    mcl = None
    if method != "odometry":
        mcl_config = LidarMclConfig(
            **{**config.__dict__, "magnetic": method == "magnetic", "seed": derive_seed(seed, 7)}
        )
        hmap = PathHeadingMap(heading_map, mcl_config.reach) if method == "magnetic" else None
        mount = (laser.mount.x, laser.mount.y, math.radians(laser.mount.yaw_deg))
        model = _beam_model(key, laser.mount.z, mcl_config.sigma_d, mcl_config.beams, mount)
        mcl = MagneticLidarMcl(grid, hmap, mcl_config, start, laser=mount, model=model)
    odo0 = _pose(setup.odometry.pose)
    log: dict[str, list] = {k: [] for k in ("t", "truth", "odo", "est", "sd", "reset", "r")}
    log.update(ess=[], resampled=[])
    spent, travelled = 0.0, 0.0
    steps = int(4 * pursuit.cum[-1] / (float(scene.route["speed"]) * DT))
    for k in range(steps):
        t = k * DT
        truth, odo = _pose(setup.robot.pose), _pose(setup.odometry.pose)
        if mcl is None:  # odometry alone, from the known start
            d = odo - odo0
            c, s = math.cos(start[2] - odo0[2]), math.sin(start[2] - odo0[2])
            est = np.array([start[0] + c * d[0] - s * d[1], start[1] + s * d[0] + c * d[1], 0.0])
            est[2] = math.remainder(start[2] + d[2], math.tau)
            row = (est, np.full(3, np.nan), False, (math.nan, math.nan), math.nan, False)
        else:
            _, ranges = laser.device.scan(grid, truth)
            reading = mag.device.read(truth, t)
            t0 = time.perf_counter()
            step = mcl.step(odo, (angles, ranges, max_range), reading)
            spent += time.perf_counter() - t0
            est = step.estimate
            row = (est, step.sd, step.reset, (step.r_z, step.r_theta), step.ess, step.resampled)
        for key, value in zip(("est", "sd", "reset", "r", "ess", "resampled"), row, strict=True):
            log[key].append(value)
        log["t"].append(t)
        log["truth"].append(truth)
        log["odo"].append(odo)
        if pursuit.done or (max_distance is not None and travelled >= max_distance):
            break
        v, _, w = pursuit.command(est)
        motion = setup.robot.step(v, w, DT)
        setup.odometry.update(motion)
        travelled += abs(v) * DT
    arrays = {k: np.array(v) for k, v in log.items()}
    return DriveResult(
        method,
        arrays["t"],
        arrays["truth"],
        arrays["odo"],
        arrays["est"],
        arrays["sd"],
        arrays["reset"].astype(bool),
        arrays["r"],
        arrays["ess"],
        arrays["resampled"].astype(bool),
        bool(pursuit.done and np.hypot(*(arrays["truth"][-1, :2] - pursuit.points[-1])) < GOAL),
        spent,
    )
