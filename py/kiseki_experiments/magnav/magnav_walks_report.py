# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The analysis of magnetic-walks: the per-walk table of RMSEs (mean and range over seeds), the
evidence of the claims (per-seed ratios) and a figure of the per-seed RMSEs
(:mod:`kiseki_experiments.magnav.magnav_walks`)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from kiseki.plots import new_figure
from kiseki_experiments.harness.base import Analysis
from kiseki_experiments.harness.verdict import Evidence

__all__ = ["analyze"]

COLUMNS = ("thesis", "kiseki", "kiseki_global", "dr", "dr_lap")
LABELS = {
    "thesis": "thesis' filter (laps restarted)",
    "kiseki": "kiseki loop filter",
    "kiseki_global": "kiseki, unknown start",
    "dr": "dead reckoning",
    "dr_lap": "dead reckoning, laps restarted (the thesis' filter's own)",
}


def analyze(config, trials: pd.DataFrame, timings: pd.DataFrame, figures: Path) -> Analysis:
    ok = trials[trials["error"].isna()]
    rows, evidence = [], []
    for walk, group in ok.groupby("walk", sort=False):
        row: dict = {"walk": walk, "seeds": len(group), "loop_m": float(group["loop_m"].iloc[0])}
        for c in (*COLUMNS, "kiseki_e0", "kiseki_e10"):
            v = group[c].to_numpy(float)
            row[f"{c}_rmse_m"] = f"{v.mean():.3f} ({v.min():.3f}-{v.max():.3f})"
        rows.append(row)
        ratio = {
            "half-of-dead-reckoning": group["kiseki"] / group["dr"],
            "half-of-lap-dead-reckoning": group["kiseki"] / group["dr_lap"],
            "scale-error": group["kiseki_e10"] / group["kiseki_e0"],
        }
        for key, values in ratio.items():
            v = values.to_numpy(float)
            evidence.append(
                Evidence.of(
                    key,
                    v,
                    subject=str(walk),
                    shown="per seed " + ", ".join(f"{x:.2f}" for x in v),
                )
            )
    table = pd.DataFrame(rows)
    path = _figure(ok, figures / "walks.png")
    notes = (
        "RMSE of the travel distance around the loop (m), mean (min-max) over seeds; odometry "
        "(1 + e) |dp| + N(0, (0.1 |dp|)^2), e ~ N(0, 0.05^2) per walk; kiseki_e0 / kiseki_e10: "
        f"e fixed at 0 and {config.scale_error}; the loop filter is never given the lap "
        "boundaries; the thesis' filter and the 'laps restarted' dead reckoning are given "
        "the reference's lap boundaries"
        + ("" if config.use_field else "; the loop filter ran WITHOUT its readings (control)")
    )
    return Analysis(tables={"per_walk": table}, figures=[path], notes=notes, evidence=evidence)


def _figure(ok: pd.DataFrame, path: Path) -> Path:
    """Per walk, each method's RMSE per seed (dots) and mean (bar)."""
    walks = list(dict.fromkeys(ok["walk"]))
    fig = new_figure(figsize=(8, 3.2 * max(1, len(walks))), dpi=110)
    axes = np.atleast_1d(fig.subplots(len(walks), 1))
    for ax, walk in zip(axes, walks, strict=True):
        group = ok[ok["walk"] == walk]
        for i, c in enumerate(COLUMNS):
            v = group[c].to_numpy(float)
            ax.bar(i, v.mean(), color="tab:blue" if c.startswith("kiseki") else "0.7")
            ax.plot(np.full(len(v), i), v, "k.", markersize=4)
        ax.set_xticks(range(len(COLUMNS)), [LABELS[c] for c in COLUMNS], fontsize=7, rotation=15)
        ax.set_ylabel("RMSE along the loop (m)")
        ax.set_title(f"{walk}: {len(group)} seeds", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, bbox_inches="tight")
    return path
