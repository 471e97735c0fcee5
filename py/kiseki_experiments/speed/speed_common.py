# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What paper 004's experiments share: the scenes, the prior map, the speed limiters by name and
one closed-loop drive of the omnidirectional robot through the simulator.

The prior map is the scene's ground truth at the laser's height (0.3 m) in its ``teach``
variant: the map a robot would have built before (the unknown box of situation 2 is only in the
``playback`` variant, so the map does not know it). The robot is the paper's (kiseki.sim's
OmniRobot: v_max 0.5 m/s, a_max 0.5 m/s^2, 0.70 m square) with its laser (+-120 deg, 4 m,
683 beams, 100 ms); the Fuzzy Potential Method (kiseki.control) chooses the direction of motion
toward the goal and the limiter named by ``method`` caps the speed
(kiseki.speed.SpeedControlledNavigator). Every method meets the same scene, robot, sensor noise
and seed: only the limiter differs.

Methods: ``none`` (v_max), ``occlusion`` (the paper's method 1, eq. 1), ``occlusion-width``
(methods 1 + 2, eq. 4), ``width`` (method 2 alone), ``distance`` (distance-only slowdown: from
the distance to the nearest occluded region, after the paper's ref. [4]) and ``polygon`` (nav2
collision-monitor style boxes); the last two are kiseki.speed's baselines.
"""

from __future__ import annotations

import dataclasses
import math
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from kiseki.control import FuzzyPotentialMethod
from kiseki.grid import OccupancyGrid
from kiseki.io.runlog import read_run
from kiseki.sim.run import SimConfig, simulate
from kiseki.sim.scene import Scene, load_scene
from kiseki.speed import (
    DistanceLimiterConfig,
    DistanceSpeedLimiter,
    PolygonLimiterConfig,
    PolygonSpeedLimiter,
    SpeedControlledNavigator,
    SpeedLimiter,
    SpeedLimiterConfig,
)
from kiseki_experiments.harness.paths import WORLDS

__all__ = [
    "METHODS",
    "WORLDS",
    "Drive",
    "RecordingLimiter",
    "drive",
    "laser_mount",
    "make_limiter",
    "prior_map",
]

METHODS = ("none", "occlusion", "occlusion-width", "width", "distance", "polygon")


def laser_mount(scene: Scene) -> tuple[float, float, float, float]:
    """The scene's first laser's mount (x ahead, y left, z up, yaw deg)."""
    for spec in scene.sensors:
        if spec.get("type") == "laser":
            return tuple(float(v) for v in spec["mount"])  # type: ignore[return-value]
    raise ValueError(f"{scene.path}: the speed experiments need a laser")


def prior_map(scene_file: str | Path) -> OccupancyGrid:
    """The map the robot knows: the teach variant's ground truth at the laser's height, with
    the free cells that the robot's free space does not reach (the outside of the building,
    behind its walls) made unknown, as on a map a robot has built: it never saw them."""
    scene = load_scene(scene_file, "teach")
    z = laser_mount(scene)[2]
    grid = scene.ground_truth(z - 0.02, z + 0.02)
    x, y, _ = scene.robot.get("start", [0.0, 0.0, 0.0])
    reached = _reachable(grid.cells == 0, grid.world_to_cell(np.array([[x, y]]))[0])
    grid.cells[(grid.cells == 0) & ~reached] = -1
    return grid


def _reachable(free: np.ndarray, start) -> np.ndarray:
    """The free cells 4-connected to the start cell (column, row)."""
    reached = np.zeros_like(free)
    col, row = int(start[0]), int(start[1])
    if not (0 <= row < free.shape[0] and 0 <= col < free.shape[1] and free[row, col]):
        raise ValueError(f"the robot's start cell ({col}, {row}) is not free on the map")
    reached[row, col] = True
    while True:
        grown = reached.copy()
        grown[1:] |= reached[:-1]
        grown[:-1] |= reached[1:]
        grown[:, 1:] |= reached[:, :-1]
        grown[:, :-1] |= reached[:, 1:]
        grown &= free
        if (grown == reached).all():
            return reached
        reached = grown


def make_limiter(method: str, prior: OccupancyGrid, sensor_offset: float):
    """The limiter of a method (None for ``none``); ``sensor_offset``: the laser's distance
    ahead of the body centre (m), which the baselines' boxes need."""
    if method == "none":
        return None
    if method in ("occlusion", "occlusion-width", "width"):
        config = SpeedLimiterConfig(
            use_occlusion=method != "width", use_width=method != "occlusion"
        )
        return RecordingLimiter(SpeedLimiter(prior, config))
    if method == "distance":
        return DistanceSpeedLimiter(prior, DistanceLimiterConfig(sensor_offset=sensor_offset))
    if method == "polygon":
        return PolygonSpeedLimiter(PolygonLimiterConfig(sensor_offset=sensor_offset))
    raise ValueError(f"unknown speed method {method!r} (known: {', '.join(METHODS)})")


class RecordingLimiter:
    """Passes updates to a kiseki.speed.SpeedLimiter and keeps each update's terms."""

    def __init__(self, limiter: SpeedLimiter) -> None:
        self.limiter, self.terms = limiter, []

    def update(self, sensor_pose, angles, ranges, max_range, dt, heading=None):
        out = self.limiter.update(sensor_pose, angles, ranges, max_range, dt, heading)
        self.terms.append(self.limiter.last)
        return out


@dataclass
class Drive:
    """One closed-loop run: per control step (10 Hz) the time, true pose, the actual speed
    (m/s, from the simulator's /velocity), the navigator's limit and, for the paper's limiter,
    eq. 1's ratio and f(w); how it ended."""

    t: np.ndarray
    pose: np.ndarray  # (n, 3)
    speed: np.ndarray
    limit: np.ndarray
    ratio: np.ndarray
    width_factor: np.ndarray
    reached: bool
    duration: float  # s until the goal (or the end of the run)
    collision: dict | None  # {t, hit, x, y, speed}


def drive(
    scene: Scene,
    goal: tuple[float, float],
    method: str,
    seed: int,
    prior: OccupancyGrid,
    max_duration: float = 120.0,
    limiter=None,
) -> Drive:
    """Drives the scene's robot to ``goal`` with the FPM under ``method``'s limiter (or the
    ``limiter`` given); the run's MCAP goes to a temporary folder and is read back."""
    offset = laser_mount(scene)[0]
    if limiter is None:
        limiter = make_limiter(method, prior, offset)
    navigator = SpeedControlledNavigator(goal, FuzzyPotentialMethod(), limiter)
    config = SimConfig(seed=seed, max_duration=max_duration)
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "run.mcap"
        summary = simulate(scene, out, config, controller=navigator, progress=False)
        run = read_run(out)
        times, poses = run.poses("/ground_truth")
        vt, velocity = run.velocities("/velocity")
    speed = np.interp(times, vt, np.hypot(velocity[:, 0], velocity[:, 1]))
    log = navigator.log.as_arrays()
    limit = np.interp(times, log["t"], np.nan_to_num(log["limit"], nan=0.0))
    terms = getattr(limiter, "terms", None)
    ratio = np.full(len(times), np.nan)
    factor = np.full(len(times), np.nan)
    if terms:
        k = min(len(terms), len(times))
        ratio[:k] = [term.ratio for term in terms[:k]]
        factor[:k] = [term.width_factor for term in terms[:k]]
    collision = None
    if summary.collision is not None:
        c = summary.collision
        at = float(np.interp(c.t, vt, np.hypot(velocity[:, 0], velocity[:, 1])))
        x, y = c.contact
        collision = {"t": float(c.t), "hit": str(c.hit), "x": x, "y": y, "speed": at}
    return Drive(
        times,
        poses,
        speed,
        limit,
        ratio,
        factor,
        bool(summary.reached_goal),
        float(summary.sim_seconds),
        collision,
    )


def with_pedestrians(scene: Scene, pedestrians: list) -> Scene:
    """A copy of a scene with other pedestrians (kiseki.sim.pedestrians.Pedestrian)."""
    return dataclasses.replace(scene, pedestrians=list(pedestrians))


def speed_at(drive_: Drive, y: float) -> float:
    """The actual speed when the robot's centre first reaches ordinate y (NaN if never)."""
    k = np.nonzero(drive_.pose[:, 1] >= y)[0]
    return float(drive_.speed[k[0]]) if k.size else math.nan
