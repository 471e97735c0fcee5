# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""mcl-unknown-obstacles: what the space observation model exists for, measured on real logs.

The teaching-and-playback thesis built its model so that obstacles missing from the taught map
(people, carts, boxes) do not make the robot lost (sec. 3.3: a local map that sees an object
where the map is free *intrudes*, which costs little; seeing through a wall *penetrates*, which
costs much). Here seeded unknown obstacles are added to the shared CARMEN logs
(:func:`kiseki.datasets.occlude_scans`: the recorded ranges are cut where a beam meets one), at
``densities`` obstacles per 10 m of the route, and four sensor models track each log from its
first pose with the same noisy odometry: the likelihood field, the beam model, the thesis'
space observation model (as printed), kiseki's ray space observation model and the odometry
alone. The maps are built from the logs
without obstacles; the obstacles are unknown to every model.

Placement (seeded, per log and trial): a point of the route is drawn uniformly by travel
distance, and an obstacle is put ``clearance``-``band`` m from it in a uniform direction: with
probability 1/2 a disc of radius 0.2-0.3 m (a person seen at hip height), else a box of half
sides 0.15-0.5 m at any heading. It is kept only if its bounding circle lies on known free
cells of the map and is at least ``clearance`` from every laser pose of the log (the robot never
drives through it); up to 50 draws per obstacle wanted, and the count placed is reported.

Claims: (1) the sweep reaches a density where the likelihood field's RMSE at least doubles over
the same log and seed without obstacles (so the sweep is dense enough to matter); (2) at the
densest setting the thesis' model tracks more closely than the likelihood field, which is what
its tolerance of intrusion is for; (3) there kiseki's ray space observation model tracks more
closely than the likelihood field. Each is per log, over the trial seeds; they and their
control are declared in ``mcl_unknown_obstacles_claims``.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated

import numpy as np
import pandas as pd
from scipy.spatial import cKDTree

from kiseki.core import derive_seed
from kiseki.datasets import UnknownObstacles, occlude_scans, read_carmen_log
from kiseki.filters import RECOVERY_MODES, LocalizeConfig, localize
from kiseki.grid import OccupancyGrid
from kiseki.mapping import MapBuildConfig, map_of_log
from kiseki.metrics import ape
from kiseki.plots import new_figure
from kiseki.teach.environment_map import build_teaching_map
from kiseki_experiments.harness.base import Analysis, Experiment, TrialOutput
from kiseki_experiments.harness.config import (
    Count,
    NonEmpty,
    NonNegativeReal,
    Particles,
    PositiveReal,
    Scans,
    Threads,
)
from kiseki_experiments.harness.paths import CARMEN_LOGS, shared_data
from kiseki_experiments.harness.verdict import Evidence
from kiseki_experiments.mcl.mcl_unknown_obstacles_claims import CLAIMS

__all__ = ["EXPERIMENT", "METHODS", "UnknownObstaclesConfig", "place_obstacles"]

METHODS = ("likelihood-field", "beam", "space-observation", "ray-space-observation", "odometry")
#: the map each method weighs against: the thesis' teaching map (0.1 m, its merge rules) for its
#: own model, the log-odds map (0.05 m) for the others (kiseki's ray model included)
TEACHING_MAP = "space-observation"
DISC_RADII = (0.2, 0.3)  # m: a person at hip height
BOX_HALF_SIDES = (0.15, 0.5)  # m: a small box to a cart
DRAWS_PER_OBSTACLE = 50
FREE_MAX = 19  # map cells 0..19 are free (the ROS map convention kiseki's readers use)


@dataclass(frozen=True)
class UnknownObstaclesConfig:
    data_dir: str = ""  # folder of the .log.gz files; "" = ../shared/data/carmen
    logs: list[str] = field(default_factory=lambda: list(CARMEN_LOGS))
    methods: Annotated[list[str], NonEmpty] = field(default_factory=lambda: list(METHODS))
    # obstacles per 10 m of route; the first is the reference without obstacles
    densities: list[NonNegativeReal] = field(default_factory=lambda: [0.0, 1.0, 2.0, 4.0])
    # the engine's default (none) and the recovery kiseki offers for real logs (resetting)
    recoveries: list[str] = field(default_factory=lambda: ["none", "resetting"])
    particles: Particles = 500
    odometry_noise: NonNegativeReal = 0.1
    clearance: PositiveReal = 0.5  # m from every laser pose (a robot's radius and a margin)
    band: PositiveReal = 3.0  # m: the farthest an obstacle is put from the route point drawn
    max_scans: Scans = 0  # 0 = whole logs
    threads: Threads = 1
    # the resets' agreement check and confirmation (false: the resets before them)
    reset_needs_agreement: bool = LocalizeConfig.reset_needs_agreement
    sensor_reset_confirm: bool = LocalizeConfig.sensor_reset_confirm
    # where a sensor reset's candidates come from: uniform or matcher. Uniform here, not
    # LocalizeConfig's matcher: the committed sweep was made with it (the matcher's sweep of the
    # resetting arms is beside it in the README) and has not been made again in whole
    sensor_reset_proposal: str = "uniform"
    # with the matcher: a search on every this-many-th sensor reset of a lost spell
    matcher_search_every: Count = LocalizeConfig.matcher_search_every
    # kiseki's ray model's resets judged by penetration only (LocalizeConfig's
    # intrusion_tolerant_resets) in its resetting arms; the other arms are run as they are
    intrusion_tolerant_resets: bool = LocalizeConfig.intrusion_tolerant_resets


def preflight(config: UnknownObstaclesConfig) -> None:
    bad = [m for m in config.methods if m not in METHODS]
    if bad or "likelihood-field" not in config.methods:
        raise ValueError(
            f"mcl-unknown-obstacles: methods must be among {', '.join(METHODS)} and include "
            f"likelihood-field (the claims' reference), got {config.methods}"
        )
    bad = [r for r in config.recoveries if r not in RECOVERY_MODES]
    if bad or not config.recoveries:
        raise ValueError(
            f"mcl-unknown-obstacles: recoveries must be among {', '.join(RECOVERY_MODES)}, "
            f"got {config.recoveries}"
        )
    d = config.densities
    if not d or d[0] != 0.0 or any(b <= a for a, b in zip(d, d[1:], strict=False)):
        raise ValueError(
            f"mcl-unknown-obstacles: densities must start at 0 (the reference) and rise, got {d}"
        )
    if config.band <= config.clearance:
        raise ValueError("mcl-unknown-obstacles: band must exceed clearance")
    ray_resets = "ray-space-observation" in config.methods and "resetting" in config.recoveries
    if config.intrusion_tolerant_resets and not ray_resets:
        raise ValueError(
            "mcl-unknown-obstacles: intrusion_tolerant_resets needs the ray-space-observation "
            "method and the resetting recovery among the arms"
        )
    folder = shared_data("carmen", config.data_dir)
    missing = [n for n in config.logs if not (folder / f"{n}.log.gz").is_file()]
    if missing:
        raise FileNotFoundError(f"mcl-unknown-obstacles: {folder}: missing {', '.join(missing)}")


def _on_free_cells(grid: OccupancyGrid, centre: np.ndarray, radius: float) -> bool:
    """Whether every map cell the circle's bounding square touches is known and free."""
    res, origin = grid.resolution, grid.origin
    lo = np.floor((centre - radius - (origin.x, origin.y)) / res).astype(int)
    hi = np.floor((centre + radius - (origin.x, origin.y)) / res).astype(int)
    if (lo < 0).any() or hi[0] >= grid.width or hi[1] >= grid.height:
        return False
    cells = grid.cells[lo[1] : hi[1] + 1, lo[0] : hi[0] + 1]
    return bool(((cells >= 0) & (cells <= FREE_MAX)).all())


def place_obstacles(
    poses: np.ndarray,
    grid: OccupancyGrid,
    per_10m: float,
    seed: int,
    clearance: float,
    band: float,
) -> UnknownObstacles:
    """Seeded unknown obstacles along a route (module docstring); fewer than wanted when the
    free space near the route has no room for them."""
    xy = np.asarray(poses, dtype=float)[:, :2]
    travel = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(xy, axis=0).T))])
    wanted = int(round(per_10m * travel[-1] / 10.0))
    rng = np.random.default_rng(seed)
    tree = cKDTree(xy)
    discs: list[tuple[float, float, float]] = []
    boxes: list[tuple[float, float, float, float, float]] = []
    for _ in range(wanted * DRAWS_PER_OBSTACLE):
        if len(discs) + len(boxes) >= wanted:
            break
        at = xy[min(int(np.searchsorted(travel, rng.uniform(0.0, travel[-1]))), len(xy) - 1)]
        bearing, distance = rng.uniform(-np.pi, np.pi), rng.uniform(clearance, band)
        centre = at + distance * np.array([np.cos(bearing), np.sin(bearing)])
        if rng.uniform() < 0.5:
            shape = ("disc", rng.uniform(*DISC_RADII))
            reach = shape[1]
        else:
            half = rng.uniform(*BOX_HALF_SIDES, 2)
            shape = ("box", *half, rng.uniform(-np.pi, np.pi))
            reach = float(np.hypot(*half))
        if tree.query(centre)[0] < clearance + reach or not _on_free_cells(grid, centre, reach):
            continue
        if shape[0] == "disc":
            discs.append((*centre, shape[1]))
        else:
            boxes.append((*centre, *shape[1:]))
    d = np.asarray(discs, dtype=float).reshape(-1, 3)
    b = np.asarray(boxes, dtype=float).reshape(-1, 5)
    return UnknownObstacles(d[:, :2], d[:, 2], b[:, :2], b[:, 2:4], b[:, 4])


def trial(config: UnknownObstaclesConfig, index: int, seed: int) -> TrialOutput:
    name = config.logs[index % len(config.logs)]
    path = shared_data("carmen", config.data_dir) / f"{name}.log.gz"
    scans = read_carmen_log(path).scans.first(config.max_scans)
    teaching = build_teaching_map(scans.poses, scans.ranges, scans.angles, scans.max_range, 0.1)
    log_odds = map_of_log(scans, MapBuildConfig(0.05))
    record: dict = {"log": name, "scans": len(scans)}
    timings: dict = {}
    for k, density in enumerate(config.densities):
        obstacles = place_obstacles(
            scans.poses,
            log_odds,
            density,
            derive_seed(seed, 100 + k),
            config.clearance,
            config.band,
        )
        seen, cut = occlude_scans(scans, obstacles)
        record[f"d{k}_obstacles"] = len(obstacles)
        record[f"d{k}_beams_cut"] = cut
        for method, recovery in _arms(config):
            lc = LocalizeConfig(
                method=method,
                seed=seed,
                odometry_noise=config.odometry_noise,
                particles=config.particles,
                recovery=recovery or "none",
                threads=config.threads,
                reset_needs_agreement=config.reset_needs_agreement,
                sensor_reset_confirm=config.sensor_reset_confirm,
                sensor_reset_proposal=config.sensor_reset_proposal,
                matcher_search_every=config.matcher_search_every,
                intrusion_tolerant_resets=config.intrusion_tolerant_resets
                and method == "ray-space-observation"
                and recovery == "resetting",
            )
            grid = teaching if method == TEACHING_MAP else log_odds
            result = localize(seen, grid, lc)
            errors = np.hypot(*(result.estimates - scans.poses)[:, :2].T)
            key = f"d{k}_{_arm(method, recovery)}"
            record[f"{key}_rmse_m"] = ape(result.estimates, scans.poses).rmse
            record[f"{key}_max_m"] = float(errors.max())
            record[f"{key}_resets"] = int(np.sum(result.resets != "none"))
            if method != "odometry":
                timings[f"{key}_ms"] = 1000.0 * float(np.mean(result.update_seconds))
    return TrialOutput(record, timings)


def _arms(config: UnknownObstaclesConfig) -> list[tuple[str, str]]:
    """(method, recovery) pairs run per density; the odometry once ("" recovery)."""
    return [
        (m, r) for m in config.methods for r in ([""] if m == "odometry" else config.recoveries)
    ]


def _arm(method: str, recovery: str) -> str:
    return f"{method}_{recovery}" if recovery else method


def _table(config: UnknownObstaclesConfig, ok: pd.DataFrame) -> pd.DataFrame:
    rows = []
    for log, group in ok.groupby("log", sort=False):
        for k, density in enumerate(config.densities):
            for method, recovery in _arms(config):
                key = f"d{k}_{_arm(method, recovery)}"
                rmse = group[f"{key}_rmse_m"]
                rows.append(
                    {
                        "log": log,
                        "obstacles_per_10m": density,
                        "obstacles": float(group[f"d{k}_obstacles"].mean()),
                        "beams_cut": float(group[f"d{k}_beams_cut"].mean()),
                        "method": method,
                        "recovery": recovery or "-",
                        "seeds": len(group),
                        "rmse_mean_m": float(rmse.mean()),
                        "rmse_max_m": float(rmse.max()),
                        "worst_error_m": float(group[f"{key}_max_m"].max()),
                        "resets": float(group[f"{key}_resets"].mean()),
                    }
                )
    return pd.DataFrame(rows)


def _plot(config: UnknownObstaclesConfig, table: pd.DataFrame, figures: Path) -> Path:
    logs = list(dict.fromkeys(table["log"]))
    rows = len(config.recoveries)
    fig = new_figure(figsize=(3.2 * len(logs), 3.0 * rows), dpi=120, layout="constrained")
    axes = fig.subplots(rows, len(logs), squeeze=False)
    for i, recovery in enumerate(config.recoveries):
        for j, log in enumerate(logs):
            ax = axes[i, j]
            part = table[(table["log"] == log) & table["recovery"].isin([recovery, "-"])]
            for method in config.methods:
                m = part[part["method"] == method]
                ax.plot(m["obstacles_per_10m"], m["rmse_mean_m"], marker="o", label=method)
            ax.set_yscale("log")
            ax.set_title(f"{log.replace('-corrected', '')}, recovery {recovery}", fontsize=8)
            ax.set_xlabel("unknown obstacles per 10 m of route", fontsize=7)
        axes[i, 0].set_ylabel("position RMSE (m), mean over seeds", fontsize=7)
    axes[0, 0].legend(fontsize=6)
    path = figures / "unknown_obstacles.png"
    fig.savefig(path, bbox_inches="tight")
    return path


def analyze(config: UnknownObstaclesConfig, trials, timings, figures: Path) -> Analysis:
    ok = trials[trials["error"].isna()].reset_index(drop=True)
    table = _table(config, ok)
    top = len(config.densities) - 1
    dense = f"{config.densities[top]:g} per 10 m"
    evidence = []
    for (log, group), recovery in itertools.product(
        ok.groupby("log", sort=False), config.recoveries
    ):
        lf0 = group[f"d0_likelihood-field_{recovery}_rmse_m"].to_numpy()
        lf = group[f"d{top}_likelihood-field_{recovery}_rmse_m"].to_numpy()
        subject = f"{log}, recovery {recovery}"
        evidence.append(
            Evidence.of(
                "field-doubles",
                lf / lf0,
                subject=subject,
                shown=f"{lf.mean():.3f} m at {dense} vs {lf0.mean():.3f} m without",
            )
        )
        if "ray-space-observation" in config.methods:
            ray = group[f"d{top}_ray-space-observation_{recovery}_rmse_m"].to_numpy()
            evidence.append(
                Evidence.of(
                    "ray-closer",
                    ray / lf,
                    subject=subject,
                    shown=f"{ray.mean():.3f} vs {lf.mean():.3f} m at {dense}",
                )
            )
        if "space-observation" in config.methods:
            so = group[f"d{top}_space-observation_{recovery}_rmse_m"].to_numpy()
            evidence.append(
                Evidence.of(
                    "thesis-closer",
                    so / lf,
                    subject=subject,
                    shown=f"{so.mean():.3f} vs {lf.mean():.3f} m at {dense}",
                )
            )
    cut = table.groupby("obstacles_per_10m")["beams_cut"].mean()
    notes = (
        f"{config.particles} particles, odometry noise {config.odometry_noise}; obstacles "
        f"{config.clearance:g}-{config.band:g} m from a route point, never nearer than "
        f"{config.clearance:g} m to a laser pose. Share of valid beams cut per density: "
        + ", ".join(f"{d:g}/10 m: {100 * c:.1f} %" for d, c in cut.items())
        + ". The maps are built from the logs without obstacles; resets = mean resets per run."
    )
    return Analysis(
        tables={"per_density": table},
        figures=[_plot(config, table, figures)],
        notes=notes,
        evidence=evidence,
    )


EXPERIMENT = Experiment(
    name="mcl-unknown-obstacles",
    paper="000_7c5a0f8de3fa28f5.txt (sec. 3.3, on real logs)",
    artefact="space observation model vs likelihood field and beam model with unknown obstacles",
    description="seeded unknown obstacles in the CARMEN logs at rising density: RMSE per model",
    config_type=UnknownObstaclesConfig,
    trial=trial,
    analyze=analyze,
    default_runs=5 * len(CARMEN_LOGS),
    preflight=preflight,
    claims=CLAIMS,
)
