# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Pictures: maps with trajectories and scan points, distance fields (PNG, written atomically)."""

from __future__ import annotations

import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from kiseki._atomic import atomic_write  # noqa: E402
from kiseki.grid import OccupancyGrid  # noqa: E402

__all__ = ["draw_map", "map_shades", "render_distance_field", "render_map", "to_map_frame"]


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


def _save(fig: plt.Figure, path: Path) -> Path:
    try:
        return atomic_write(path, lambda tmp: fig.savefig(tmp, dpi=fig.dpi, bbox_inches="tight"))
    finally:
        plt.close(fig)


def _figure(grid: OccupancyGrid, max_inches: float = 12.0) -> tuple[plt.Figure, plt.Axes]:
    aspect = grid.height / grid.width
    width = max_inches if aspect <= 1 else max_inches / aspect
    fig, ax = plt.subplots(figsize=(width, max(2.5, width * aspect)), dpi=120)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    return fig, ax


def _extent(grid: OccupancyGrid) -> list[float]:
    if grid.origin.theta == 0.0:
        x0, y0 = grid.origin.x, grid.origin.y
    else:  # draw in the map's own frame
        x0 = y0 = 0.0
    return [x0, x0 + grid.width * grid.resolution, y0, y0 + grid.height * grid.resolution]


def _world_xy(grid: OccupancyGrid, points: np.ndarray) -> np.ndarray:
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
    fig, ax = _figure(grid)
    draw_map(ax, grid)
    if points is not None and len(points):
        xy = _world_xy(grid, points)
        ax.plot(xy[:, 0], xy[:, 1], ".", color="tab:red", markersize=1.5, label="scan points")
    if trajectory is not None and len(trajectory):
        xy = _world_xy(grid, trajectory)
        ax.plot(xy[:, 0], xy[:, 1], "-", color="tab:blue", linewidth=1.2, label="trajectory")
        ax.plot(xy[0, 0], xy[0, 1], "o", color="tab:green", markersize=5, label="start")
    if trajectory is not None or points is not None:
        ax.legend(loc="upper right", fontsize=8)
    ax.set_title(title or f"{grid.width} x {grid.height} cells, {grid.resolution} m")
    return _save(fig, Path(path))


def render_distance_field(grid: OccupancyGrid, path: str | os.PathLike, clip: float = 2.0) -> Path:
    """Draws the distance to the nearest obstacle (metres, clipped at ``clip``)."""
    fig, ax = _figure(grid)
    field = np.minimum(grid.distance_field(), clip)
    im = ax.imshow(
        field, cmap="viridis", origin="lower", extent=_extent(grid), interpolation="nearest"
    )
    fig.colorbar(im, ax=ax, label="distance to nearest obstacle (m)", shrink=0.8)
    ax.set_title("distance field")
    return _save(fig, Path(path))
