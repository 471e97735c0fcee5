# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Collisions of the simulated robots: a robot's footprint (its length x width rectangle at its
true pose) against the scene's obstacles at the robot's height, against the other robots'
footprints and against pedestrians' discs.

Obstacles are read from the scene's ground truth of the band 0.05 m .. the robot's height, at
the scene's grid resolution: the footprint is sampled every half cell (edges included) and a
sample in an occupied cell is a contact, so a contact is found to within one cell (0.05 m) of
the obstacle's face. Robots against robots (separating axes) and against pedestrians (the
nearest point of the rectangle to the disc's centre) are exact. Used by kiseki.sim.setup (a
robot must start free), kiseki.sim.run and playback (a collision ends the run) and teaching (a
push into an obstacle is not made).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = [
    "COLLISION_SCHEMA",
    "Collision",
    "CollisionCheck",
    "FootprintChecker",
    "ObstacleCells",
    "body_grid",
    "check_free_start",
    "check_route_clear",
    "refuse_pedestrians",
    "disc_contact",
    "footprint_points",
    "rectangle_contact",
]

COLLISION_SCHEMA = {
    "type": "object",
    "title": "kiseki.Collision",
    "properties": {
        "t": {"type": "number", "description": "s, the end of the step that made the contact"},
        "robot": {"type": "string"},
        "hit": {"type": "string", "description": "obstacle, a robot's or a pedestrian's name"},
        "contact": {"type": "array", "description": "(x, y) m, a point of the contact"},
    },
}


@dataclass(frozen=True)
class Collision:
    """A contact: at time t (s), robot hit `hit` ("obstacle", another robot's name or a
    pedestrian's name) at the world point `contact` (x, y). It ends a simulated run and a
    playback; in teaching the move is not made."""

    t: float
    robot: str
    hit: str
    contact: tuple[float, float]

    def payload(self) -> dict:
        return {"t": self.t, "robot": self.robot, "hit": self.hit, "contact": list(self.contact)}

    def line(self) -> str:
        """The contact as the commands print it."""
        x, y = self.contact
        return (
            f"COLLISION at t = {self.t:.2f} s: {self.robot} hit {self.hit} at ({x:.3f}, {y:.3f}); "
            "the run ended there"
        )


def footprint_points(pose, length: float, width: float, spacing: float) -> np.ndarray:
    """(n, 2) world points covering the rectangle length x width centred on pose (x, y, theta),
    at most `spacing` apart, its edges included."""
    nu = max(2, int(math.ceil(length / spacing - 1e-9)) + 1)
    nv = max(2, int(math.ceil(width / spacing - 1e-9)) + 1)
    u, v = np.meshgrid(
        np.linspace(-length / 2, length / 2, nu), np.linspace(-width / 2, width / 2, nv)
    )
    c, s = math.cos(pose[2]), math.sin(pose[2])
    u, v = u.ravel(), v.ravel()
    return np.column_stack([pose[0] + c * u - s * v, pose[1] + s * u + c * v])


def body_grid(scene, height: float):
    """The scene's obstacles a robot of this height can touch: the ground truth of the band
    0.05 m (above the floor) .. its height (or the scene's top)."""
    return scene.ground_truth(0.05, min(height, float(scene.bounds[1][2]) - 0.05))


class FootprintChecker:
    """A robot's footprint against the occupied cells of a grid (see :func:`body_grid`)."""

    def __init__(self, grid, length: float, width: float) -> None:
        self.grid, self.cells = grid, grid.cells
        self.length, self.width = length, width
        self.spacing = 0.5 * self.grid.resolution

    def samples(self, pose) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(points (n, 2), cells (n, 2), inside the grid (n,))."""
        pts = footprint_points(pose, self.length, self.width, self.spacing)
        return (pts, *self._cells(pts))

    def _cells(self, pts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        cells = self.grid.world_to_cell(pts)
        inside = (cells[:, 0] >= 0) & (cells[:, 0] < self.grid.width) & (cells[:, 1] >= 0)
        inside &= cells[:, 1] < self.grid.height
        return cells, inside

    def occupied(self, pts: np.ndarray) -> np.ndarray:
        """Which world points (n, 2) lie in occupied cells; points beyond the grid touch
        nothing (an open corridor end)."""
        cells, inside = self._cells(pts)
        hit = np.zeros(len(pts), dtype=bool)
        hit[inside] = self.cells[cells[inside, 1], cells[inside, 0]] == 100
        return hit

    def contact(self, pose) -> tuple[float, float] | None:
        """The centroid of the footprint's samples in occupied cells, or None. Samples beyond
        the scene's bounds touch nothing (an open corridor end)."""
        pts = footprint_points(pose, self.length, self.width, self.spacing)
        hit = self.occupied(pts)
        if not hit.any():
            return None
        x, y = pts[hit].mean(axis=0)
        return float(x), float(y)


def check_free_start(scene, pose, length: float, width: float, height: float) -> None:
    """ValueError naming the scene when the robot's start footprint leaves the scene's bounds or
    overlaps an obstacle."""
    checker = FootprintChecker(body_grid(scene, height), length, width)
    if not checker.samples(pose)[2].all():
        raise ValueError(f"{scene.path}: the robot's start footprint leaves the scene's bounds")
    if checker.contact(pose) is not None:
        raise ValueError(f"{scene.path}: the robot's start footprint overlaps an obstacle")


class ObstacleCells:
    """The occupied cells of a grid (a scene's :func:`body_grid`) by their centres, for the
    distance from a point to the nearest one."""

    def __init__(self, grid) -> None:
        occupied = np.argwhere(grid.cells == 100)  # (row, col)
        self.centres = grid.cell_to_world(occupied[:, ::-1].astype(float))
        self._tree = None
        if len(occupied):
            from scipy.spatial import cKDTree  # here: importing the simulator stays fast

            self._tree = cKDTree(self.centres)

    def nearest(self, point) -> tuple[float, tuple[float, float] | None]:
        """(distance m, (x, y) of the nearest occupied cell's centre); (inf, None) without
        any."""
        if self._tree is None:
            return math.inf, None
        distance, k = self._tree.query(np.asarray(point, dtype=float)[:2])
        x, y = self.centres[int(k)]
        return float(distance), (float(x), float(y))


def check_route_clear(scene, waypoints, names, width: float, grid) -> None:
    """ValueError naming the scene and the first route waypoint (x, y) where the robot cannot
    stand in any heading: an obstacle cell of `grid` (the scene's :func:`body_grid` at the
    robot's height) lies within half its `width` of the point, inside the disc every footprint
    centred there covers. Cells are taken by their centres, so an obstacle grazing the disc by
    less than half a cell passes (the run's own contact check finds it)."""
    cells = ObstacleCells(grid)
    for name, point in zip(names, waypoints, strict=True):
        distance, centre = cells.nearest(point)
        if distance <= width / 2:
            x, y = centre
            raise ValueError(
                f"{scene.path}: route waypoint {name} {list(point)} lies {distance:.2f} m from "
                f"an obstacle at ({x:.2f}, {y:.2f}) m, within half the robot's width "
                f"({width / 2:.2f} m): the robot cannot stand there"
            )


def refuse_pedestrians(scene, run: str) -> None:
    """ValueError for a scene with pedestrians in a run that does not simulate them (teaching,
    playback: their sensors would not see them, their logs would not hold them)."""
    if scene.pedestrians:
        names = ", ".join(p.name for p in scene.pedestrians)
        raise ValueError(
            f"{scene.path}: {run} does not simulate the scene's pedestrians ({names}): remove "
            "them for it (kiseki sim run simulates them)"
        )


def _corners(pose, length: float, width: float) -> np.ndarray:
    return footprint_points(pose, length, width, max(length, width) + 1.0)  # the 4 corners


def _inside(points: np.ndarray, pose, length: float, width: float) -> np.ndarray:
    c, s = math.cos(pose[2]), math.sin(pose[2])
    dx, dy = points[:, 0] - pose[0], points[:, 1] - pose[1]
    u, v = c * dx + s * dy, -s * dx + c * dy
    return (np.abs(u) <= length / 2 + 1e-12) & (np.abs(v) <= width / 2 + 1e-12)


def rectangle_contact(a, a_size, b, b_size) -> tuple[float, float] | None:
    """Two rectangles (pose, (length, width)) by separating axes: None when apart, else a point
    of the overlap (the mean of the overlapping corners and edge samples)."""
    ca, cb = _corners(a, *a_size), _corners(b, *b_size)
    for theta in (a[2], b[2]):
        for axis in (
            np.array([math.cos(theta), math.sin(theta)]),
            np.array([-math.sin(theta), math.cos(theta)]),
        ):
            pa, pb = ca @ axis, cb @ axis
            if pa.max() < pb.min() or pb.max() < pa.min():
                return None
    step = 0.25 * min(*a_size, *b_size)
    sa, sb = footprint_points(a, *a_size, step), footprint_points(b, *b_size, step)
    both = np.vstack([sa[_inside(sa, b, *b_size)], sb[_inside(sb, a, *a_size)]])
    x, y = both.mean(axis=0) if len(both) else (np.asarray(a[:2]) + np.asarray(b[:2])) / 2
    return float(x), float(y)


def disc_contact(pose, length: float, width: float, center, radius: float):
    """A rectangle against a disc: the rectangle's point nearest the disc's centre when it lies
    within `radius`, else None."""
    c, s = math.cos(pose[2]), math.sin(pose[2])
    dx, dy = center[0] - pose[0], center[1] - pose[1]
    u = min(max(c * dx + s * dy, -length / 2), length / 2)
    v = min(max(-s * dx + c * dy, -width / 2), width / 2)
    x, y = pose[0] + c * u - s * v, pose[1] + s * u + c * v
    if math.hypot(center[0] - x, center[1] - y) > radius:
        return None
    return float(x), float(y)


class CollisionCheck:
    """Every robot of a run (RobotSetup: name, robot.pose, length, width, height) against the
    obstacles, the other robots (unless the scene's robots are points, ``point_robots``) and
    the pedestrians; the first contact found is returned."""

    def __init__(self, scene, setups, pedestrians=()) -> None:
        self.setups, self.pedestrians = list(setups), list(pedestrians)
        self.robots_touch = not getattr(scene, "point_robots", False)
        grids: dict[float, object] = {}
        self.checkers = []
        for s in self.setups:
            if s.height not in grids:
                grids[s.height] = body_grid(scene, s.height)
            self.checkers.append(FootprintChecker(grids[s.height], s.length, s.width))

    def check(self, t: float) -> Collision | None:
        poses = [tuple(_xyt(s.robot.pose)) for s in self.setups]
        for s, pose, checker in zip(self.setups, poses, self.checkers, strict=True):
            point = checker.contact(pose)
            if point is not None:
                return Collision(t, s.name, "obstacle", point)
        for i, (a, pa) in enumerate(zip(self.setups, poses, strict=True)):
            for b, pb in zip(self.setups[i + 1 :], poses[i + 1 :], strict=True):
                if not self.robots_touch:
                    break
                point = rectangle_contact(pa, (a.length, a.width), pb, (b.length, b.width))
                if point is not None:
                    return Collision(t, a.name, b.name, point)
            for p in self.pedestrians:
                point = disc_contact(pa, a.length, a.width, p.position(t), p.radius)
                if point is not None:
                    return Collision(t, a.name, p.name, point)
        return None


def _xyt(p) -> tuple[float, float, float]:
    return (float(p.x), float(p.y), float(p.theta)) if hasattr(p, "x") else tuple(map(float, p))
