# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``kiseki relocalize``: ranked pose hypotheses of one scan of a log over the whole map."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import typer
from rich.console import Console

from kiseki._support.guard import guarded
from kiseki._support.interrupt import interruptible
from kiseki._support.options import BEAM_LIMIT, THREAD_LIMIT, Count
from kiseki._support.outputs import FIGURE_SUFFIXES, check_suffix
from kiseki._support.table import show
from kiseki.cli._defaults import default_of
from kiseki.cli._off_map import warn_if_off_the_map
from kiseki.datasets import open_scans
from kiseki.filters import RelocalizeConfig, Relocalizer, render_hypotheses
from kiseki.io.ros_map import load_map
from kiseki.mapping import endpoint_agreement

__all__ = ["app"]

app = typer.Typer()
console = Console(soft_wrap=True)

SCAN_LIMIT = 10_000_000


@app.command("relocalize")
@guarded(inputs=("map_file", "log"), outputs=("plot",))
@interruptible()
def relocalize_command(
    map_file: Path = typer.Argument(..., help="ROS map YAML, or a CMU .dat(.gz) map."),
    log: Path = typer.Argument(
        ...,
        help="CARMEN log (.log, .log.gz), kiseki run (.mcap), CMU Wean robotdata log or ROS bag.",
    ),
    scan: int = typer.Option(
        ..., parser=Count("--scan", 0, SCAN_LIMIT), help="Index of the scan (0 = the first)."
    ),
    hypotheses: int = typer.Option(
        default_of(RelocalizeConfig, "hypotheses"),
        parser=Count("--hypotheses", 1, 1000),
        help="Distinct poses to print, best first.",
    ),
    beams: int = typer.Option(
        default_of(RelocalizeConfig, "beams"),
        parser=Count("--beams", 0, BEAM_LIMIT, "0 = every beam"),
        help="Beams used, nav2's max_beams rule.",
    ),
    threads: int = typer.Option(
        default_of(RelocalizeConfig, "threads"),
        parser=Count("--threads", 0, THREAD_LIMIT, "0 = every core"),
        help="Threads of the search (the result is the same for any number).",
    ),
    plot: Path | None = typer.Option(
        None, help="Draw the map with the hypotheses (and the reference pose, if any) (PNG)."
    ),
    as_json: bool = typer.Option(False, "--json", help="Print the hypotheses as JSON."),
) -> None:
    """Relocalize from one scan: search the whole map for the poses that explain scan N of a
    log best (branch-and-bound correlative matching, scored with the likelihood field), and
    print the distinct hypotheses ranked by score, with their error when the log has reference
    poses.

    Example: kiseki relocalize map.yaml run.mcap --scan 10 --hypotheses 3"""
    check_suffix("--plot", plot, FIGURE_SUFFIXES)
    scans = open_scans(log)
    if scan >= len(scans):
        raise ValueError(f"--scan {scan}: {log} has {len(scans)} scans (0..{len(scans) - 1})")
    grid = load_map(map_file)
    config = RelocalizeConfig(hypotheses=hypotheses, beams=beams, threads=threads)
    found = Relocalizer(grid, scans.max_range, config).match(scans.angles, scans.ranges[scan])
    if not found:
        raise ValueError(f"scan {scan} of {log}: no beam returned, nothing to match")
    best = np.array([[found[0].x, found[0].y, found[0].theta]])
    share = endpoint_agreement(
        grid, best, scans.ranges[scan : scan + 1], scans.angles, scans.max_range
    )
    warn_if_off_the_map(grid, best, None, map_file, share)  # another building's map, say
    truth = scans.poses[scan] if scans.has_reference_poses else None
    rows, data = [], []
    for rank, h in enumerate(found, start=1):
        record = {"rank": rank, "x": h.x, "y": h.y, "theta_deg": math.degrees(h.theta)}
        record["score"] = h.score
        if truth is not None:
            record["error_m"] = float(np.hypot(h.x - truth[0], h.y - truth[1]))
            turn = math.remainder(h.theta - float(truth[2]), 2 * math.pi)
            record["heading_error_deg"] = abs(math.degrees(turn))
        data.append(record)
        rows.append([f"{v:.3f}" if isinstance(v, float) else v for v in record.values()])
    columns = list(data[0])
    title = f"{log.name} scan {scan}: {len(found)} hypotheses over {map_file.name}"
    show(title, columns, rows, as_json=as_json, data=data, console=console)
    if plot is not None:
        render_hypotheses(grid, found, plot, None if truth is None else tuple(truth), title)
