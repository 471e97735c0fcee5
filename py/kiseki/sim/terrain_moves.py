# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Stops of a robot on rough ground for the rubble paper's loop (paper 003, Fig. 1): move, stop,
sweep with the tilting laser (median of three, gyro attitude), repeat.

* In a scene (YAML): the stops lie along the scene's route every ``step`` metres from its first
  waypoint; the robot faces along the route and rests on the terrain under its footprint
  (kiseki.sim.pose6.resting_pose), so bumps and slopes set its attitude; the sensor is the
  scene's tilting laser on its mount.
* In an OctoMap ``.bt`` (a real building): the robot finds its own start, a free spot near the
  floor (:func:`free_start`), and drives straight towards the most open direction; the laser
  sits 0.5 m above the floor, 0.2 m ahead of the body's centre (rubble_a's mount).

Each stop is a sweep taken ``seconds_per_move`` after the previous one, so the gyro's drift
grows along the run as it would on a robot.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from kiseki._support.counts import check_count
from kiseki._support.real_numbers import check_number
from kiseki.core import check_seed
from kiseki.sim.pose6 import Pose6, resting_pose
from kiseki.sim.scene import load_scene, read_octree
from kiseki.sim.sensors import Mount
from kiseki.sim.setup import build_robot, build_sensors
from kiseki.sim.tilting_laser import TiltingLaser, TiltingLaserParams

__all__ = ["Stop", "free_start", "terrain_stops"]

SECONDS_PER_MOVE = 10.0
"""The time between two sweeps: a move of about 0.4 m at 0.1 m/s and a 3-sweep stop."""
BT_MOUNT = Mount(0.2, 0.0, 0.5)
BT_FOOTPRINT = (0.6, 0.4, 0.3)  # length, width, height (m): a small tracked rescue robot


@dataclass(frozen=True)
class Stop:
    """One stop: the true body pose, the true sensor pose (4x4, world from sensor), the sweep's
    ranges (tilt x scan, NaN where nothing was hit) and the gyro's (roll, pitch, yaw)."""

    body: Pose6
    sensor: np.ndarray
    ranges: np.ndarray
    gyro_rpy: np.ndarray


def _polyline_points(
    waypoints: np.ndarray, step: float, count: int
) -> list[tuple[float, float, float]]:
    seg = np.diff(waypoints, axis=0)
    lengths = np.hypot(seg[:, 0], seg[:, 1])
    total = float(lengths.sum())
    if step * (count - 1) > total + 1e-9:
        raise ValueError(
            f"the route is {total:.2f} m long: at most {int(total / step + 1e-9)} moves"
            f" of {step:g} m"
        )
    cum = np.concatenate([[0.0], np.cumsum(lengths)])
    out = []
    for k in range(count):
        s = k * step
        i = min(int(np.searchsorted(cum, s, side="right") - 1), len(seg) - 1)
        f = (s - cum[i]) / lengths[i] if lengths[i] > 0 else 0.0
        x, y = waypoints[i] + f * seg[i]
        out.append((float(x), float(y), math.atan2(seg[i, 1], seg[i, 0])))
    return out


def free_start(world, bounds, clearance: float = 0.6) -> tuple[float, float, float]:
    """A free spot near the floor of an octree world: (x, y, floor z). Candidates on a 0.5 m
    grid over the bounds (coarser on a site over 100 m across: at most 200 a side, so the
    search stays a few seconds); at each, the floor is found by casting down from just under
    the top; a spot needs 1.5 m of free space above the floor and ``clearance`` metres around
    at 0.5 m above it. The spot nearest the centre of the bounds wins. Raises ValueError when
    none."""
    lo, hi = (np.asarray(b, dtype=float) for b in bounds)
    centre = (lo + hi) / 2
    step = max(0.5, float((hi[:2] - lo[:2]).max()) / 200)
    xs = np.arange(lo[0] + 0.5, hi[0] - 0.5, step)
    ys = np.arange(lo[1] + 0.5, hi[1] - 0.5, step)
    if len(xs) == 0 or len(ys) == 0:
        raise ValueError("free_start: the world is smaller than 1 m across")
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    cand = np.column_stack([gx.ravel(), gy.ravel()])
    top = hi[2] - 0.05
    height = float(hi[2] - lo[2])
    down = world.cast_many(
        np.column_stack([cand, np.full(len(cand), top)]),
        np.tile([0, 0, -1.0], (len(cand), 1)),
        height,
    )
    ok = np.asarray(down) < height
    floor = top - np.asarray(down)
    angles = np.linspace(0, 2 * math.pi, 8, endpoint=False)
    best, best_d = None, math.inf
    for (x, y), f, hit in zip(cand, floor, ok, strict=True):
        if not hit:
            continue
        up = world.cast_many(np.array([[x, y, f + 0.05]]), np.array([[0.0, 0.0, 1.0]]), 1.5)
        if up[0] < 1.45:
            continue
        o = np.tile([x, y, f + 0.5], (8, 1))
        d = np.column_stack([np.cos(angles), np.sin(angles), np.zeros(8)])
        if np.min(world.cast_many(o, d, clearance)) < clearance:
            continue
        dist = math.hypot(x - centre[0], y - centre[1])
        if dist < best_d:
            best, best_d = (float(x), float(y), float(f)), dist
    if best is None:
        raise ValueError("free_start: no free spot near the floor (1.5 m high, 0.6 m around)")
    return best


def terrain_stops(
    world_path: str | os.PathLike, moves: int, seed: int, step: float = 0.35
) -> list[Stop]:
    """The ``moves + 1`` stops of a run in a scene YAML or an OctoMap ``.bt`` (see the module)."""
    seed = check_seed(seed)
    moves = check_count(moves, "moves", 1, 200)
    check_number(step, "step", 0.02, 0.6, unit="m")  # the search reaches 0.7 m
    path = Path(world_path)
    if path.suffix == ".bt":
        world = read_octree(path)
        try:
            x, y, f = free_start(world, world.bounds)
        except ValueError as err:  # the file's voxels, not the call, decide it: name the file
            raise ValueError(f"{path}: {err}") from None
        o = np.tile([x, y, f + 0.5], (32, 1))
        angles = np.linspace(0, 2 * math.pi, 32, endpoint=False)
        reach = world.cast_many(
            o, np.column_stack([np.cos(angles), np.sin(angles), np.zeros(32)]), 30.0
        )
        heading = float(angles[int(np.argmax(reach))])
        free = float(np.max(reach)) - 0.6
        end = np.array([x, y]) + max(free, 0.0) * np.array([math.cos(heading), math.sin(heading)])
        try:
            plan = _polyline_points(np.array([[x, y], end]), step, moves + 1)
        except ValueError as err:
            raise ValueError(f"{path}: the longest free line from the start: {err}") from None
        length, width, height = BT_FOOTPRINT
        mount, laser = BT_MOUNT, TiltingLaser(TiltingLaserParams(), seed)
    else:
        scene = load_scene(path)
        robot = build_robot(scene, seed)
        lasers = [s for s in build_sensors(scene, robot, seed, 0.1) if s.kind == "tilting_laser"]
        if not lasers:
            raise ValueError(f"{path}: the scene has no tilting_laser sensor")
        world = scene.world
        waypoints = np.asarray(scene.route.get("waypoints", []), dtype=float)
        if waypoints.ndim != 2 or len(waypoints) < 2:
            raise ValueError(f"{path}: the scene's route needs at least two waypoints")
        try:
            plan = _polyline_points(waypoints, step, moves + 1)
        except ValueError as err:
            raise ValueError(f"{path}: {err}") from None
        length, width, height = robot.length, robot.width, robot.height
        mount, laser = lasers[0].mount, lasers[0].device
    stops = []
    for k, planar in enumerate(plan):
        body = resting_pose(world, planar, length, width, height + 1.0)
        sensor = mount.world(body.values)
        ranges, gyro = laser.scan(world, sensor, k * SECONDS_PER_MOVE)
        stops.append(Stop(body, sensor, ranges, np.asarray(gyro, dtype=float)))
    return stops
