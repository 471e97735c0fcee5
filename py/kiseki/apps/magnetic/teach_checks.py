# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What a magnetic teaching or navigation checks before and after its simulated runs
(:mod:`kiseki.apps.magnetic.navigate_run`): the robot has a magnetometer, the route is long
enough for the linear map's nodes, the parallel paths' starts are clear, and each teaching run
reached the route's end."""

from __future__ import annotations

import math

import numpy as np

from kiseki.magnetic.linear_map import NODE_SPACING
from kiseki.sim.collisions import FootprintChecker, body_grid
from kiseki.sim.setup import build_robot

__all__ = ["check_magnetometer", "check_offset", "check_route_length", "check_taught_run"]

OFFSET_STEP = 0.01
"""m: the steps in which :func:`check_offset` finds the offsets that keep both starts clear."""


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


def check_offset(scene, scene_path, offset: float, left: np.ndarray, option: str) -> None:
    """The parallel paths start ``offset`` m to the left and right of the robot's start
    (``left``: the unit vector to its left): a start where the robot's footprint leaves the
    scene's bounds or overlaps an obstacle is refused before the runs, naming ``option`` (the
    caller's name of the offset: ``--offset`` on the command line) and its value, the path,
    its start and the offsets that keep both starts clear. (The left run's own start check
    named the scene's footprint, as if the scene were wrong, not the offset.)"""
    robot = build_robot(scene, 0)  # its size; the scene's own start is checked here
    checker = FootprintChecker(body_grid(scene, robot.height), robot.length, robot.width)
    x, y, yaw = scene.robot.get("start", [0.0, 0.0, 0.0])

    def problem(distance: float) -> tuple[str, np.ndarray, str] | None:
        for name, sign in (("left", 1.0), ("right", -1.0)):
            at = np.array([x, y]) + sign * distance * np.asarray(left, dtype=np.float64)
            why = _blocked(checker, (at[0], at[1], math.radians(yaw)))
            if why is not None:
                return name, at, why
        return None

    found = problem(offset)
    if found is None:
        return
    name, at, why = found
    steps = int(math.floor(offset / OFFSET_STEP))
    clear = next((k for k in range(1, steps + 1) if problem(k * OFFSET_STEP)), steps + 1) - 1
    fits = (
        f"the parallel paths start clear up to {option} {clear * OFFSET_STEP:.2f} m"
        if clear
        else f"no {option} of {OFFSET_STEP:g} m or more fits"
    )
    raise ValueError(
        f"{option} {offset:g} m: the {name} parallel path would start at ({at[0]:.2f}, "
        f"{at[1]:.2f}), where the robot's footprint {why} in {scene_path}; {fits}"
    )


def check_magnetometer(scene, scene_path) -> None:
    """A magnetic teaching or navigation needs the robot's magnetometer: a scene without one is
    refused naming the scene (its run would have no readings)."""
    if not any(s.get("type") == "magnetometer" for s in scene.sensors):
        raise ValueError(f"{scene_path}: the robot has no sensor of type magnetometer")


def check_taught_run(summary, scene_path, name: str) -> None:
    """A teaching run that did not reach the route's end maps part of it: refused, naming the
    path (``center``, ``left``, ``right``) and why it stopped, not written as a short map."""
    if summary.reached_goal:
        return
    path = "the route" if name == "center" else f"the {name} parallel path"
    c = summary.collision
    why = (
        f"hit {c.hit} at ({c.contact[0]:.2f}, {c.contact[1]:.2f}) at t = {c.t:.1f} s"
        if c is not None
        else f"stopped at ({summary.final_pose[0]:.2f}, {summary.final_pose[1]:.2f})"
    )
    raise ValueError(
        f"{scene_path}: the teaching run along {path} did not reach its end ({why}): no map"
    )
