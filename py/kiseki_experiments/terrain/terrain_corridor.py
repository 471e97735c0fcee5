# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""terrain-corridor: paper 003's sec. 3 problem case: in a narrow place with flat walls left and
right, matching every range (no plane removal) gave large errors along the direction of travel,
because the walls' uniform ranges outnumber the floor's irregularities. One level move of 35 cm
along data/worlds/terrain_corridor.yaml (end walls beyond the laser's 5 m, six low objects on the
floor), searched after each removal (none, Hough, PCL) with eq. 4 as printed (a sum) and kiseki's
mean cost beside it; the along-track error is measured. Same pipeline as terrain-env-a
(kiseki_experiments.terrain.terrain_envs, terrain_common).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from kiseki_experiments.harness.base import Analysis, Evidence, Experiment
from kiseki_experiments.harness.config import Real
from kiseki_experiments.harness.paths import WORLDS
from kiseki_experiments.terrain.terrain_claims import CLAIMS_CORRIDOR, LARGE
from kiseki_experiments.terrain.terrain_envs import (
    COST_NAMES,
    EnvAConfig,
    arms,
    preflight,
    search_move,
    trial,
)
from kiseki_experiments.terrain.terrain_figures import draw_match
from kiseki_experiments.terrain.terrain_stats import share_interval

__all__ = ["CORRIDOR", "CorridorConfig"]


@dataclass(frozen=True)
class CorridorConfig(EnvAConfig):
    scene: str = str(WORLDS / "terrain_corridor.yaml")
    move_m: list[Real] = field(default_factory=lambda: [0.35, 0.0, 0.0])
    attitude_deg: list[Real] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    removals: list[str] = field(default_factory=lambda: ["none", "hough", "pcl"])
    exact_gyro_rows: bool = True


def analyze(config: CorridorConfig, trials, timings, figures: Path) -> Analysis:
    ok = trials[trials["error"].isna()]
    if ok.empty:
        return Analysis(notes="every trial failed: nothing to analyse")
    rows = []
    for tag, exact, cost in arms(config):
        for m in config.removals:
            along = ok[f"{tag}{m}_along"].abs()
            share, lo, hi = share_interval(along.to_numpy() > LARGE)
            rows.append(
                {
                    "removal": m,
                    "cost": COST_NAMES.get(cost, cost),
                    "gyro": "exact" if exact else "with error",
                    "along_mean_cm": 100 * along.mean(),
                    "along_max_cm": 100 * along.max(),
                    "large_share": share,
                    "large_low": lo,
                    "large_high": hi,
                    "error_mean_cm": 100 * ok[f"{tag}{m}_error"].mean(),
                    "x_cm": 100 * ok[f"{tag}{m}_x"].mean(),
                    "kept_share": ok[f"{tag}{m}_kept"].mean(),
                    "cost_rise_along_10cm": ok[f"{tag}{m}_rise_along"].mean(),
                    "cost_rise_across_10cm": ok[f"{tag}{m}_rise_across"].mean(),
                }
            )
    table = pd.DataFrame(rows)
    evidence = []
    if "none" in config.removals:
        for tag, exact, cost in arms(config):
            if not exact:
                along = ok[f"{tag}none_along"].abs().to_numpy()
                evidence.append(
                    Evidence.share(
                        "none_large", int((along > LARGE).sum()), len(along),
                        subject=COST_NAMES.get(cost, cost),
                        shown=f"mean |along| {100 * along.mean():.1f} cm",
                    )
                )  # fmt: skip
    by = table[(table["gyro"] == "with error") & (table["cost"] == COST_NAMES[config.cost])]
    by = by.set_index("removal")
    seed0 = int(ok.sort_values("trial")["seed"].iloc[0])
    maps, _, found = search_move(config, seed0, False)
    path = figures / "terrain_corridor.png"
    draw_match(path, maps, found, config.step, "corridor, first trial")
    notes = (
        "The corridor's geometry is kiseki's (data/worlds/terrain_corridor.yaml); the paper "
        "states the effect without numbers. The move is level, 35 cm along the corridor (x); "
        f"the search grid is the paper's (x 0..70 cm, step {config.step:g} m). Gyro error as in "
        "terrain-env-a; the 'exact' rows have none."
    )
    if "none" in by.index and "cost_rise_along_10cm" in by:
        rises = "; ".join(
            f"{m}: {100 * by.loc[m, 'cost_rise_along_10cm']:.0f} % along, "
            f"{100 * by.loc[m, 'cost_rise_across_10cm']:.0f} % across"
            for m in by.index
        )
        notes += (
            " The cost 10 cm from its minimum, above the minimum (mean of seeds, gyro with "
            f"error): {rises}. Without removal the surface is a valley along the corridor: the "
            "walls' and floor's ranges hardly change with x, so the along-track position rests "
            "on the few object cells. Eq. 4 as printed is a sum (the default, cost=sum): a "
            "candidate sharing fewer cells costs less, and along the valley the candidates "
            "further along the corridor share fewer, so the sum's minimum moves along it. "
            f"'{COST_NAMES['mean']}' is kiseki's variant, the sum over the summed weights, run "
            "on the same sweeps: it removes that reward, and its valley's floor keeps its "
            "minimum near the truth, since kiseki's simulated ranges have only white noise (5 "
            "mm) and flat surfaces exactly flat (a real laser's systematic range errors on large "
            "flat surfaces, incidence angle and mixed pixels, are not simulated)."
        )
    return Analysis({"along_track": table}, [path], notes=notes, evidence=evidence)


CORRIDOR = Experiment(
    name="terrain-corridor",
    paper="003_fd335d240f62896b.txt",
    artefact="sec. 3 (flat walls left and right)",
    description="a 35 cm move along a narrow flat-walled corridor: along-track error per removal",
    config_type=CorridorConfig,
    trial=trial,
    analyze=analyze,
    # 100: at 10 the share of seeds with a large along-track error (0.4) was undecided; the
    # report asked 98 trials (issue 29: the default trials decide at least 80 % of the claims)
    default_runs=100,
    preflight=preflight,
    claims=CLAIMS_CORRIDOR,
)
