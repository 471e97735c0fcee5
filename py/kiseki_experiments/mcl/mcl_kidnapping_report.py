# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""mcl-kidnapping's analysis (kiseki_experiments.mcl.mcl_kidnapping): the recovery table, the
reliability estimate's ROC areas per source, the error and reliability figure, the ROC figure,
and the claims' evidence, every number from the trials' records."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from kiseki.metrics import area_under_roc
from kiseki.plots import new_figure
from kiseki_experiments.harness.base import Analysis
from kiseki_experiments.harness.verdict import Evidence
from kiseki_experiments.mcl.mcl_kidnapping_config import KidnapConfig

__all__ = ["analyze"]


def analyze(config: KidnapConfig, trials: pd.DataFrame, timings: pd.DataFrame, figures: Path):
    ok = trials[trials["error"].isna()]
    rows = []
    for r in config.recoveries:
        rec = ok[f"{r}_recovered"].astype(bool)
        scans_to = ok.loc[rec, f"{r}_recovery_scans"]
        rows.append(
            {
                "recovery": r,
                "trials": len(ok),
                "tracked_before": float(ok[f"{r}_tracked_before"].mean()),
                "recovered": float(rec.mean()),
                "median_recovery_scans": float(scans_to.median()) if len(scans_to) else None,
                "max_recovery_scans": float(scans_to.max()) if len(scans_to) else None,
                "reliability_before": float(ok[f"{r}_reliability_before"].mean()),
                "reliability_after": float(ok[f"{r}_reliability_after"].mean()),
                "agreement_reliability_after": float(ok[f"{r}_agreement_reliability_after"].mean()),
                **_reliability_shares(ok, r),
                "ms_per_update": float(timings[f"{r}_ms_per_update"].median()),
            }
        )
    table = pd.DataFrame(rows)
    tables = {"recovery": table}
    if "none" in config.recoveries:
        tables["reliability_auc"] = _auc_table(ok)
    by = table.set_index("recovery")
    evidence = []
    if "resetting" in by.index:
        rec = ok["resetting_recovered"].astype(bool)
        scans_to = by.loc["resetting", "median_recovery_scans"]
        evidence.append(
            Evidence.share(
                "recovers",
                int(rec.sum()),
                len(rec),
                shown=f"{int(rec.sum())} of {len(rec)}; median {scans_to} scans to recover",
            )
        )
    if "none" in by.index:
        before = by.loc["none", "reliability_before"]
        evidence.append(
            Evidence.of(
                "falls",
                ok["none_reliability_after"],
                shown=f"mean 10 updates after the jump; {before:.2f} before it",
            )
        )
        evidence += _reliability_evidence(ok)
    fig = new_figure(figsize=(10, 3.6), dpi=120)
    axes = fig.subplots(1, 2)
    colours = ("tab:red", "tab:orange", "tab:blue", "tab:green")
    for r, colour in zip(config.recoveries, colours, strict=False):
        errors = [np.asarray(e) for e in ok[f"{r}_errors"]]
        rel = [np.asarray(e) for e in ok[f"{r}_reliability"]]
        if not errors:
            continue
        length = min(len(e) for e in errors)
        t = np.arange(length) - 20
        axes[0].plot(t, np.median([e[:length] for e in errors], axis=0), color=colour, label=r)
        axes[1].plot(t, np.mean([e[:length] for e in rel], axis=0), color=colour, label=r)
    axes[0].set_yscale("log")
    axes[0].set_ylabel("median position error (m)")
    axes[1].set_ylabel("mean reliability estimate")
    for ax in axes:
        ax.axvline(0, color="k", lw=0.8, ls=":")
        ax.set_xlabel("updates after the kidnapping")
        ax.legend(fontsize=7)
    path = figures / "kidnapping.png"
    fig.savefig(path, bbox_inches="tight")
    notes = (
        f"{len(ok)} trials; {config.method}, {config.particles} particles, {config.beams} beams; "
        f"the robot is carried at least {config.min_jump} m; recovered = back within "
        f"{config.recover_distance} m and {config.recover_heading} deg for "
        f"{config.recover_hold} updates. Reliability reported: {config.reliability} "
        "(kiseki.filters.reliability); beside it the engine's estimate (the recent share of "
        "updates whose scan agrees with the map seen from the particles)."
    )
    paths = [path]
    if "none" in config.recoveries and len(ok):
        paths.append(_roc_figure(ok, figures / "reliability_roc.png", config.reliability))
    return Analysis(tables=tables, figures=paths, notes=notes, evidence=evidence)


def _reliability_shares(ok: pd.DataFrame, arm: str) -> dict:
    """The reliability claims' shares for one arm, the reported estimate's and the engine's."""
    lost = ok[f"{arm}_lost_after"].astype(bool)
    updates = ok[f"{arm}_tracking_updates"].sum()
    out: dict = {"trials_lost": int(lost.sum())}
    for name in ("", "agreement_"):
        low = ok.loc[lost, f"{arm}_{name}low_within_10"].astype(bool)
        out[f"{name}low_within_10"] = float(low.mean()) if len(low) else None
        high = ok[f"{arm}_{name}tracking_high"].sum()
        out[f"{name}high_when_tracking"] = float(high / updates) if updates else None
    return out


def _lost_and_scores(group: pd.DataFrame):
    """The none arm's recorded updates (from 20 before the jump on) of some trials: whether
    each is more than 1 m off, and 1 - reliability of each estimate (learned, engine's)."""
    errors = np.concatenate([np.asarray(e) for e in group["none_errors"]])
    scores = {
        name: 1.0 - np.concatenate([np.asarray(r) for r in group[f"none_{name}reliability"]])
        for name in ("", "agreement_")
    }
    return errors > 1.0, scores


def _auc_table(ok: pd.DataFrame) -> pd.DataFrame:
    """Per source (simulation or log), the area under the ROC curve of 1 - reliability for
    "error above 1 m"."""
    rows = []
    for source, group in ok.groupby("source", sort=True):
        lost, scores = _lost_and_scores(group)
        row = {"source": source, "updates": len(lost), "share_lost": float(lost.mean())}
        row |= {f"{name}auc": area_under_roc(score, lost) for name, score in scores.items()}
        rows.append(row)
    return pd.DataFrame(rows)


def _roc_figure(ok: pd.DataFrame, path: Path, reported: str) -> Path:
    """ROC curves of both estimates (the reported one, named ``reported``, and the engine's)
    for "error above 1 m", one panel per source."""
    groups = list(ok.groupby("source", sort=True))
    fig = new_figure(figsize=(3.2 * len(groups), 3.2), dpi=120)
    axes = np.atleast_1d(fig.subplots(1, len(groups)))
    for ax, (source, group) in zip(axes, groups, strict=True):
        lost, scores = _lost_and_scores(group)
        for (name, score), colour in zip(scores.items(), ("tab:blue", "tab:grey"), strict=True):
            order = np.argsort(-score, kind="stable")
            hit = np.concatenate([[0.0], np.cumsum(lost[order]) / max(lost.sum(), 1)])
            false = np.concatenate([[0.0], np.cumsum(~lost[order]) / max((~lost).sum(), 1)])
            label = f"{'engine' if name else reported} {area_under_roc(score, lost):.3f}"
            ax.plot(false, hit, color=colour, label=label)
        ax.plot([0, 1], [0, 1], color="k", lw=0.6, ls=":")
        ax.set_title(source, fontsize=8)
        ax.set_xlabel("false alarms (share within 1 m)")
        ax.legend(fontsize=7, loc="lower right")
    fig.axes[0].set_ylabel("lost updates caught (> 1 m)")
    fig.savefig(path, bbox_inches="tight")
    return path


def _reliability_evidence(ok: pd.DataFrame) -> list[Evidence]:
    lost = ok["none_lost_after"].astype(bool)
    low = ok.loc[lost, "none_low_within_10"].astype(bool)
    old = ok.loc[lost, "none_agreement_low_within_10"].astype(bool)
    high, updates = int(ok["none_tracking_high"].sum()), int(ok["none_tracking_updates"].sum())
    old_high = int(ok["none_agreement_tracking_high"].sum())
    return [
        Evidence.share(
            "low_when_lost",
            int(low.sum()),
            len(low),
            shown=f"{int(low.sum())} of {len(low)} (the engine's estimate: {int(old.sum())})",
        ),
        Evidence.share(
            "high_when_tracking",
            high,
            updates,
            shown=f"{high} of {updates} updates (the engine's estimate: {old_high})",
        ),
    ]
