# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Whether a route can be played back on a taught map: no straight leg between consecutive
waypoints crosses an occupied cell, except a cell the robot's own body covered while it was
taught.

Why the exception. The thesis' environment map M (sec. 3.4) takes a cell's first value from the
first local map L that holds it, and L marks the cells hidden behind an obstacle as occupied;
a later L that sees the cell free clears it. The AGV's depth cameras look sideways and see
nothing within 0.5 m, so the cells the robot drives over are seen only from elsewhere. When
such a cell was first seen hidden (behind a wall's corner, from the previous aisle) and no
camera saw it again, M keeps it occupied although the robot stood on it. In 70 generated
factory layouts (``layouts-exp2-exp3``, two teaching runs each) this blocked 6 of the 140 runs'
routes, on 4 layouts: the plane map in all 6, the band map in 5, and in each first run the
blocking cell lay within 0.25 m of the waypoint T2 where the robot turns. The teaching log
records where the robot was, by odometry, the frame M is built in (:func:`travelled_poses`);
a cell whose centre lies inside the robot's footprint at one of those poses is known free.
A route edited by hand, or a waypoint file without its log, has no such poses and is checked
against M alone.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from kiseki._support.real_numbers import check_number
from kiseki.grid import OccupancyGrid
from kiseki.io.runlog import read_run
from kiseki.teach.waypoint_schema import read_waypoint_file

__all__ = ["check_route", "read_travelled", "travelled_poses"]


def travelled_poses(log: str | os.PathLike) -> np.ndarray:
    """The (n, 3) odometry poses (x, y, theta) of a teaching log's ``/odom`` topic: where the
    robot was in the frame its maps were built in. ValueError names the file when the log has
    no odometry."""
    run = read_run(log)
    if "/odom" not in run.topics():
        raise ValueError(f"{log}: no /odom topic (not a teaching log)")
    poses = np.array([(m["x"], m["y"], m["theta"]) for _, m in run.messages("/odom")], float)
    if poses.size == 0 or not np.isfinite(poses).all():
        raise ValueError(f"{log}: the /odom poses are empty or not finite")
    return poses.reshape(-1, 3)


def read_travelled(waypoints: str | os.PathLike) -> np.ndarray | None:
    """:func:`travelled_poses` of the teaching log a waypoint file names, or None when it names
    none or the log is not beside it (a hand-made file, a copied folder)."""
    doc = read_waypoint_file(waypoints)
    if not doc.log or not (log := Path(waypoints).parent / doc.log).is_file():
        return None
    return travelled_poses(log)


def check_route(
    environment: OccupancyGrid,
    waypoints: list[dict],
    travelled: np.ndarray | None = None,
    footprint: tuple[float, float] | None = None,
) -> None:
    """Raises ValueError when a straight leg between consecutive waypoints crosses an occupied
    cell of the taught map (the robot follows the legs, so such a route is unreachable), other
    than one whose centre lies inside the robot's `footprint` (length, width, centred on its
    pose) at one of the `travelled` poses (n, 3) of its teaching run."""
    covered = None
    if travelled is not None:
        covered = _Footprints(travelled, footprint)
    grid = None  # a copy with the covered cells cleared, made at the first covered hit
    for a, b in zip(waypoints, waypoints[1:], strict=False):
        length = math.hypot(b["x"] - a["x"], b["y"] - a["y"])
        if length == 0:
            continue
        heading = math.atan2(b["y"] - a["y"], b["x"] - a["x"])
        while True:
            cast = environment if grid is None else grid
            rng, hit, cell = cast.cast_ray(a["x"], a["y"], heading, max_range=length)
            if not hit or rng >= length - environment.resolution:
                break
            centre = environment.cell_to_world(np.array([cell], dtype=float))[0]
            if covered is None or not covered.contains(centre):
                raise ValueError(
                    f"the route leg {a['name']} -> {b['name']} crosses occupied space "
                    f"at ({centre[0]:.2f}, {centre[1]:.2f}) m of the taught map"
                )
            grid = environment.copy() if grid is None else grid
            grid.cells[cell[1], cell[0]] = 0  # the robot stood there: cast on past it


class _Footprints:
    """The robot's rectangle (length along its heading, width across) at each travelled pose."""

    def __init__(self, poses: np.ndarray, footprint: tuple[float, float] | None) -> None:
        poses = np.asarray(poses, dtype=float)
        if poses.ndim != 2 or poses.shape[1] != 3 or not np.isfinite(poses).all():
            raise ValueError(f"travelled: expected finite (n, 3) poses, got shape {poses.shape}")
        if footprint is None or len(footprint) != 2:
            raise ValueError(f"footprint: expected (length, width) > 0 m, got {footprint}")
        for name, value in zip(("length", "width"), footprint, strict=True):
            check_number(value, f"footprint: {name}", 0.0, low_open=True, unit="m")
        self.poses = poses
        self.half = 0.5 * np.asarray(footprint, dtype=float)

    def contains(self, point: np.ndarray) -> bool:
        dx, dy = point[0] - self.poses[:, 0], point[1] - self.poses[:, 1]
        c, s = np.cos(self.poses[:, 2]), np.sin(self.poses[:, 2])
        along, across = c * dx + s * dy, -s * dx + c * dy
        return bool(np.any((np.abs(along) <= self.half[0]) & (np.abs(across) <= self.half[1])))
