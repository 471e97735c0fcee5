# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What a magnetic teaching or navigation checks before and after its simulated runs
(:mod:`kiseki.apps.magnetic.navigate_run`): the robot has a magnetometer, the route is long
enough for the linear map's nodes, the parallel paths' starts and waypoints are clear, and each
teaching run reached the route's end (a parallel path's failure names the offset)."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from kiseki.magnetic.linear_map import NODE_SPACING
from kiseki.sim.collisions import FootprintChecker, ObstacleCells, body_grid, footprint_points
from kiseki.sim.setup import build_robot

__all__ = ["OffsetCheck", "check_magnetometer", "check_route_length", "check_taught_run"]

OFFSET_STEP = 0.01
"""m: the steps in which :class:`OffsetCheck` finds the offsets that keep both paths clear."""


def check_route_length(scene, scene_path, waypoints: np.ndarray) -> None:
    """A drive (from the robot's start through the waypoints) shorter than the linear map's node
    spacing cannot give the two nodes navigation needs: refused before the three runs."""
    start = np.asarray(scene.robot.get("start", [0.0, 0.0, 0.0])[:2], dtype=np.float64)
    drive = np.vstack([start, waypoints])
    length = float(np.linalg.norm(np.diff(drive, axis=0), axis=1).sum())
    if length < NODE_SPACING:
        raise ValueError(
            f"{scene_path}: the route is {length:.2f} m long, shorter than the linear map's "
            f"node spacing ({NODE_SPACING:g} m): too short to navigate"
        )


def _blocked(checker: FootprintChecker, pose) -> str | None:
    """Why the robot's footprint cannot stand at ``pose``, or None."""
    if not checker.samples(pose)[2].all():
        return "leaves the scene's bounds"
    return None if checker.contact(pose) is None else "overlaps an obstacle"


class OffsetCheck:
    """The parallel paths are the route moved ``offset`` m to its left and right (``along(d)``:
    the route's waypoints moved ``d`` m to its left, the robot's start with its first one).
    What would end a parallel path's teaching run is refused naming ``option`` (the caller's
    name of the offset: ``--offset`` on the command line) and its value, the path, the point
    and the offsets that keep both paths clear:

    * its start, where the robot's footprint leaves the scene's bounds or overlaps an obstacle
      (the run's own start check named the scene's footprint, as if the scene were wrong);
    * a waypoint outside the scene's bounds (the run refused it, naming the scene);
    * a waypoint where the robot cannot stand in any heading: an obstacle cell's centre within
      half its width (the rule of :func:`kiseki.sim.collisions.check_route_clear`; the run hit
      it).

    :meth:`before_runs` checks the starts, and the waypoints when the route itself is clear
    (its waypoints in the scene's bounds, the robot's footprint along its legs touching no
    obstacle); else :meth:`after_route` checks them once the route's own run reached its end,
    so that a route into a wall is told as the scene's, not the offset's. An obstacle between
    the waypoints is found by the run itself (:func:`check_taught_run`)."""

    def __init__(
        self, scene, scene_path, offset: float, along: Callable[[float], np.ndarray], option: str
    ) -> None:
        self.scene_path, self.offset, self.along, self.option = scene_path, offset, along, option
        robot = build_robot(scene, 0)  # its size; the scene's own start is checked here
        grid = body_grid(scene, robot.height)
        self.checker = FootprintChecker(grid, robot.length, robot.width)
        self.half_width = robot.width / 2
        self.obstacles = ObstacleCells(grid)
        self.lo, self.hi = (np.asarray(b, dtype=np.float64)[:2] for b in scene.bounds)
        x, y, self.yaw = scene.robot.get("start", [0.0, 0.0, 0.0])
        self.start = np.array([x, y], dtype=np.float64)
        self.route = np.asarray(along(0.0), dtype=np.float64)
        self.names = scene.route.get("names") or [f"W{i}" for i in range(len(self.route))]
        self.route_clear = self._in_bounds(self.route).all() and not self._legs_touch()

    def before_runs(self) -> None:
        self._check(waypoints=self.route_clear)

    def after_route(self) -> None:
        if not self.route_clear:
            self._check(waypoints=True)

    def _in_bounds(self, points: np.ndarray) -> np.ndarray:
        return np.all((points >= self.lo) & (points <= self.hi), axis=-1)

    def _legs_touch(self) -> bool:
        """Whether the robot's footprint, heading along each leg of the drive from its start
        through the route's waypoints, touches an obstacle (every half cell of the way)."""
        c = self.checker
        drive = np.vstack([self.start, self.route])
        for a, b in zip(drive[:-1], drive[1:], strict=True):
            length = float(np.hypot(*(b - a)))
            if length == 0.0:
                continue
            body = footprint_points(
                (0.0, 0.0, math.atan2(*(b - a)[::-1])), c.length, c.width, c.spacing
            )
            at = np.linspace(0.0, 1.0, max(2, math.ceil(length / c.spacing) + 1))
            points = (a + at[:, None] * (b - a))[:, None, :] + body[None]
            if c.occupied(points.reshape(-1, 2)).any():
                return True
        return False

    def _problem(self, distance: float, waypoints: bool) -> tuple[str, str] | None:
        for name, sign in (("left", 1.0), ("right", -1.0)):
            moved = np.asarray(self.along(sign * distance), dtype=np.float64)
            at = self.start + moved[0] - self.route[0]
            why = _blocked(self.checker, (at[0], at[1], math.radians(self.yaw)))
            if why is not None:
                return name, (
                    f"would start at ({at[0]:.2f}, {at[1]:.2f}), where the robot's footprint {why}"
                )
            if not waypoints:
                continue
            for label, point in zip(self.names, moved, strict=True):
                where = f"would pass waypoint {label} at ({point[0]:.2f}, {point[1]:.2f})"
                if not self._in_bounds(point):
                    lo, hi = self.lo, self.hi
                    return name, (
                        f"{where}, outside the scene's bounds (x {lo[0]:g}..{hi[0]:g}, "
                        f"y {lo[1]:g}..{hi[1]:g})"
                    )
                gap = self.obstacles.nearest(point)[0]
                if gap <= self.half_width:
                    return name, (
                        f"{where}, where the robot cannot stand in any heading (an obstacle "
                        f"{gap:.2f} m away, within half its width of {self.half_width:.2f} m)"
                    )
        return None

    def _check(self, waypoints: bool) -> None:
        found = self._problem(self.offset, waypoints)
        if found is None:
            return
        name, what = found
        option, step = self.option, OFFSET_STEP
        steps = int(math.floor(self.offset / step))
        blocked = (k for k in range(1, steps + 1) if self._problem(k * step, waypoints))
        clear = next(blocked, steps + 1) - 1
        points = "starts and waypoints" if waypoints else "starts"
        fits = (
            f"the parallel paths' {points} are clear up to {option} {clear * step:.2f} m"
            if clear
            else f"no {option} of {step:g} m or more keeps them clear"
        )
        raise ValueError(
            f"{option} {self.offset:g} m: the {name} parallel path {what} in {self.scene_path}; "
            f"{fits}"
        )


def check_magnetometer(scene, scene_path) -> None:
    """A magnetic teaching or navigation needs the robot's magnetometer: a scene without one is
    refused naming the scene (its run would have no readings)."""
    if not any(s.get("type") == "magnetometer" for s in scene.sensors):
        raise ValueError(f"{scene_path}: the robot has no sensor of type magnetometer")


def check_taught_run(
    summary, scene_path, name: str, offset: float = 0.0, option: str = "offset"
) -> None:
    """A teaching run that did not reach the route's end maps part of it: refused, naming the
    path (``center``, ``left``, ``right``) and why it stopped, not written as a short map. A
    parallel path's run (the route moved ``offset`` m) names ``option`` and its value first:
    the taught route reached its end, so the offset put the path where the robot stopped."""
    if summary.reached_goal:
        return
    c = summary.collision
    why = (
        f"hit {c.hit} at ({c.contact[0]:.2f}, {c.contact[1]:.2f}) at t = {c.t:.1f} s"
        if c is not None
        else f"stopped at ({summary.final_pose[0]:.2f}, {summary.final_pose[1]:.2f})"
    )
    if name == "center":
        raise ValueError(
            f"{scene_path}: the teaching run along the route did not reach its end ({why}): no map"
        )
    fix = (
        f"give an {option} whose parallel paths clear the scene's obstacles"
        if c is not None
        else f"give another {option}"
    )
    raise ValueError(
        f"{option} {offset:g} m: the teaching run along the {name} parallel path did not reach "
        f"its end in {scene_path} ({why}): no map; {fix}"
    )
