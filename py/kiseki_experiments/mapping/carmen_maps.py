# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""carmen-maps: for each CARMEN log with SLAM-corrected poses, build the map from those poses
and measure how many scan endpoints land on (or next to) its occupied cells, the map's size
and the build time. The claims are the foundation's map-quality threshold (>= 90 % of the
endpoints), set for the Intel log and applied here to every log."""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from kiseki.core import Random
from kiseki.datasets import read_carmen_log
from kiseki.mapping import MapBuildConfig, endpoint_agreement, map_of_log
from kiseki.plots import new_figure
from kiseki_experiments.harness.base import Analysis, Experiment, TrialOutput
from kiseki_experiments.harness.config import NonNegativeReal, PositiveReal, Resolution, Share
from kiseki_experiments.harness.paths import CARMEN_LOGS, shared_data
from kiseki_experiments.harness.verdict import ClaimSpec, Control, Criterion, Evidence

RANGE_BANDS = [(0.0, 5.0), (5.0, 15.0), (15.0, 100.0)]  # metres
LOGS = CARMEN_LOGS


@dataclass(frozen=True)
class CarmenMapsConfig:
    data_dir: str = ""  # folder of the .log.gz files; "" = ../shared/data/carmen
    logs: list[str] = field(default_factory=lambda: list(LOGS))
    resolution: Resolution = 0.05  # m, as in the foundation issue
    usable_range: PositiveReal = 30.0  # m
    threshold: Share = 0.90  # share of endpoints on/next to occupied cells (foundation issue)
    # m, seeded noise added to every corrected pose's x and y (0: the corrected poses as
    # recorded); the claims' control sets it to show their criterion can fail
    pose_noise_sd: NonNegativeReal = 0.0


def data_dir(config: CarmenMapsConfig) -> Path:
    return shared_data("carmen", config.data_dir)


def preflight(config: CarmenMapsConfig) -> None:
    folder = data_dir(config)
    if not config.logs:
        raise ValueError("carmen-maps: logs is empty")
    missing = [n for n in config.logs if not (folder / f"{n}.log.gz").is_file()]
    if missing:
        raise FileNotFoundError(f"carmen-maps: {folder}: missing {', '.join(missing)}.log.gz")


def trial(config: CarmenMapsConfig, index: int, seed: int) -> TrialOutput:
    """Trial i maps log i modulo the number of logs (map building is deterministic: the
    seed is used only by ``pose_noise_sd``)."""
    name = config.logs[index % len(config.logs)]
    start = time.perf_counter()
    scans = read_carmen_log(data_dir(config) / f"{name}.log.gz").scans
    if config.pose_noise_sd > 0:
        noise = Random(seed).normal(0.0, config.pose_noise_sd, 2 * len(scans.poses))
        scans.poses[:, :2] += noise.reshape(-1, 2)
    read_s = time.perf_counter() - start
    build_config = MapBuildConfig(resolution=config.resolution, usable_range=config.usable_range)
    start = time.perf_counter()
    grid = map_of_log(scans, build_config)
    build_s = time.perf_counter() - start
    share = endpoint_agreement(grid, scans.poses, scans.ranges, scans.angles, scans.max_range)
    by_band = {}
    for low, high in RANGE_BANDS:  # where the endpoints that miss come from
        band = np.where((scans.ranges >= low) & (scans.ranges < high), scans.ranges, np.inf)
        band = band.astype(np.float32)
        if np.isfinite(band).any():
            by_band[f"share_{low:g}_{high:g}m"] = endpoint_agreement(
                grid, scans.poses, band, scans.angles, scans.max_range
            )
        else:
            by_band[f"share_{low:g}_{high:g}m"] = float("nan")
        by_band[f"endpoints_{low:g}_{high:g}m"] = int(np.isfinite(band).sum())
    cells = grid.cells
    record = {
        "log": name,
        "scans": len(scans),
        "beams": int(scans.ranges.shape[1]),
        "width": grid.width,
        "height": grid.height,
        "size_x_m": grid.width * grid.resolution,
        "size_y_m": grid.height * grid.resolution,
        "occupied_cells": int((cells == 100).sum()),
        "free_cells": int((cells == 0).sum()),
        "endpoint_share": share,
        **by_band,
    }
    return TrialOutput(record, {"read_seconds": read_s, "build_seconds": build_s})


def analyze(config, trials: pd.DataFrame, timings: pd.DataFrame, figures: Path) -> Analysis:
    ok = trials[trials["error"].isna()].merge(timings, on="trial")
    per_log = (
        ok.groupby("log", sort=False)
        .agg(
            scans=("scans", "first"),
            beams=("beams", "first"),
            width=("width", "first"),
            height=("height", "first"),
            size_x_m=("size_x_m", "first"),
            size_y_m=("size_y_m", "first"),
            endpoint_share=("endpoint_share", "mean"),
            **{c: (c, "mean") for c in trials.columns if c.startswith(("share_", "endpoints_"))},
            build_seconds=("build_seconds", "median"),
            trials=("trial", "count"),
        )
        .reset_index()
    )
    bands = [f"endpoints_{low:g}_{high:g}m" for low, high in RANGE_BANDS]
    evidence = []
    for row in per_log.itertuples():
        n = int(round(sum(getattr(row, b) for b in bands)))  # the endpoints of the range bands
        evidence.append(
            Evidence.share(
                "endpoints",
                round(row.endpoint_share * n),
                n,
                subject=row.log,
                note="foundation threshold"
                if row.log.startswith("intel")
                else "the Intel threshold applied to another building",
            )
        )
    fig = new_figure(figsize=(7, 3.5), dpi=120)
    ax = fig.subplots()
    ax.bar(per_log["log"], per_log["endpoint_share"], color="tab:blue")
    ax.axhline(config.threshold, color="tab:red", linestyle="--", label="threshold")
    ax.set_ylim(0.8, 1.0)
    ax.set_ylabel("endpoints on/next to occupied")
    ax.legend()
    fig.autofmt_xdate(rotation=20)
    path = figures / "endpoint_share.png"
    fig.savefig(path, bbox_inches="tight")
    notes = (
        f"Maps at {config.resolution} m from the logs' corrected poses; a cell counts as "
        "occupied above p = 0.65. Build times are medians over the trials of each log. "
        "The share_* columns split the endpoints by measured range: a 1 deg beam at 15 m is "
        "already 0.26 m wide, so distant walls are sampled sparsely and their endpoints agree "
        "less; where a log stays below the threshold even within 5 m, the misses are on "
        "objects seen briefly (people, doors, furniture moved) that later scans clear."
    )
    notes += (
        " The interval is Wilson's over the log's endpoints, as if independent; neighbouring "
        "endpoints are not, so it is narrower than a resampling of whole scans would give."
    )
    return Analysis(tables={"per_log": per_log}, figures=[path], notes=notes, evidence=evidence)


CLAIMS = (
    ClaimSpec(
        key="endpoints",
        claim="scan endpoints on or next to occupied cells",
        unit="share of endpoints",
        criterion=Criterion(
            paper_value=">= 0.90 (the foundation issue's threshold)",
            compare=">=",
            threshold=0.90,
            why="the foundation issue's threshold for the Intel log: 9 in 10 endpoints on a "
            "wall of the map built from the same scans",
            bounds=(0.0, 1.0),
        ),
        control=Control(
            name="poses blurred by 0.3 m of noise (the corrections undone)",
            overrides=("pose_noise_sd=0.3", "logs=intel-corrected"),
            runs=1,
            why="a map built from poses off by 6 cells smears every wall",
        ),
        measure="the endpoints of every scan of a log (one trial per log)",
    ),
)


EXPERIMENT = Experiment(
    name="carmen-maps",
    paper="foundation thresholds (no paper)",
    artefact="map quality on real logs",
    description="maps built from CARMEN logs with corrected poses: endpoint agreement, size, time",
    config_type=CarmenMapsConfig,
    trial=trial,
    analyze=analyze,
    default_runs=len(LOGS),
    preflight=preflight,
    claims=CLAIMS,
)
