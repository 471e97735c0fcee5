# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""A playback as a picture (PNG, or another format matplotlib writes): the taught map, the
waypoints of the route with their names, the filter's estimate along the run, the simulated
robot's true path and where it came to rest, and the contact when the run ended on one.

The taught map is in the teaching run's odometry frame, which starts at the robot's true start
pose: the true path is drawn in the world frame on the same axes, so that where the two paths
part shows the odometry's drift during teaching plus the estimate's error during playback."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from kiseki.apps.teach.playback import PlaybackResult
from kiseki.grid import OccupancyGrid
from kiseki.plots import draw_map, figure_for_grid, save_figure, world_xy

__all__ = ["render_playback"]


def render_playback(
    result: PlaybackResult,
    environment: OccupancyGrid,
    waypoints: list[dict],
    path: str | os.PathLike,
    label: str = "playback",
) -> Path:
    """Draws `result` (a :func:`~kiseki.apps.teach.playback` run) over its taught map
    `environment` with the route's `waypoints` (the taught marks it followed) to `path` (the
    format from its suffix), titled 'LABEL: goal reached (or not), N steps (T s)'; returns
    the path."""
    if not isinstance(result, PlaybackResult):
        raise TypeError(f"result must be a PlaybackResult, got {type(result).__name__}")
    if not waypoints:
        raise ValueError("waypoints: a route has at least a start and a goal, got none")
    fig, ax = figure_for_grid(environment)
    draw_map(ax, environment)
    marks = world_xy(environment, np.array([[w["x"], w["y"]] for w in waypoints], dtype=float))
    ax.plot(marks[:, 0], marks[:, 1], ":", color="tab:gray", linewidth=1.0, label="route")
    ax.plot(marks[:, 0], marks[:, 1], "s", color="tab:orange", markersize=5, label="waypoints")
    for w, (x, y) in zip(waypoints, marks, strict=True):
        ax.annotate(str(w["name"]), (x, y), textcoords="offset points", xytext=(4, 4), fontsize=8)
    if result.truth is not None and len(result.truth):
        truth = world_xy(environment, result.truth)
        ax.plot(truth[:, 0], truth[:, 1], "--", color="tab:green", linewidth=1.0, label="true path")
        ax.plot(*truth[-1], "o", color="tab:green", markersize=5, label="true stop")
    if result.estimates is not None and len(result.estimates):
        estimate = world_xy(environment, result.estimates)
        ax.plot(estimate[:, 0], estimate[:, 1], "-", color="tab:blue", linewidth=1.2,
                label="estimate")  # fmt: skip
    if result.collision is not None:
        contact = world_xy(environment, np.array([result.collision.contact]))[0]
        ax.plot(*contact, "x", color="tab:red", markersize=10, markeredgewidth=2,
                label=f"contact, t = {result.collision.t:.1f} s")  # fmt: skip
    _zoom(ax, environment, marks, result)
    ax.legend(loc="upper right", fontsize=8)
    reached = "goal reached" if result.reached else "goal not reached"
    ax.set_title(f"{label}: {reached}, {result.steps} steps ({result.duration:.1f} s)")
    return save_figure(fig, path)


def _zoom(ax, environment: OccupancyGrid, marks: np.ndarray, result: PlaybackResult) -> None:
    """Limits the axes to the map's known cells, the waypoints and the paths, 1 m around: a
    taught map's grid spans the whole scene and more, most of it unknown."""
    rows, cols = np.nonzero(environment.cells >= 0)
    parts = [marks]
    if len(rows):
        corners = np.array([[cols.min(), rows.min()], [cols.max(), rows.max()]], dtype=float)
        parts.append(world_xy(environment, environment.cell_to_world(corners)))
    for poses in (result.truth, result.estimates):
        if poses is not None and len(poses):
            parts.append(world_xy(environment, poses))
    points = np.vstack(parts)
    low, high = points.min(axis=0) - 1.0, points.max(axis=0) + 1.0
    ax.set_xlim(low[0], high[0])
    ax.set_ylim(low[1], high[1])
