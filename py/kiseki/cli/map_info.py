# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``kiseki map info``: a map's size, resolution, origin and cell counts."""

from __future__ import annotations

from pathlib import Path

import typer
from rich.console import Console

from kiseki._support.guard import guarded
from kiseki._support.table import show_fields
from kiseki.grid import grid_summary
from kiseki.io.ros_map import load_map

__all__ = ["app"]

app = typer.Typer()
console = Console(soft_wrap=True)  # piped: one line stays one line (grep, awk)


@app.command("info")
@guarded(inputs=("map_file",))
def map_info(
    map_file: Path = typer.Argument(..., metavar="MAP", help="ROS map YAML or CMU .dat map."),
    as_json: bool = typer.Option(False, "--json", help="Print one JSON object."),
) -> None:
    """Print a map's size, resolution, origin and cell counts: a table on a terminal,
    tab-separated field/value lines when piped, or JSON with --json.

    Example: kiseki map info data/maps/factory_corridor.yaml --json"""
    summary = grid_summary(load_map(map_file))
    show_fields(str(map_file), summary, as_json=as_json, console=console)
