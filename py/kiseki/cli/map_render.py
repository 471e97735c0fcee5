# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``kiseki map render``: a map (and a trajectory over it) drawn to a PNG."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import typer
from rich.console import Console

from kiseki._support.guard import guarded
from kiseki._support.interrupt import interruptible
from kiseki._support.outputs import FIGURE_SUFFIXES, check_suffix
from kiseki.datasets import read_carmen_log
from kiseki.io.ros_map import load_map
from kiseki.io.trajectory_csv import read_trajectory_csv
from kiseki.plots import render_map

__all__ = ["app"]

app = typer.Typer()
console = Console(soft_wrap=True)  # piped: one line stays one line (grep, awk)


def _read_trajectory(path: Path) -> np.ndarray:
    """x, y[, theta] rows from a CSV with a header naming x and y, or poses of a CARMEN log."""
    if path.name.endswith((".log", ".log.gz")):
        return read_carmen_log(path).scans.poses
    return read_trajectory_csv(path)


@app.command("render")
@guarded(inputs=("map_file", "trajectory"), outputs=("output",))
@interruptible()
def map_render(
    map_file: Path = typer.Argument(..., metavar="MAP", help="ROS map YAML or CMU .dat map."),
    output: Path = typer.Option(..., "-o", "--output", help="PNG to write."),
    trajectory: Path | None = typer.Option(
        None, help="Trajectory to overlay: CSV with x,y columns, or a CARMEN log."
    ),
) -> None:
    """Draw a map (and a trajectory over it) to a PNG.

    Example: kiseki map render data/maps/factory_corridor.yaml -o corridor.png"""
    check_suffix("--output", output, FIGURE_SUFFIXES)
    grid = load_map(map_file)
    path = _read_trajectory(trajectory) if trajectory is not None else None
    render_map(grid, output, trajectory=path, title=map_file.name)
    console.print(f"{output}: {grid.width} x {grid.height} map drawn")
