# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What a magnetic teaching or navigation checks before and after its simulated runs
(:mod:`kiseki.apps.magnetic.navigate_run`): the robot has a magnetometer, the route is long
enough for the linear map's nodes, and each teaching run reached the route's end."""

from __future__ import annotations

import numpy as np

from kiseki.magnetic.linear_map import NODE_SPACING

__all__ = ["check_magnetometer", "check_route_length", "check_taught_run"]


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
