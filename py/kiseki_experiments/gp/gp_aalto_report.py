# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The analysis of gp-aalto: tables, evidence and notes from the tasks' payloads (the claims are
declared in :mod:`kiseki_experiments.gp.gp_aalto_folds`, the held-out map's, and
:mod:`kiseki_experiments.gp.gp_aalto_claims`, the MCL's; the pictures drawn by
:mod:`kiseki_experiments.gp.gp_aalto_figures`). Change detection is a table, not a claim: one
verdict per recorded run, on four changed runs and one static one, which no interval can
decide."""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd

from kiseki_experiments.gp.gp_aalto_claims import mcl_evidence
from kiseki_experiments.gp.gp_aalto_figures import draw_all
from kiseki_experiments.gp.gp_aalto_folds import fold_evidence, fold_table
from kiseki_experiments.gp.gp_aalto_notes import (
    SOLIN_LENGTH_SCALE,
    SOLIN_SIGMA_N,
    THESIS_KERNEL,
    comparison_table,
    notes,
)
from kiseki_experiments.harness.base import Analysis

__all__ = ["analyze", "payloads"]

XYZ = ("x", "y", "z")


def payloads(trials: pd.DataFrame) -> dict[str, dict]:
    """task name -> its decoded payload (failed trials left out)."""
    ok = trials[trials["error"].isna()]
    return {row.task: json.loads(row.payload) for row in ok.itertuples()}


def _held_out_table(maps: dict) -> pd.DataFrame:
    rows = []
    for sensor, p in maps.items():
        variants = [("raw", "exact", p["train_points"], p["raw"])]
        variants.append(("corrected", "exact", p["train_points"], p["corrected"]))
        if "hilbert_all" in p:
            h = p["hilbert_all"]
            variants.append(("corrected", f"hilbert ({h['basis']} basis)", h["points"], h))
        for variant, method, points, s in variants:
            row = {"sensor": sensor, "readings": variant, "method": method, "points": points}
            row |= {f"rmse_{c}": s["rmse"][i] for i, c in enumerate(XYZ)}
            if "sd" in s:
                row |= {f"sd_{c}": s["sd"][i] for i, c in enumerate(XYZ)}
                row |= {f"in1_{c}": s["in1"][i] for i, c in enumerate(XYZ)}
                row |= {"in1_all": s["in1_all"]}
            row |= {"in2_all": s["in2_all"], "mlpd": s["mlpd"]}
            rows.append(row)
    return pd.DataFrame(rows)


def _hyperparameter_table(maps: dict) -> pd.DataFrame:
    rows = [
        {"source": "thesis Table 6.1 (its hall, 3-D, its units)", "component": "each"}
        | THESIS_KERNEL,
        {
            "source": "Solin et al.'s example on this data (potential kernel, uT)",
            "component": "potential",
            "sigma_f": float("nan"),
            "length_scale": SOLIN_LENGTH_SCALE,
            "sigma_n": SOLIN_SIGMA_N,
        },
    ]
    for sensor, p in maps.items():
        for variant in ("kernels_raw", "kernels"):
            label = "raw" if variant == "kernels_raw" else "corrected"
            for c, k in zip(XYZ, p[variant], strict=True):
                rows.append({"source": f"kiseki {sensor}, {label} (uT)", "component": c} | k)
    table = pd.DataFrame(rows)
    table["sigma_n_over_sigma_f"] = table["sigma_n"] / table["sigma_f"]
    return table


def _sweep_table(maps: dict) -> pd.DataFrame:
    rows = []
    for sensor, p in maps.items():
        for r in p["sweep"]:
            row = {"sensor": sensor, "readings": r.get("readings", "corrected")}
            row |= {"every": r["step"], "points": r["points"]}
            row |= {"method": r["method"], "in2_all": r["in2_all"], "mlpd": r["mlpd"]}
            rows.append(row | {f"rmse_{c}": r["rmse"][i] for i, c in enumerate(XYZ)})
    return pd.DataFrame(rows)


def _change_table(change: dict) -> pd.DataFrame:
    rows = []
    for r in change["rows"]:
        keys = ("run", "role", "coverage", "share", "rms_z", "mlpd")
        row = {k: r[k] for k in keys} | {
            k: r.get(k, float("nan")) for k in ("near_others_share", "near_others_departed")
        }
        flagged = bool(r["share"] > change["threshold"])
        expected = not r["role"].startswith("static")  # shelves brought in
        row |= {"changed": flagged, "expected": expected, "as_expected": flagged == expected}
        rows.append(row)
    table = pd.DataFrame(rows)
    table["threshold"] = change["threshold"]
    return table


def analyze(config, trials: pd.DataFrame, timings: pd.DataFrame, figures: Path) -> Analysis:
    p = payloads(trials)
    maps = {k[4:]: v for k, v in p.items() if k.startswith("map-")}
    folds = [p[k] for k in sorted(p, key=_fold_order) if k.startswith("fold-")]
    change, mcl, walks = p.get("change"), p.get("mcl"), p.get("walks")
    tables: dict[str, pd.DataFrame] = {}
    tables["thesis_solin_kiseki"] = comparison_table(config, maps, mcl, timings)
    if maps:
        tables["held_out"] = _held_out_table(maps)
        tables["hyperparameters"] = _hyperparameter_table(maps)
        tables["denser_training"] = _sweep_table(maps)
        offsets = [
            {"sensor": s, "bx_forward": v["offset"][0], "by_left": v["offset"][1]}
            for s, v in maps.items()
        ]
        tables["robot_frame_offset"] = pd.DataFrame(offsets)
        for s, v in maps.items():
            if "offset_vs_invensense" in v:
                rows = [
                    {"run": r["run"]} | {f"mean_{c}": r["mean"][i] for i, c in enumerate(XYZ)}
                    for r in v["offset_vs_invensense"]
                ]
                tables[f"{s}_minus_invensense"] = pd.DataFrame(rows)
    if folds:
        tables["leave_one_run_out"] = fold_table(folds)
    if change is not None:
        tables["change_detection"] = _change_table(change)
    if mcl is not None:
        cols = ["noise_seed", "mcl_mean", "mcl_max", "odometry_mean", "odometry_max"]
        cols += ["heading_mean", "heading_max", "resamplings"]
        tables["mcl"] = pd.DataFrame(mcl["rows"])[cols]
    if walks is not None:
        tables["walks_3d"] = _walks_table(walks)
    paths = draw_all(config, maps, change, mcl, walks, figures)
    text = notes(config, maps, change, mcl, walks)
    evidence = fold_evidence(folds) + mcl_evidence(mcl)
    return Analysis(tables, paths, notes=text, evidence=evidence)


def _fold_order(task: str) -> tuple[int, str]:
    """Folds by held-out run number (fold-10 after fold-9), other tasks after them."""
    return (int(task[5:]), task) if task.startswith("fold-") else (1 << 30, task)


def _walks_table(walks: dict) -> pd.DataFrame:
    rows = []
    for w in walks["walks"]:
        for label in ("raw", "corrected"):
            if label not in w:
                continue
            v, s = w[label], w[label]["score"]
            row = {"walk": w["walk"], "readings": label, "train": w["train"]}
            row |= {"test": w["samples"] - w["train"]}
            row |= {f"offset_{c}": v["offset"][i] for i, c in enumerate(XYZ)}
            row |= {f"rmse_{c}": s["rmse"][i] for i, c in enumerate(XYZ)}
            row |= {f"sd_{c}": s["sd"][i] for i, c in enumerate(XYZ)}
            row |= {"in2_all": s["in2_all"], "length_scale": v["kernels"][0]["length_scale"]}
            rows.append(row)
    return pd.DataFrame(rows)
