# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Pictures: maps with trajectories and scan points, distance fields (PNG, written atomically).

Figures are :class:`matplotlib.figure.Figure` objects drawn by the Agg canvas and made without
pyplot (:func:`new_figure`): importing kiseki or drawing with it never selects a matplotlib
backend, so a user's backend choice stands, and the figures are not kept by pyplot (there is
nothing to close). matplotlib itself is imported by the first figure, not by importing this
module: a command that draws nothing does not pay for it."""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from kiseki._support.atomic import atomic_write
from kiseki.grid import OccupancyGrid

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = [
    "draw_map",
    "figure_for_grid",
    "map_shades",
    "new_figure",
    "render_distance_field",
    "render_map",
    "save_figure",
    "to_map_frame",
    "world_xy",
]


def new_figure(**kwargs: Any) -> Figure:
    """A matplotlib figure (``Figure(**kwargs)``: figsize, dpi, ...) with an Agg canvas, made
    without pyplot: no backend is selected and pyplot does not keep it. Add axes with
    ``fig.subplots(...)``; ``fig.savefig`` picks the canvas of the file's format (Agg for
    PNG)."""
    # matplotlib on the first figure: importing kiseki.plots (every experiment does) stays fast
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(**kwargs)
    FigureCanvasAgg(fig)
    return fig


def map_shades(grid: OccupancyGrid) -> np.ndarray:
    """Grey levels for display: free white, occupied black, unknown light grey, and
    intermediate probabilities in between."""
    cells = grid.cells.astype(np.float32)
    shades = 1.0 - np.clip(cells, 0, 100) / 100.0
    shades[cells < 0] = 0.78
    return shades


def to_map_frame(grid: OccupancyGrid, points: np.ndarray) -> np.ndarray:
    """World points (n, 2+) -> coordinates in the map's own frame (origin corner, its yaw)."""
    pts = np.asarray(points, dtype=float)[:, :2] - [grid.origin.x, grid.origin.y]
    c, s = np.cos(grid.origin.theta), np.sin(grid.origin.theta)
    return pts @ np.array([[c, -s], [s, c]])


def save_figure(fig: Figure, path: str | os.PathLike) -> Path:
    """Writes the figure to `path` atomically (format from the suffix) at the figure's dpi,
    cropped to what is drawn; returns the path."""
    return atomic_write(Path(path), lambda tmp: fig.savefig(tmp, dpi=fig.dpi, bbox_inches="tight"))


def figure_for_grid(grid: OccupancyGrid, max_inches: float = 12.0) -> tuple[Figure, Axes]:
    """A figure (:func:`new_figure`, 120 dpi) and its axes shaped like the grid: its longer
    side `max_inches` long (the height at least 2.5 in); axes labelled in metres. Draw the grid
    with :func:`draw_map` and points with :func:`world_xy`."""
    aspect = grid.height / grid.width
    width = max_inches if aspect <= 1 else max_inches / aspect
    fig = new_figure(figsize=(width, max(2.5, width * aspect)), dpi=120)
    ax = fig.subplots()
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    return fig, ax


def _extent(grid: OccupancyGrid) -> list[float]:
    if grid.origin.theta == 0.0:
        x0, y0 = grid.origin.x, grid.origin.y
    else:  # draw in the map's own frame
        x0 = y0 = 0.0
    return [x0, x0 + grid.width * grid.resolution, y0, y0 + grid.height * grid.resolution]


def world_xy(grid: OccupancyGrid, points: np.ndarray) -> np.ndarray:
    """World points (n, 2+) -> the (n, 2) coordinates :func:`draw_map` draws them at: world x, y
    for a map without yaw, else the map's own frame (:func:`to_map_frame`)."""
    pts = np.asarray(points, dtype=float)
    if pts.ndim != 2 or pts.shape[1] < 2:
        raise ValueError(f"points must have shape (n, 2) or (n, 3), got {pts.shape}")
    return pts[:, :2] if grid.origin.theta == 0.0 else to_map_frame(grid, pts)


def draw_map(ax, grid: OccupancyGrid) -> None:
    """The grid in grey shades (free white, occupied black, unknown grey) in world metres."""
    ax.imshow(
        map_shades(grid),
        cmap="gray",
        vmin=0,
        vmax=1,
        origin="lower",
        extent=_extent(grid),
        interpolation="nearest",
    )


def render_map(
    grid: OccupancyGrid,
    path: str | os.PathLike,
    trajectory: np.ndarray | None = None,
    points: np.ndarray | None = None,
    title: str | None = None,
) -> Path:
    """Draws the grid, an optional trajectory (n, 2|3) and optional points (m, 2) to a PNG."""
    fig, ax = figure_for_grid(grid)
    draw_map(ax, grid)
    if points is not None and len(points):
        xy = world_xy(grid, points)
        ax.plot(xy[:, 0], xy[:, 1], ".", color="tab:red", markersize=1.5, label="scan points")
    if trajectory is not None and len(trajectory):
        xy = world_xy(grid, trajectory)
        ax.plot(xy[:, 0], xy[:, 1], "-", color="tab:blue", linewidth=1.2, label="trajectory")
        ax.plot(xy[0, 0], xy[0, 1], "o", color="tab:green", markersize=5, label="start")
    if trajectory is not None or points is not None:
        ax.legend(loc="upper right", fontsize=8)
    ax.set_title(title or f"{grid.width} x {grid.height} cells, {grid.resolution} m")
    return save_figure(fig, path)


def render_distance_field(grid: OccupancyGrid, path: str | os.PathLike, clip: float = 2.0) -> Path:
    """Draws the distance to the nearest obstacle (metres, clipped at ``clip``)."""
    fig, ax = figure_for_grid(grid)
    field = np.minimum(grid.distance_field(), clip)
    im = ax.imshow(
        field, cmap="viridis", origin="lower", extent=_extent(grid), interpolation="nearest"
    )
    fig.colorbar(im, ax=ax, label="distance to nearest obstacle (m)", shrink=0.8)
    ax.set_title("distance field")
    return save_figure(fig, path)
