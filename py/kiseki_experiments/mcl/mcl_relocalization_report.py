# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The analysis of mcl-relocalization: the per-log table, the evidence of its claims and the
figure of every scan's best error against its identifiability margin, from the trials' records
(:mod:`kiseki_experiments.mcl.mcl_relocalization`)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from kiseki.plots import new_figure
from kiseki_experiments.harness.base import Analysis
from kiseki_experiments.harness.records import unpack
from kiseki_experiments.harness.verdict import Evidence

__all__ = ["analyze"]


def analyze(config, trials: pd.DataFrame, timings: pd.DataFrame, figures: Path):
    """Per log: the shares of the table and the evidence of each claim (``config`` is the run's
    RelocalizationConfig)."""
    ok = trials[trials["error"].isna()].merge(timings, on="trial")
    rows, evidence = [], []
    for log, group in ok.groupby("log", sort=False):
        n, ident = int(group["scans"].sum()), int(group["identifiable"].sum())
        hits = int(group["best_hit_identifiable"].sum())
        rows.append(
            {
                "log": log,
                "scans": n,
                "identifiable_share": ident / n,
                "identifiable_by_truth_score_share": group["identifiable_by_truth_score"].sum() / n,
                "best_hit_of_identifiable": f"{hits}/{ident}",
                "best_hit_share_all": group["best_hit"].sum() / n,
                "top_hit_share_all": group["top_hit"].sum() / n,
                "median_s_per_scan": group["median_s"].median(),
                "p90_s_per_scan": group["p90_s"].max(),
                "max_s_per_scan": group["max_s"].max(),
            }
        )
        evidence.append(
            Evidence.share(
                "best-of-identifiable",
                hits,
                ident,
                subject=log,
                shown=f"{hits} of {ident} identifiable ({ident} of {n} scans)",
            )
        )
    table = pd.DataFrame(rows)
    total, top = int(ok["scans"].sum()), int(ok["top_hit"].sum())
    evidence.append(
        Evidence.share(
            "top-5-of-all",
            top,
            total,
            subject="all logs",
            shown=f"{top} of {total} scans",
        )
    )
    path = _figure(config, ok, figures / "relocalization.png")
    notes = (
        f"{config.scans} scans per trial spread over each log; map at {config.resolution} m; "
        f"a hit is within {config.hit_distance} m and {config.hit_angle_deg} deg of the "
        f"reference pose; identifiable: no lattice pose more than {config.near_radius} m from "
        f"it scores within {100 * config.score_tolerance:g} % (of the magnitude) of the best "
        f"lattice pose within {config.near_radius} m; times are the top-{config.top} search on "
        f"{config.threads} threads"
        + (f"; beam angles turned by {config.scan_turn_deg} deg" if config.scan_turn_deg else "")
    )
    return Analysis(tables={"per_log": table}, figures=[path], notes=notes, evidence=evidence)


def _figure(config, ok: pd.DataFrame, path: Path) -> Path:
    """The best hypothesis' position error against the identifiability margin (near - far) /
    |near| of every scan: scans right of the tolerance line are identifiable."""
    fig = new_figure(figsize=(7, 4), dpi=120)
    ax = fig.subplots()
    for log, group in ok.groupby("log", sort=False):
        near = np.concatenate([unpack(t) for t in group["near"]])
        far = np.concatenate([unpack(t) for t in group["far"]])
        error = np.concatenate([unpack(t) for t in group["error_m"]])
        margin = np.where(np.isfinite(near), (near - far) / np.maximum(np.abs(near), 1e-9), -1.0)
        label = str(log).replace("-corrected", "")
        ax.scatter(np.clip(margin, -0.5, 1.5), np.maximum(error, 1e-3), s=6, label=label)
    ax.axvline(config.score_tolerance, color="k", linewidth=0.8, linestyle="--")
    ax.axhline(config.hit_distance, color="tab:red", linewidth=0.8, linestyle=":")
    ax.set_yscale("log")
    ax.set_xlabel(
        "(near - far) / |near|  (clipped to [-0.5, 1.5]; right of the dashed line: identifiable)"
    )
    ax.set_ylabel("best hypothesis' position error (m)")
    ax.legend(fontsize=7)
    fig.savefig(path, bbox_inches="tight")
    return path
