# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""fig-3-14: the teaching-and-playback thesis' likelihood check (sec. 3.3.3, Fig. 3.14). A
robot stands beside a thin (0.1 m) partition on one side; a sideways depth sensor (59 deg field
of view, the Xtion) sees the partition and its end; the likelihood of particles displaced along
x is computed with the raw map cut-out (conventional) and with the occlusion-aware expected map
(proposal 1). The thesis: both peak at the truth, but the conventional likelihood stays maximal
on one side, while the proposal falls off on both.

Geometry (an assumption; the thesis gives only "a 0.1 m partition on one side"): the partition
runs along x at y = 1.0 m from x = -0.3 m (its end, inside the sensor's view) to x = 6 m; the
map is 0.1 m, the local map 8 m x 8 m at 0.1 m (the thesis' sizes); each trial adds Gaussian
range noise (0.01 m) to the scan.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from kiseki.core import Pose2, Random
from kiseki.grid import OccupancyGrid
from kiseki.models import LocalMapBuilder, SpaceObservationModel
from kiseki.plots import new_figure
from kiseki_experiments.harness.base import Analysis, Experiment, TrialOutput
from kiseki_experiments.harness.config import (
    ConfigError,
    Count,
    NonNegativeReal,
    PositiveReal,
    Real,
)
from kiseki_experiments.harness.verdict import ClaimSpec, Control, Criterion, Evidence

LOCAL_MAP_M = 8.0  # the thesis' local map size (8 m x 8 m at 0.1 m)


@dataclass(frozen=True)
class Fig314Config:
    partition_y: Real = 1.0  # m
    partition_start_x: Real = -0.3  # m, the partition's end seen by the sensor
    field_of_view_deg: PositiveReal = 59.0  # Xtion
    beams: Count = 60
    range_noise_sd: NonNegativeReal = 0.01  # m
    max_offset: NonNegativeReal = 1.0  # m, particles displaced along x up to this
    offsets: Count = 41
    # "no difference": off-truth likelihood >= this share of the peak
    flat_ratio: PositiveReal = 0.95
    # negative controls: the two models' expected maps (the thesis: conventional raw,
    # proposal 1 occlusion-aware)
    conventional_occlusion_aware: bool = False
    proposal_occlusion_aware: bool = True

    def __post_init__(self) -> None:
        """Refuses settings that make the check meaningless (beams=0 drew every likelihood at
        1.0 and a claim 'held'), naming the key."""
        finite = np.isfinite
        checks = (
            ("beams", self.beams >= 2, ">= 2"),
            ("offsets", self.offsets >= 3, ">= 3"),
            ("max_offset", finite(self.max_offset) and 0 < self.max_offset <= 3.5,
             "in (0, 3.5] m (the local map's half width)"),
            ("field_of_view_deg", 0 < self.field_of_view_deg < 180, "in (0, 180) deg"),
            ("range_noise_sd", finite(self.range_noise_sd) and 0 <= self.range_noise_sd < 1,
             "in [0, 1) m"),
            ("flat_ratio", 0 < self.flat_ratio <= 1, "in (0, 1]"),
            ("partition_y", finite(self.partition_y) and 0.2 <= self.partition_y <= 3.5,
             "in [0.2, 3.5] m"),
            ("partition_start_x", finite(self.partition_start_x)
             and -3.5 <= self.partition_start_x < 5.5, "in [-3.5, 5.5) m"),
        )  # fmt: skip
        for key, ok, limit in checks:
            if not ok:
                raise ConfigError(f"fig-3-14: {key} must be {limit}, got {getattr(self, key)}")


def _scene(config: Fig314Config) -> OccupancyGrid:
    grid = OccupancyGrid(np.zeros((80, 140), np.int8), 0.1, Pose2(-7.0, -4.0, 0.0))
    xs = np.arange(config.partition_start_x, 6.0, 0.05)
    cells = grid.world_to_cell(np.column_stack([xs, np.full_like(xs, config.partition_y + 0.05)]))
    grid.cells[cells[:, 1], cells[:, 0]] = 100
    return grid


def trial(config: Fig314Config, index: int, seed: int) -> TrialOutput:
    del index
    grid = _scene(config)
    half = np.radians(config.field_of_view_deg) / 2
    angles = np.linspace(-half, half, config.beams)
    ranges = grid.cast_scans(np.array([[0.0, 0.0, np.pi / 2]]), angles, max_range=10.0)[0]
    noise = Random(seed).normal(0.0, config.range_noise_sd, ranges.size)
    ranges = np.where(ranges < 10.0, ranges + noise, ranges).astype(np.float32)
    builder = LocalMapBuilder(LOCAL_MAP_M, 0.1)
    builder.add_scan(Pose2(0.0, 0.0, np.pi / 2), angles, ranges, 10.0)
    local = builder.build()
    offsets = np.linspace(-config.max_offset, config.max_offset, config.offsets)
    poses = np.column_stack([offsets, np.zeros_like(offsets), np.zeros_like(offsets)])
    record = {}
    arms = (
        ("raw", config.conventional_occlusion_aware),
        ("occlusion", config.proposal_occlusion_aware),
    )
    for name, occlusion in arms:
        model = SpaceObservationModel(grid, occlusion_aware=occlusion)
        model.set_local_map(local)
        lk = model.likelihoods(poses)
        record.update({f"{name}_{k}": float(v) for k, v in enumerate(lk / lk.max())})
    return TrialOutput(record)


def analyze(config, trials: pd.DataFrame, timings: pd.DataFrame, figures: Path) -> Analysis:
    ok = trials[trials["error"].isna()]
    offsets = np.linspace(-config.max_offset, config.max_offset, config.offsets)
    curves = {
        m: ok[[f"{m}_{k}" for k in range(config.offsets)]].to_numpy().mean(axis=0)
        for m in ("raw", "occlusion")
    }
    table = pd.DataFrame({"offset_m": offsets, **{f"{m}_likelihood": c for m, c in curves.items()}})
    centre = config.offsets // 2
    peak = {m: float(offsets[np.argmax(c)]) for m, c in curves.items()}
    flat_side = offsets <= -0.3  # beyond the partition's end
    raw_flat = float(curves["raw"][flat_side].min())
    occ_flat = float(curves["occlusion"][flat_side].min())
    # per trial: the lowest likelihood beyond the partition's end, each model (its own peak 1)
    flat = {
        m: ok[[f"{m}_{k}" for k in np.flatnonzero(flat_side)]].to_numpy().min(axis=1)
        for m in ("raw", "occlusion")
    }
    evidence = [
        Evidence.of("conventional_flat", flat["raw"], shown=f"mean curve min {raw_flat:.3f}"),
        Evidence.of(
            "proposal_drops",
            flat["raw"] - flat["occlusion"],
            shown=f"mean curves {raw_flat:.3f} vs {occ_flat:.3f}",
        ),
    ]
    checks = pd.DataFrame(
        [
            {
                "check (table row, no control can fail it)": "both models peak at the true "
                "position (thesis: x = 0)",
                "raw": peak["raw"],
                "occlusion": peak["occlusion"],
                "unit": "m",
            },
            {
                "check (table row, no control can fail it)": "both fall off on the other side "
                f"(thesis: falls off), likelihood / peak at +{config.max_offset:g} m",
                "raw": float(curves["raw"][-1]),
                "occlusion": float(curves["occlusion"][-1]),
                "unit": "ratio",
            },
        ]
    )
    del centre
    fig = new_figure(figsize=(6.5, 3.5), dpi=120)
    ax = fig.subplots()
    ax.plot(offsets, curves["raw"], "-o", markersize=3, label="conventional (raw map)")
    ax.plot(offsets, curves["occlusion"], "-s", markersize=3, label="proposal 1 (occlusion-aware)")
    ax.axvline(0.0, color="grey", linewidth=0.8)
    ax.set_xlabel("particle offset along x (m); 0 = true position")
    ax.set_ylabel("likelihood / maximum")
    ax.legend(fontsize=8)
    path = figures / "likelihood_vs_offset.png"
    fig.savefig(path, bbox_inches="tight")
    notes = (
        "Thesis Fig. 3.14 plots the same two curves (its exact geometry is not given). Here the "
        "flat side is where the displaced particle only adds intrusions (local-map occupied over "
        "map free, which the thesis makes cheap); the occlusion-aware map turns the map's free "
        "cells "
        "hidden behind the partition into expected-occupied ones, so displaced particles also "
        "mismatch at the shadow's edge. The effect is modest at this range because the shadow "
        f"edge covers few cells of the {LOCAL_MAP_M:g} m local map. Claims: per trial, the "
        "lowest likelihood beyond the partition's end (x <= -0.3 m) of each model; table "
        "`checks` holds what no control can fail (where the curves peak, the far side)."
    )
    return Analysis(
        tables={"likelihood": table, "checks": checks},
        figures=[path],
        notes=notes,
        evidence=evidence,
    )


CLAIMS = (
    ClaimSpec(
        key="conventional_flat",
        claim="conventional: no drop off the truth on one side (beyond the partition's end)",
        unit="lowest likelihood / peak for x <= -0.3 m",
        criterion=Criterion(
            paper_value="stays maximal",
            compare=">=",
            threshold=Fig314Config.flat_ratio,
            why="'no difference' read as within 5 % of the peak (the config's flat_ratio); the "
            "thesis shows the curve flat at its maximum",
            bounds=(0.0, 1.0),
        ),
        control=Control(
            name="the conventional model made occlusion-aware",
            overrides=("conventional_occlusion_aware=true",),
            runs=5,
            why="the occlusion-aware expected map is what makes the likelihood fall there",
        ),
        measure="the conventional likelihood's lowest value / its peak beyond the end",
    ),
    ClaimSpec(
        key="proposal_drops",
        claim="proposal 1 lowers the likelihood off the truth on that side: conventional's "
        "lowest value minus proposal 1's",
        unit="difference of likelihood / peak",
        criterion=Criterion(
            paper_value="falls off",
            compare=">=",
            threshold=0.02,
            why="2 % of the peak, a drop a plot like Fig. 3.14 shows; the thesis gives the "
            "curves only as a figure",
            bounds=(-1.0, 1.0),
        ),
        control=Control(
            name="proposal 1's expected map not occlusion-aware",
            overrides=("proposal_occlusion_aware=false",),
            runs=5,
            why="both arms are then the conventional model: the difference is 0",
        ),
        measure="per trial, min over x <= -0.3 m of the conventional likelihood minus "
        "proposal 1's (each normalised to its peak)",
    ),
)


EXPERIMENT = Experiment(
    name="fig-3-14",
    paper="000_7c5a0f8de3fa28f5.txt",
    artefact="Fig. 3.14",
    description="likelihood vs x offset beside a 0.1 m partition, raw vs occlusion-aware map",
    config_type=Fig314Config,
    trial=trial,
    analyze=analyze,
    default_runs=10,
    claims=CLAIMS,
)
