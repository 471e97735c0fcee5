# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""merge-rules: the thesis' environment-map merge rule against evidence counting, on real logs.

For each CARMEN log with SLAM-corrected poses, build the teaching map (thesis sec. 3.4: each
scan's local map placed at its pose, no-return beams left out) once with the thesis' rule
(L free over M occupied -> free, forever) and once with evidence counting (a cell turns free
only when its free observations outweigh its hits; `kiseki.teach.environment_map`), at 0.1 m,
and measure
- the share of scan endpoints on or next to an occupied cell (how much of what the scans hit
  the map still holds; the log-odds map of `kiseki.mapping.build_map` at the same resolution
  is the reference);
- the space observation model's tracking error along the log on that map (position and
  heading RMSE against the corrected poses, odometry noise 0.1, the filter's motion noise
  matched to it: `kiseki.filters`).
Trial i is log i, both rules (the maps are deterministic; the trial's seed drives the odometry
noise and the filter, the same for both rules).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from kiseki.datasets import read_carmen_log
from kiseki.filters import LocalizeConfig, localize
from kiseki.mapping import MapBuildConfig, build_map, endpoint_agreement
from kiseki.metrics import ape
from kiseki.plots import new_figure
from kiseki.teach.environment_map import MERGE_RULES, build_teaching_map
from kiseki_experiments.harness.base import Analysis, Experiment, TrialOutput
from kiseki_experiments.harness.config import NonNegativeReal, Particles, Resolution, Scans
from kiseki_experiments.harness.paths import CARMEN_LOGS, shared_data
from kiseki_experiments.harness.verdict import ClaimSpec, Control, Criterion, Evidence


@dataclass(frozen=True)
class MergeRulesConfig:
    data_dir: str = ""  # folder of the .log.gz files; "" = ../shared/data/carmen
    logs: list[str] = field(default_factory=lambda: list(CARMEN_LOGS))
    resolution: Resolution = 0.1  # m: the thesis' local map cells
    odometry_noise: NonNegativeReal = 0.1  # of each odometry increment (as in the README's runs)
    particles: Particles = 500
    max_scans: Scans = 0  # 0 = the whole log; otherwise its first max_scans scans
    # negative control: the rule the evidence-counting arm is built with ("thesis": both arms
    # are the thesis' map)
    evidence_arm_rule: str = "evidence"


BLOCKS = (
    10  # the log cut into this many runs of consecutive scans: the claim's interval is over them
)


def _folder(config: MergeRulesConfig) -> Path:
    return shared_data("carmen", config.data_dir)


def preflight(config: MergeRulesConfig) -> None:
    if not config.logs:
        raise ValueError("merge-rules: logs is empty")
    if not (config.resolution > 0 and np.isfinite(config.resolution)):
        raise ValueError(f"merge-rules: resolution must be positive, got {config.resolution}")
    if config.evidence_arm_rule not in MERGE_RULES:
        raise ValueError(
            f"merge-rules: evidence_arm_rule must be one of {', '.join(MERGE_RULES)}, "
            f"got {config.evidence_arm_rule!r}"
        )
    if config.max_scans < 0:
        raise ValueError(f"merge-rules: max_scans must be >= 0, got {config.max_scans}")
    folder = _folder(config)
    missing = [n for n in config.logs if not (folder / f"{n}.log.gz").is_file()]
    if missing:
        raise FileNotFoundError(f"merge-rules: {folder}: missing {', '.join(missing)}.log.gz")


def trial(config: MergeRulesConfig, index: int, seed: int) -> TrialOutput:
    """Trial i: log i (modulo the number of logs), both rules, on the same odometry noise and
    filter seed."""
    name = config.logs[index % len(config.logs)]
    scans = read_carmen_log(_folder(config) / f"{name}.log.gz").scans.first(config.max_scans)
    reference = build_map(
        scans.poses,
        scans.ranges,
        scans.angles,
        scans.max_range,
        MapBuildConfig(resolution=config.resolution),
    )
    record = {
        "log": name,
        "scans": len(scans),
        "log_odds_endpoint_share": endpoint_agreement(
            reference, scans.poses, scans.ranges, scans.angles, scans.max_range
        ),
    }
    timings = {}
    localize_config = LocalizeConfig(
        method="space-observation",
        seed=seed,
        odometry_noise=config.odometry_noise,
        particles=config.particles,
    )
    blocks = np.array_split(np.arange(len(scans)), BLOCKS)
    for rule in MERGE_RULES:
        built = config.evidence_arm_rule if rule == "evidence" else rule  # control: thesis
        start = time.perf_counter()
        grid = build_teaching_map(
            scans.poses, scans.ranges, scans.angles, scans.max_range, config.resolution, rule=built
        )
        timings[f"{rule}_build_seconds"] = time.perf_counter() - start
        start = time.perf_counter()
        estimate = localize(scans, grid, localize_config).estimates
        timings[f"{rule}_track_seconds"] = time.perf_counter() - start
        cells = np.asarray(grid.cells)
        record |= {
            f"{rule}_endpoint_share": endpoint_agreement(
                grid, scans.poses, scans.ranges, scans.angles, scans.max_range
            ),
            f"{rule}_position_rmse_m": ape(estimate, scans.poses).rmse,
            f"{rule}_heading_rmse_deg": ape(estimate, scans.poses, "rotation_deg").rmse,
            f"{rule}_occupied_cells": int((cells == 100).sum()),
            f"{rule}_free_cells": int((cells == 0).sum()),
        }
        for b, idx in enumerate(blocks):  # the same whole map, the block's scans
            record[f"{rule}_endpoint_share_block{b}"] = endpoint_agreement(
                grid, scans.poses[idx], scans.ranges[idx], scans.angles, scans.max_range
            )
    return TrialOutput(record, timings)


def analyze(config, trials: pd.DataFrame, timings: pd.DataFrame, figures: Path) -> Analysis:
    ok = trials[trials["error"].isna()].merge(timings, on="trial")
    columns = {
        "scans": ("scans", "first"),
        "endpoints_log_odds": ("log_odds_endpoint_share", "mean"),
    }
    for rule in MERGE_RULES:
        columns |= {
            f"endpoints_{rule}": (f"{rule}_endpoint_share", "mean"),
            f"position_rmse_{rule}_m": (f"{rule}_position_rmse_m", "mean"),
            f"heading_rmse_{rule}_deg": (f"{rule}_heading_rmse_deg", "mean"),
            f"track_ms_per_scan_{rule}": (f"{rule}_track_seconds", "median"),
        }
    table = ok.groupby("log", sort=False).agg(**columns).reset_index()
    for rule in MERGE_RULES:
        table[f"track_ms_per_scan_{rule}"] *= 1000.0 / table["scans"]
    evidence = []
    for log, g in ok.groupby("log", sort=False):
        first = g.iloc[0]  # the maps are deterministic: every trial of a log has the same blocks
        blocks = [
            first[f"evidence_endpoint_share_block{b}"] - first[f"thesis_endpoint_share_block{b}"]
            for b in range(BLOCKS)
            if f"thesis_endpoint_share_block{b}" in first
        ]
        shown = (
            f"whole log {first['evidence_endpoint_share']:.3f} vs "
            f"{first['thesis_endpoint_share']:.3f}"
        )
        evidence.append(Evidence.of("keeps_hits", blocks, shown=shown, subject=log))
    fig = new_figure(figsize=(10, 3.5), dpi=120)
    axes = fig.subplots(1, 2)
    x = np.arange(len(table))
    for k, (rule, colour) in enumerate((("thesis", "tab:orange"), ("evidence", "tab:blue"))):
        axes[0].bar(x + 0.3 * (k - 0.5), table[f"endpoints_{rule}"], 0.3, color=colour, label=rule)
        axes[1].bar(
            x + 0.3 * (k - 0.5), table[f"position_rmse_{rule}_m"], 0.3, color=colour, label=rule
        )
    axes[0].plot(x, table["endpoints_log_odds"], "k_", ms=20, label="log-odds map")
    axes[0].set_ylabel("endpoints on/next to occupied")
    axes[0].set_ylim(0.5, 1.0)
    axes[1].set_ylabel("space observation position RMSE (m)")
    for ax in axes:
        ax.set_xticks(x, [n.replace("-corrected", "") for n in table["log"]])
        ax.legend(fontsize=7)
    path = figures / "merge_rules.png"
    fig.savefig(path, bbox_inches="tight")
    notes = (
        f"Teaching maps at {config.resolution} m from the corrected poses; endpoints count "
        "when they land on an occupied cell or one of its 8 neighbours. Tracking: the space "
        f"observation model, {config.particles} particles, odometry noise "
        f"{config.odometry_noise}, RMSE against the corrected poses over the whole log. The "
        "thesis' rule frees a wall cell for good once any beam crosses it (a beam through a "
        "door gap, a grazing beam along a wall, a person who walked away); evidence counting "
        "keeps it while the hits outnumber the free observations, and still frees what "
        "moved away once it has been seen free more often than hit."
    )
    return Analysis(tables={"per_log": table}, figures=[path], notes=notes, evidence=evidence)


CLAIMS = (
    ClaimSpec(
        key="keeps_hits",
        claim="evidence counting keeps more of what the scans hit: the share of endpoints on or "
        "next to an occupied cell, evidence counting minus the thesis' rule (beyond the thesis)",
        unit="difference of shares of endpoints",
        criterion=Criterion(
            paper_value="(beyond the thesis)",
            compare=">=",
            threshold=0.01,
            why="one endpoint in a hundred more on the map; per block of consecutive scans, "
            f"{BLOCKS} blocks per log, against the whole log's maps",
            bounds=(-1.0, 1.0),
        ),
        control=Control(
            name="the evidence arm built with the thesis' rule",
            overrides=("evidence_arm_rule=thesis", "logs=intel-corrected", "max_scans=200"),
            runs=1,
            why="both arms are then the thesis' map: every block's difference is 0",
        ),
        measure="per block of scans: the evidence map's endpoint share minus the thesis map's",
    ),
)


EXPERIMENT = Experiment(
    name="merge-rules",
    paper="000_7c5a0f8de3fa28f5.txt (beyond the thesis)",
    artefact="sec. 3.4 merge rules on real logs",
    description="thesis' merge rule vs evidence counting: endpoint agreement, tracking RMSE",
    config_type=MergeRulesConfig,
    trial=trial,
    analyze=analyze,
    default_runs=len(CARMEN_LOGS),
    preflight=preflight,
    claims=CLAIMS,
)
