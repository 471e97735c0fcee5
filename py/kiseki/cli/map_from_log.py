# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``kiseki map from-log``: an occupancy grid from a log's poses and scans."""

from __future__ import annotations

import time
from pathlib import Path

import typer
from rich.console import Console

from kiseki._support.guard import guarded
from kiseki._support.interrupt import interruptible
from kiseki._support.options import CELL_LIMITS, REACH_LIMIT, Metres, refuse_given
from kiseki._support.outputs import FIGURE_SUFFIXES, check_suffix
from kiseki.cli._defaults import default_of
from kiseki.cli._off_map import has_endpoints
from kiseki.cli.map import MAP_IMAGE, refuse_foreign_image
from kiseki.datasets import open_scans
from kiseki.datasets.rosbag import is_ros_bag
from kiseki.io.ros_map import load_map, save_map
from kiseki.mapping import MapBuildConfig, endpoint_agreement, map_of_log
from kiseki.plots import render_map
from kiseki.teach.environment_map import build_teaching_map

__all__ = ["app"]

app = typer.Typer()
console = Console(soft_wrap=True)  # piped: one line stays one line (grep, awk)


@app.command("from-log")
@guarded(inputs=("log",), outputs=("output", MAP_IMAGE, "render"))
@interruptible()
def map_from_log(
    ctx: typer.Context,
    log: Path = typer.Argument(
        ...,
        help="CARMEN log (.log, .log.gz), kiseki run (.mcap), ROS 1 bag (.bag) or ROS 2 bag "
        "(folder, .db3 or .mcap).",
    ),
    output: Path = typer.Option(..., "-o", "--output", help="Map YAML to write (image beside)."),
    resolution: float = typer.Option(
        default_of(MapBuildConfig, "resolution"),
        parser=Metres("--resolution", *CELL_LIMITS),
        help="Cell size in metres.",
    ),
    usable_range: float = typer.Option(
        default_of(MapBuildConfig, "usable_range"),
        parser=Metres("--usable-range", 0, REACH_LIMIT, lo_open=True),
        help="Free space is marked at most this far (m); --rules log-odds only.",
    ),
    render: Path | None = typer.Option(None, help="Also draw the map and trajectory to this PNG."),
    rules: str = typer.Option(
        "log-odds",
        help="log-odds (occupancy probabilities), teaching (the thesis' merge rules: the map "
        "the space observation model expects; use --resolution 0.1) or evidence (a teaching map "
        "whose cells turn free only when their free observations outweigh their hits).",
    ),
    scan_topic: str = typer.Option("/scan", help="ROS bags: the sensor_msgs/LaserScan topic."),
    odom_topic: str = typer.Option(
        "/odom", help="ROS bags: the nav_msgs/Odometry topic (if absent: odom -> base on /tf)."
    ),
    reference_topic: str | None = typer.Option(
        None, help="ROS bags: a nav_msgs/Odometry topic of reference poses, e.g. /ground_truth."
    ),
) -> None:
    """Build an occupancy grid from a log's poses and scans and save it as a ROS map.

    Example: kiseki map from-log run.mcap -o map.yaml --render map.png"""
    if rules not in ("log-odds", "teaching", "evidence"):
        raise ValueError(f"--rules must be log-odds, teaching or evidence, got {rules!r}")
    if rules != "log-odds":  # teaching maps merge 8 m local maps: they have no usable range
        refuse_given(ctx, ["usable_range"], f"to --rules {rules} (only to log-odds)")
    check_suffix("--output", output, (".yaml", ".yml"))
    refuse_foreign_image(output)
    check_suffix("--render", render, FIGURE_SUFFIXES)
    config = MapBuildConfig(resolution=resolution, usable_range=usable_range)
    start = time.perf_counter()
    scans = open_scans(log, scan_topic, odom_topic, reference_topic)
    if not scans.has_reference_poses:
        hint = ""
        if reference_topic is None and is_ros_bag(log):
            hint = " (a bag's reference poses come from --reference-topic, e.g. /ground_truth)"
        raise ValueError(f"{log}: the log has no reference poses to build a map from{hint}")
    if not has_endpoints(scans.poses, scans.ranges, scans.max_range):
        raise ValueError(
            f"{log}: no range reading below the max range of {scans.max_range:g} m (a reading "
            "at or beyond it is no return): nothing to map"
        )
    try:  # the map's size follows from the log's poses: its errors name the log
        if rules in ("teaching", "evidence"):
            grid = build_teaching_map(
                scans.poses,
                scans.ranges,
                scans.angles,
                scans.max_range,
                resolution,
                rule="thesis" if rules == "teaching" else "evidence",
                progress=True,
            )
        else:
            grid = map_of_log(scans, config, True)
    except ValueError as err:
        raise ValueError(f"{log}: {err}") from None
    seconds = time.perf_counter() - start
    saved = load_map(save_map(grid, output))
    share = endpoint_agreement(saved, scans.poses, scans.ranges, scans.angles, scans.max_range)
    if render is not None:
        render_map(saved, render, trajectory=scans.poses, title=f"{log.name}")
    console.print(
        f"{output}: {grid.width} x {grid.height} cells at {grid.resolution} m from "
        f"{len(scans)} scans ({scans.invalid_ranges} invalid range readings skipped) in "
        f"{seconds:.2f} s; {100 * share:.1f} % of scan endpoints on or next to occupied cells"
    )
