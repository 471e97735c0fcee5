# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""terrain-global-map: paper 003's loop (Fig. 1) over a sequence of moves: local map, move,
local map, correlation search, merge into the global map. The robot stops every 0.35 m along
data/worlds/rubble_a.yaml's route (over the slope, between the heaps; kiseki.sim.terrain_moves),
each stop a tilting-laser sweep (median of 3) with the gyro's attitude read 10 s after the
previous one; the estimates chain the searched moves (kiseki.terrain.mapper) and every sweep is
merged into an OctoMap at its estimated pose. The paper shows the loop and its maps without a
multi-move error figure: the drift is measured here (the position error against the distance
travelled) and the global map saved for octovis.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from kiseki.sim.terrain_moves import terrain_stops
from kiseki.terrain.mapper import MapperConfig, SdemMapper
from kiseki.terrain.render import render_run
from kiseki_experiments.harness.base import Analysis, Claim, Experiment, TrialOutput
from kiseki_experiments.harness.config import Count, Resolution
from kiseki_experiments.harness.paths import WORLDS

__all__ = ["GLOBAL_MAP", "GlobalMapConfig"]

DRIFT_LIMIT = 0.10
"""kiseki's criterion (the paper gives none): the final error below 10 % of the distance."""


@dataclass(frozen=True)
class GlobalMapConfig:
    scene: str = str(WORLDS / "rubble_a.yaml")
    moves: Count = 10
    step: Resolution = 0.35
    removal: str = "hough"
    search: str = "exhaustive"
    cost: str = "sum"  # eq. 4 as printed; "mean": kiseki's variant
    voxel: Resolution = 0.05


def preflight(config: GlobalMapConfig) -> None:
    MapperConfig(removal=config.removal, search=config.search, cost=config.cost)
    if not Path(config.scene).is_file():
        raise FileNotFoundError(f"terrain-global-map: scene {config.scene} not found")
    if not 0.02 <= config.step <= 0.6:
        raise ValueError(f"terrain-global-map: step must be 0.02..0.6 m, got {config.step}")


def _run(config: GlobalMapConfig, seed: int):
    stops = terrain_stops(config.scene, config.moves, seed, config.step)
    mapper_config = MapperConfig(
        removal=config.removal, search=config.search, cost=config.cost, voxel=config.voxel,
        seed=seed,
    )  # fmt: skip
    mapper = SdemMapper(mapper_config, start=stops[0].sensor[:3, 3])
    for stop in stops:
        mapper.add(stop.ranges, stop.gyro_rpy)
    true = np.array([s.sensor[:3, 3] for s in stops])
    return true, mapper


def trial(config: GlobalMapConfig, index: int, seed: int) -> TrialOutput:
    true, mapper = _run(config, seed)
    est = mapper.positions
    err = np.linalg.norm(est - true, axis=1)
    steps = np.linalg.norm(np.diff(est, axis=0) - np.diff(true, axis=0), axis=1)
    travelled = float(np.sum(np.linalg.norm(np.diff(true, axis=0), axis=1)))
    record = {
        "travelled_m": travelled,
        "final_error_m": float(err[-1]),
        "max_error_m": float(err.max()),
        "drift_share": float(err[-1] / travelled),
        "step_error_mean_m": float(steps.mean()),
        "step_error_max_m": float(steps.max()),
        "final_z_error_m": float(est[-1, 2] - true[-1, 2]),
        "occupied_voxels": int(mapper.global_map.occupied_leaves),
    }
    return TrialOutput(record)


def analyze(config: GlobalMapConfig, trials, timings, figures: Path) -> Analysis:
    ok = trials[trials["error"].isna()]
    if ok.empty:
        return Analysis(notes="every trial failed: nothing to analyse")
    cols = ["travelled_m", "final_error_m", "max_error_m", "drift_share", "step_error_mean_m",
            "step_error_max_m", "final_z_error_m", "occupied_voxels"]  # fmt: skip
    table = ok[["trial", "seed", *cols]].reset_index(drop=True)
    mean = table[cols].mean()
    claims = [
        Claim(
            claim="the loop of local maps, searches and merges builds a global map over a "
            "sequence of moves",
            paper_value="Fig. 1's loop; no multi-move error figure",
            measured_value=f"{config.moves} moves over {mean['travelled_m']:.2f} m: final "
            f"error {100 * mean['final_error_m']:.1f} cm ({100 * mean['drift_share']:.1f} % of "
            f"the distance), per-move error {100 * mean['step_error_mean_m']:.1f} cm",
            unit="% of distance",
            holds=bool(mean["drift_share"] < DRIFT_LIMIT),
            note="kiseki's criterion: the mean final error below 10 % of the distance",
        )
    ]
    seed0 = int(ok.sort_values("trial")["seed"].iloc[0])
    true, mapper = _run(config, seed0)
    rows = np.column_stack([np.arange(len(true)), true, mapper.positions])
    path = figures / "terrain_global_map.png"
    render_run(rows, mapper.global_map, path, title=f"rubble_a, {config.moves} moves, first trial")
    mapper.global_map.write_binary(str(figures / "terrain_global_map.bt"))
    notes = (
        "Stops every {:.2f} m along rubble_a's route; removal {}, search {}, cost {}. The "
        "per-move errors (mean {:.1f} cm) come mostly from the gyro's 0.5 deg reading error "
        "(terrain-env-a: 3.7 cm with an exact gyro) and add up as a random walk along the chain; "
        "z drifts with the gyro's pitch. figures/terrain_global_map.bt is the first trial's "
        "global map (octovis opens it)."
    ).format(config.step, config.removal, config.search, config.cost,
             100 * mean["step_error_mean_m"])  # fmt: skip
    return Analysis({"drift": table}, [path], claims, notes)


GLOBAL_MAP = Experiment(
    name="terrain-global-map",
    paper="003_fd335d240f62896b.txt",
    artefact="Fig. 1 (the loop)",
    description="a multi-move run in rubble_a building an OctoMap global map: drift reported",
    config_type=GlobalMapConfig,
    trial=trial,
    analyze=analyze,
    default_runs=5,
    preflight=preflight,
)
