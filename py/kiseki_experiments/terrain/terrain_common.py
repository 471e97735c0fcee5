# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What the rubble paper's experiments (``terrain-*``, paper 003 sec. 7) share: one move of the
tilting laser in a scene, the two local maps, their plane removal and the correlation search.

Frames. The first sweep is taken level at the scene's robot start (the mount's offset and
height, heading the robot's); the second from the first sensor pose composed with the move
(:class:`kiseki.sim.pose6.Pose6`: the move is the sensor's, expressed in the first sensor's
frame, as the paper gives the unit's motion and attitude). Each sweep's median of three (the
laser) becomes an S-DEM, and its points are turned by the gyro's reading of that sweep
(``attitude_matrix``: sensor to level, heading included), as the paper compensates attitude
with the gyro: both S-DEMs are then level and share the first sweep's heading up to the gyro's
error, so the search is over translation only with ``rotation=None``, and its answer is the
second sensor's position in the first's level frame, whose truth is the move's (x, y, z).

The gyro reads the first sweep at t = 0 and the second ``move_seconds`` later; its drift
(kiseki.sim.gyro) grows with that time. 10 s (default) is kiseki's assumption: three sweeps of
about 2 s each and 0.46 m of driving at 0.2 m/s; the paper does not say.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from kiseki import _core
from kiseki.sim.pose6 import Pose6, pose_matrix
from kiseki.sim.primitives import BoxList
from kiseki.sim.scene import load_scene
from kiseki.sim.tilting_laser import TiltingLaser, TiltingLaserParams
from kiseki.terrain import (
    METHODS,
    attitude_matrix,
    correlation_search,
    remove_planes,
    sdem_from_points,
    sdem_from_ranges,
    search_grid,
)

__all__ = [
    "EXACT_GYRO",
    "LocalMaps",
    "Match",
    "check_common",
    "local_maps",
    "match",
    "object_cells",
    "slice_row",
    "start_pose",
]

EXACT_GYRO = {"gyro_sd_deg": 0.0, "gyro_bias_sd_deg_s": 0.0, "gyro_arw_deg_rt_s": 0.0}
"""Tilting-laser parameters of a gyro without error (the ablation rows)."""


def check_common(name: str, removals, search: str, cost: str, step: float) -> None:
    """Raises ValueError naming the experiment for an unknown removal, search or cost."""
    bad = [m for m in removals if m not in METHODS]
    if not removals or bad:
        raise ValueError(f"{name}: removals must be some of {METHODS}, got {list(removals)}")
    if search not in ("exhaustive", "coarse-to-fine"):
        raise ValueError(f"{name}: search must be exhaustive or coarse-to-fine, got {search!r}")
    if cost not in ("mean", "sum"):
        raise ValueError(f"{name}: cost must be mean or sum, got {cost!r}")
    if not 0.005 <= step <= 0.35:
        raise ValueError(f"{name}: step must be 0.005..0.35 m, got {step}")


def start_pose(scene) -> np.ndarray:
    """The first sweep's sensor pose (4x4): level, at the robot's start plus the mount."""
    if not scene.sensors or scene.sensors[0].get("type") != "tilting_laser":
        raise ValueError(f"{scene.path}: the first sensor must be a tilting_laser")
    x, y, heading = (float(v) for v in scene.robot["start"][:3])
    mx, my, mz = (float(v) for v in scene.sensors[0]["mount"][:3])
    c, s = math.cos(heading), math.sin(heading)
    return pose_matrix(x + c * mx - s * my, y + s * mx + c * my, mz, 0.0, 0.0, heading)


@dataclass
class LocalMaps:
    """The two level S-DEMs, the true sensor poses, the gyro's readings (rad)."""

    previous: _core.SphereElevationMap
    current: _core.SphereElevationMap
    poses: tuple[np.ndarray, np.ndarray]
    gyro: tuple[np.ndarray, np.ndarray]
    truth: np.ndarray


def _level(ranges: np.ndarray, gyro_rpy: np.ndarray) -> _core.SphereElevationMap:
    points, _ = sdem_from_ranges(ranges).to_points()
    return sdem_from_points(points, attitude_matrix(*(float(a) for a in gyro_rpy)))


def local_maps(
    scene_path: str, move: Pose6, seed: int, move_seconds: float, exact_gyro: bool = False
) -> LocalMaps:
    """The previous and current level S-DEMs of one move in the scene (see the module)."""
    scene = load_scene(scene_path)
    first = start_pose(scene)
    second = first @ move.matrix()
    laser = TiltingLaser(TiltingLaserParams(**(EXACT_GYRO if exact_gyro else {})), seed)
    r0, a0 = laser.scan(scene.world, first, 0.0)
    r1, a1 = laser.scan(scene.world, second, float(move_seconds))
    truth = np.array([move.x, move.y, move.z])
    return LocalMaps(_level(r0, a0), _level(r1, a1), (first, second), (a0, a1), truth)


@dataclass
class Match:
    """One removal method's search: the estimate (m), its error, what was kept."""

    method: str
    translation: np.ndarray
    error: np.ndarray
    cost: float
    overlap: int
    kept: tuple[float, float]
    removed: tuple[np.ndarray, np.ndarray]
    costs: np.ndarray | None
    seconds: float
    kept_maps: tuple


def match(maps: LocalMaps, method: str, search: str, cost: str, step: float, seed: int) -> Match:
    """Plane removal with ``method`` on both maps, then the search over the paper's grid (with
    ``step``); the estimate against the truth."""
    start = time.perf_counter()
    prev = remove_planes(maps.previous, method, seed=seed)
    cur = remove_planes(maps.current, method, seed=seed)
    grid = search_grid(step=step)
    result = correlation_search(prev.kept, cur.kept, None, grid, search, cost=cost)
    seconds = time.perf_counter() - start
    t = np.asarray(result.translation, dtype=float)
    return Match(
        method, t, t - maps.truth, result.cost, result.overlap,
        (prev.kept_share, cur.kept_share), (prev.removed, cur.removed), result.costs,
        seconds, (prev.kept, cur.kept),
    )  # fmt: skip


def _object_world(scene_path: str, max_top: float) -> _core.BoxWorld | None:
    """The scene's small objects on the floor alone: boxes standing on the floor (bottom within
    2 cm of z = 0) whose top is below ``max_top``; None when there are none."""
    boxes = load_scene(scene_path).boxes
    small = BoxList.empty()
    for c, h, r in zip(boxes.centers, boxes.half_sizes, boxes.rotations, strict=True):
        extent = np.abs(np.asarray(r)) @ np.asarray(h)  # half extents of the rotated box
        if c[2] - extent[2] > -0.02 and c[2] + extent[2] < max_top:
            small.centers.append(c)
            small.half_sizes.append(h)
            small.rotations.append(r)
    return _core.BoxWorld(*small.arrays()) if small.centers else None


def object_cells(
    scene_path: str, sdem, pose: np.ndarray, gyro_rpy, max_top: float = 1.0, tol: float = 0.05
) -> np.ndarray:
    """(rows, cols) mask of the level S-DEM's cells whose point lies on a small floor object:
    each cell's ray (turned back from the gyro's level frame into the sensor's and then into
    the world with the true pose) is cast against the objects alone; the cell is the object's
    when that range is within ``tol`` of the cell's range."""
    grid = sdem.grid
    mask = np.zeros((grid.rows, grid.cols), dtype=bool)
    world = _object_world(scene_path, max_top)
    if world is None:
        return mask
    points, cells = sdem.to_points()
    ranges = np.linalg.norm(points, axis=1)
    level = attitude_matrix(*(float(a) for a in gyro_rpy))
    dirs = (points / ranges[:, None]) @ level @ np.asarray(pose)[:3, :3].T
    origins = np.broadcast_to(np.asarray(pose)[:3, 3], dirs.shape)
    hit = np.asarray(world.cast_many(np.ascontiguousarray(origins), dirs, 10.0))
    mask.reshape(-1)[cells[np.abs(hit - ranges) < tol]] = True
    return mask


def slice_row(sdem, theta_deg: float) -> tuple[np.ndarray, np.ndarray]:
    """(phi in deg, r) of the S-DEM's row at tilt ``theta_deg`` (Figs. 11-12's cut)."""
    grid = sdem.grid
    row = int(round((theta_deg - grid.theta_min_deg) / grid.step_deg))
    if not 0 <= row < grid.rows:
        raise ValueError(f"theta {theta_deg} deg is outside the S-DEM's tilt range")
    phi = grid.phi_min_deg + grid.step_deg * np.arange(grid.cols)
    return phi, sdem.ranges[row]
