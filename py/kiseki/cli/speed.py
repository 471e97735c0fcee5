# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``kiseki speed``: paper 004's speed limit on recorded logs."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import typer
import yaml
from rich.console import Console

from kiseki._support.atomic import atomic_write
from kiseki._support.guard import Derived, guarded
from kiseki._support.interrupt import interruptible
from kiseki._support.options import REACH_LIMIT, Degrees, Metres, Quantity, refuse_given
from kiseki._support.outputs import FIGURE_SUFFIXES, check_suffix
from kiseki.cli._off_map import warn_if_off_the_map
from kiseki.datasets import is_ros_bag, open_scans
from kiseki.io.ros_map import load_map
from kiseki.speed import SpeedLimiterConfig
from kiseki.speed.acceleration import SPEED_LIMIT
from kiseki.speed.along_log import limits_along_log
from kiseki.speed.render import render_limits

__all__ = ["app"]

app = typer.Typer(
    no_args_is_help=True, help="Speed limits that consider occluded regions and passage width."
)
console = Console(soft_wrap=True)
METHODS = ("occlusion", "occlusion-width", "width")
# the settings written beside the CSV (kiseki._support.guard)
_CONFIG = Derived("the config", lambda a: a["output"].with_suffix(".config.yaml"))


@app.command("limits")
@guarded(inputs=("log", "map_file"), outputs=("output", _CONFIG, "plot"))
@interruptible()
def speed_limits(
    ctx: typer.Context,
    log: Path = typer.Argument(
        ...,
        help="Log with reference poses: CARMEN (.log, .log.gz), kiseki run (.mcap), ROS 1 bag "
        "(.bag) or ROS 2 bag (folder, .db3 or .mcap).",
    ),
    map_file: Path = typer.Option(..., "--map", help="ROS map YAML of the log's building."),
    output: Path = typer.Option(..., "-o", "--output", help="CSV to write (one row per scan)."),
    method: str = typer.Option(
        "occlusion-width", help="occlusion (eq. 1), width (eq. 2) or occlusion-width (eq. 4)."
    ),
    reach: float = typer.Option(
        4.0,
        parser=Metres("--reach", 0, REACH_LIMIT, lo_open=True),
        help="Sensor range of eq. 1's region (m); the paper's 4 m.",
    ),
    half_angle: float = typer.Option(
        math.degrees(SpeedLimiterConfig.half_angle),
        parser=Degrees("--half-angle", 0, 180, lo_open=True),
        help="theta: +-degrees around the motion (paper 90); not with --method width.",
    ),
    v_max: float = typer.Option(
        SpeedLimiterConfig.v_max,
        parser=Quantity("--v-max", 0, SPEED_LIMIT, "m/s", lo_open=True),
        help="The robot's maximum speed (m/s).",
    ),
    heading: str = typer.Option(
        "laser", help="Direction of motion: laser (where the robot faces) or motion (its path)."
    ),
    plot: Path | None = typer.Option(None, help="PNG: the map with the path coloured by limit."),
    scan_topic: str = typer.Option("/scan", help="Laser topic (ROS bags)."),
    reference_topic: str | None = typer.Option(
        None, help="Reference pose topic (ROS bags; see kiseki map from-log)."
    ),
) -> None:
    """The speed limit of paper 004 along a recorded log: for each scan at its reference pose,
    eq. 1's ratio, the passage width, f(w) and the limit, written to a CSV (beside it, the
    config as .config.yaml); --plot draws the map and the path coloured by the limit.

    Example: kiseki speed limits intel.log.gz --map intel.yaml -o limits.csv --plot limits.png
    """
    if method not in METHODS:
        raise ValueError(f"--method must be one of {', '.join(METHODS)}, got {method!r}")
    if method == "width":  # eq. 2 measures the passage ahead: no region of +-theta
        refuse_given(ctx, ["half_angle"], "to --method width (eq. 1's region only)")
    config = SpeedLimiterConfig(
        v_max=v_max,
        half_angle=math.radians(half_angle),
        use_occlusion=method != "width",
        use_width=method != "occlusion",
    )
    side = output.with_suffix(".config.yaml")
    check_suffix("--plot", plot, FIGURE_SUFFIXES)
    grid = load_map(map_file)
    topics = {"scan_topic": scan_topic}
    if reference_topic is not None:
        topics["reference_topic"] = reference_topic
    scans = open_scans(log, **topics)
    if not scans.has_reference_poses:  # a topic can be named in a ROS bag only
        hint = " (give --reference-topic)" if is_ros_bag(log) else ""
        raise ValueError(f"{log}: the log has no reference poses{hint}")
    limits = limits_along_log(scans, grid, config, reach, heading)
    warn_if_off_the_map(grid, scans.poses, scans, map_file, poses="reference")
    columns = limits.columns()
    rows = np.column_stack(list(columns.values()))
    text = ",".join(columns) + "\n" + "\n".join(",".join(f"{v:.6g}" for v in r) for r in rows)
    atomic_write(output, lambda tmp: Path(tmp).write_text(text + "\n", encoding="utf-8"))

    doc = {"log": str(log), "map": str(map_file), "method": method, "reach": reach}
    doc |= {"heading": heading, **vars(config)}
    atomic_write(side, lambda tmp: Path(tmp).write_text(yaml.safe_dump(doc), encoding="utf-8"))
    v = limits.v_ref
    console.print(
        f"{output}: {len(v)} scans; limit {v.min():.2f}-{v.max():.2f} m/s (median "
        f"{np.median(v):.2f}); below half of v_max at {np.mean(v < v_max / 2):.0%} of the scans"
    )
    if plot is not None:
        render_limits(grid, limits, plot, v_max, title=f"{log.name}: {method}")
        console.print(f"{plot}: the path coloured by the limit")
