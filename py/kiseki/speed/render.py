# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Pictures of speed limits: the map with the path coloured by the limit, and the limit and its
terms over time."""

from __future__ import annotations

import os
from pathlib import Path

from kiseki.grid import OccupancyGrid
from kiseki.plots import draw_map, new_figure, save_figure, world_xy
from kiseki.speed.along_log import LimitsAlongLog

__all__ = ["render_limits"]


def render_limits(
    grid: OccupancyGrid,
    limits: LimitsAlongLog,
    path: str | os.PathLike,
    v_max: float,
    title: str = "",
) -> Path:
    """A PNG: left, the map with each scan's pose coloured by its limit (m/s); right, the limit,
    eq. 1's ratio and f(w) against time."""
    fig = new_figure(figsize=(13, 5.5), dpi=120)
    ax_map, ax_t = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1.2, 1]})
    draw_map(ax_map, grid)
    xy = world_xy(grid, limits.poses)
    dots = ax_map.scatter(
        xy[:, 0], xy[:, 1], c=limits.v_ref, s=4, cmap="RdYlGn", vmin=0, vmax=v_max
    )
    fig.colorbar(dots, ax=ax_map, label="speed limit (m/s)", shrink=0.8)
    ax_map.set_xlabel("x (m)")
    ax_map.set_ylabel("y (m)")
    t = limits.times - limits.times[0]
    ax_t.plot(t, limits.v_ref / v_max, lw=1, label="limit / v_max")
    ax_t.plot(t, limits.ratio, lw=0.8, alpha=0.7, label="eq. 1 ratio")
    ax_t.plot(t, limits.width_factor, lw=0.8, alpha=0.7, label="f(w)")
    ax_t.set_xlabel("time (s)")
    ax_t.set_ylim(0, 1.05)
    ax_t.legend(fontsize=8, loc="lower right")
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    return save_figure(fig, path)
