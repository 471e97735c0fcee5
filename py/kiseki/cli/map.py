# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``kiseki map``: occupancy-grid maps: build, render, inspect. A group that loads each of its
commands' modules only when that command runs (``kiseki map info`` does not load matplotlib or
the log readers that ``kiseki map from-log`` needs)."""

from __future__ import annotations

from pathlib import Path

import typer

from kiseki._support.guard import Derived
from kiseki._support.yaml import read_yaml_file
from kiseki.cli._lazy import Entry, LazyGroup

__all__ = ["COMMANDS", "MAP_IMAGE", "app", "refuse_foreign_image"]

# the image a map YAML names, written beside it (kiseki._support.guard)
MAP_IMAGE = Derived("--output's image", lambda a: a["output"].with_suffix(".pgm"))

# its commands in listing order, each with its module and its line (its first paragraph)
COMMANDS = {
    "from-log": Entry(
        "kiseki.cli.map_from_log",
        "Build an occupancy grid from a log's poses and scans and save it as a ROS map.",
        group=False,
    ),
    "render": Entry(
        "kiseki.cli.map_render",
        "Draw a map (and a trajectory over it) to a PNG.",
        group=False,
    ),
    "convert": Entry(
        "kiseki.cli.map_convert",
        "Save a map (e.g. the CMU Wean .dat.gz) as a ROS map YAML + PGM (trinary).",
        group=False,
    ),
    "info": Entry(
        "kiseki.cli.map_info",
        "Print a map's size, resolution, origin and cell counts: a table on a terminal, "
        "tab-separated field/value lines when piped, or JSON with --json.",
        group=False,
    ),
}


class _MapGroup(LazyGroup):
    table = COMMANDS


app = typer.Typer(
    cls=_MapGroup, no_args_is_help=True, help="Occupancy-grid maps: build, render, inspect."
)


def refuse_foreign_image(output: Path) -> None:
    """An image where --output's is written (X.pgm beside X.yaml) is replaced only as the image
    of the map X.yaml already is (an earlier map saved there, replaced whole); a file of the
    user's own under that name is refused, before any work, and kept. (With no X.yaml at all
    the output guard has refused it already: MAP_IMAGE is a derived output.)"""
    image = output.with_suffix(".pgm")
    if not (image.exists() or image.is_symlink()):
        return
    try:
        content = read_yaml_file(output, "ROS map YAML")
    except (OSError, ValueError):  # not a map: the image is not its
        content = None
    named = None
    if isinstance(content, dict) and isinstance(content.get("image"), str):
        named = output.parent / content["image"]
    if named is None or named.resolve() != image.resolve():
        raise FileExistsError(
            f"--output's image {image} exists and is not the image of the map {output}: "
            f"give another --output name, or move {image.name}"
        )
