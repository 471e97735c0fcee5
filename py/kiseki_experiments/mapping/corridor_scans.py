# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""corridor-scans: a self-check of the simulator-to-map chain on the factory corridor map kept
in data/maps (the 0.4 m band of data/worlds/factory_corridor.yaml). Each trial drives a laser
(Hokuyo UTM-30LX, sigma 0.01 m) along the corridor on a line offset sideways by a seeded random
amount, rebuilds the map from the noisy scans and measures it against the true map. Needs
nothing outside the repository."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from kiseki.core import Random
from kiseki.grid import beam_angles
from kiseki.io.ros_map import load_map
from kiseki.mapping import build_map, endpoint_agreement
from kiseki.plots import new_figure
from kiseki_experiments.harness.base import Analysis, Experiment, TrialOutput
from kiseki_experiments.harness.config import NonNegativeReal, Share, Spacing
from kiseki_experiments.harness.paths import MAPS
from kiseki_experiments.harness.verdict import ClaimSpec, Control, Criterion, Evidence

MAP = MAPS / "factory_corridor.yaml"


@dataclass(frozen=True)
class CorridorLaser:
    """The laser of this check: a Hokuyo UTM-30LX (270 deg, 1081 beams, 30 m; datasheet
    accuracy +-30 mm taken as 3 sigma) at the robot's centre, one scan every `scan_spacing` m
    along the corridor from P0 (x = 0) to P2 (x = 13.0 m)."""

    seed: int = 0
    beams: int = 1081
    field_of_view_deg: float = 270.0
    max_range: float = 30.0
    range_noise_sd: float = 0.01
    scan_spacing: float = 0.1
    goal_x: float = 13.0


def simulate_scans(
    grid, laser: CorridorLaser, lateral_offset: float = 0.0
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Poses (n, 3), noisy ranges (n, b) and beam angles (b,) along y = lateral_offset."""
    xs = np.arange(0.0, laser.goal_x + 1e-9, laser.scan_spacing)
    poses = np.column_stack([xs, np.full_like(xs, lateral_offset), np.zeros_like(xs)])
    angles = beam_angles(laser.beams, np.deg2rad(laser.field_of_view_deg))
    ranges = grid.cast_scans(poses, angles, max_range=laser.max_range)
    noise = Random(laser.seed).normal(0.0, laser.range_noise_sd, ranges.size)
    hit = ranges < laser.max_range
    ranges[hit] += noise.reshape(ranges.shape)[hit]
    np.maximum(ranges, 0.0, out=ranges)  # a laser reads no negative range (beams at a wall)
    return poses, ranges.astype(np.float32), angles


@dataclass(frozen=True)
class CorridorScansConfig:
    map_file: str = str(MAP)
    range_noise_sd: NonNegativeReal = 0.01  # m, UTM-30LX +-30 mm taken as 3 sigma
    max_lateral_offset: NonNegativeReal = 0.5  # m, uniform in [-max, max] per trial
    scan_spacing: Spacing = 0.1  # m
    precision_threshold: Share = 0.99  # share of rebuilt occupied cells on true obstacles


def preflight(config: CorridorScansConfig) -> None:
    if not Path(config.map_file).is_file():
        raise FileNotFoundError(f"corridor-scans: map {config.map_file} not found")
    if config.range_noise_sd < 0 or config.max_lateral_offset < 0 or config.scan_spacing <= 0:
        raise ValueError("corridor-scans: noise, offset must be >= 0 and spacing > 0")


def trial(config: CorridorScansConfig, index: int, seed: int) -> TrialOutput:
    del index
    truth = load_map(config.map_file)
    offset = Random(seed).uniform(-config.max_lateral_offset, config.max_lateral_offset, 1)[0]
    demo = CorridorLaser(
        seed=seed, range_noise_sd=config.range_noise_sd, scan_spacing=config.scan_spacing
    )
    poses, ranges, angles = simulate_scans(truth, demo, lateral_offset=offset)
    rebuilt = build_map(poses, ranges, angles, demo.max_range)
    occupied = np.argwhere(rebuilt.cells == 100)[:, ::-1].astype(float)
    cells = truth.world_to_cell(rebuilt.cell_to_world(occupied))
    inside = (cells[:, 0] >= 0) & (cells[:, 0] < truth.width) & (cells[:, 1] >= 0)
    inside &= cells[:, 1] < truth.height
    field = truth.distance_field()
    near = np.zeros(len(cells), dtype=bool)
    near[inside] = field[cells[inside, 1], cells[inside, 0]] <= 1.5 * truth.resolution
    record = {
        "lateral_offset": float(offset),
        "endpoints_on_truth": endpoint_agreement(truth, poses, ranges, angles, demo.max_range),
        "endpoints_on_rebuilt": endpoint_agreement(rebuilt, poses, ranges, angles, demo.max_range),
        "occupied_precision": float(near.mean()),
        "occupied_cells": len(occupied),
    }
    return TrialOutput(record)


def analyze(config, trials: pd.DataFrame, timings: pd.DataFrame, figures: Path) -> Analysis:
    ok = trials[trials["error"].isna()]
    summary = ok[["endpoints_on_truth", "endpoints_on_rebuilt", "occupied_precision"]].describe()
    summary = summary.T.reset_index(names="quantity")
    worst = float(ok["occupied_precision"].min()) if len(ok) else float("nan")
    evidence = [
        Evidence.of(
            "precision",
            ok["occupied_precision"],
            shown=f"mean over trials; worst trial {worst:.4f}",
            note="self-check: ray casting, noise model, mapping and map files agree",
        )
    ]
    fig = new_figure(figsize=(6, 3.5), dpi=120)
    ax = fig.subplots()
    ax.scatter(ok["lateral_offset"], ok["occupied_precision"], s=12)
    ax.set_xlabel("lateral offset of the path (m)")
    ax.set_ylabel("occupied-cell precision")
    path = figures / "precision_vs_offset.png"
    fig.savefig(path, bbox_inches="tight")
    return Analysis(tables={"summary": summary}, figures=[path], evidence=evidence)


CLAIMS = (
    ClaimSpec(
        key="precision",
        claim="rebuilt occupied cells lie within 1.5 cells of a true obstacle",
        unit="share of rebuilt occupied cells",
        criterion=Criterion(
            paper_value=">= 0.99 (kiseki's self-check)",
            compare=">=",
            threshold=0.99,
            why="a 1 cm range noise moves an endpoint by a fifth of a 5 cm cell: at most 1 in "
            "100 occupied cells may stray further than 1.5 cells",
            bounds=(0.0, 1.0),
        ),
        control=Control(
            name="range noise 0.15 m (3 cells) instead of 1 cm",
            overrides=("range_noise_sd=0.15", "scan_spacing=0.5"),
            runs=5,
            why="endpoints scattered over 3 cells land beyond 1.5 cells of the wall",
        ),
        measure="a trial's share of rebuilt occupied cells near a true obstacle",
    ),
)


EXPERIMENT = Experiment(
    name="corridor-scans",
    paper="kiseki self-checks (no paper)",
    artefact="simulated laser -> map",
    description="rebuild the factory corridor map from simulated noisy scans, per seed",
    config_type=CorridorScansConfig,
    trial=trial,
    analyze=analyze,
    default_runs=10,
    preflight=preflight,
    claims=CLAIMS,
)
