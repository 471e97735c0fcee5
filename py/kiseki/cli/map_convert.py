# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``kiseki map convert``: a map saved as a ROS map YAML + PGM."""

from __future__ import annotations

from pathlib import Path

import typer
from rich.console import Console

from kiseki._support.guard import guarded
from kiseki._support.interrupt import interruptible
from kiseki._support.outputs import check_suffix
from kiseki.cli.map import MAP_IMAGE, refuse_foreign_image
from kiseki.grid import grid_summary
from kiseki.io.ros_map import load_map, save_map

__all__ = ["app"]

app = typer.Typer()
console = Console(soft_wrap=True)  # piped: one line stays one line (grep, awk)


@app.command("convert")
@guarded(inputs=("map_file",), outputs=("output", MAP_IMAGE))
@interruptible()
def map_convert(
    map_file: Path = typer.Argument(..., metavar="MAP", help="ROS map YAML or CMU .dat(.gz) map."),
    output: Path = typer.Option(..., "-o", "--output", help="ROS map YAML to write (PGM beside)."),
) -> None:
    """Save a map (e.g. the CMU Wean .dat.gz) as a ROS map YAML + PGM (trinary).

    Example: kiseki map convert data/maps/factory_corridor.yaml -o corridor.yaml"""
    check_suffix("--output", output, (".yaml", ".yml"))
    refuse_foreign_image(output)
    grid = load_map(map_file)
    save_map(grid, output)
    summary = grid_summary(grid)
    console.print(
        f"{output}: {grid.width} x {grid.height} cells at {grid.resolution} m; "
        f"{summary['free']} free, {summary['occupied']} occupied, {summary['unknown']} unknown"
    )
