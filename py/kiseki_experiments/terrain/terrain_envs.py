# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""terrain-env-a and terrain-env-b: paper 003's sec. 7.3, one move in environments A and B
(data/worlds/rubble_a.yaml, rubble_b.yaml) with the true motion (35, 30, 5) cm and the attitudes
(-2, -10, 15) and (-2, -11, 22) deg (kiseki.sim.pose6.PAPER_MOVES). Per seed: the two sweeps
(median of three, gyro with drift; kiseki_experiments.terrain.terrain_common), each plane removal
(``removals``; Hough per tilt scan is the paper's), the search (exhaustive over the paper's grid
by default), and the same with an exact gyro (``exact_gyro_rows``) to separate the gyro's share
of the error. Environment B also labels the cells of the small objects on the floor (cast
against them alone) and measures the share of them each removal takes out: the paper's reason
for B's failure.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from kiseki.sim.pose6 import PAPER_MOVES, Pose6
from kiseki.terrain import attitude_matrix
from kiseki_experiments.harness.base import Analysis, Claim, Experiment, TrialOutput
from kiseki_experiments.harness.config import Real, Resolution, Seconds
from kiseki_experiments.harness.paths import WORLDS
from kiseki_experiments.terrain.terrain_common import (
    check_common,
    local_maps,
    match,
    object_cells,
)
from kiseki_experiments.terrain.terrain_figures import draw_match

__all__ = ["ENV_A", "ENV_B", "EnvAConfig", "EnvBConfig", "search_move"]

PAPER = "003_fd335d240f62896b.txt"
TOLERANCE = 0.05  # m, the claim for environment A


def _degrees(move: Pose6) -> list[float]:
    return [float(np.degrees(a)) for a in (move.roll, move.pitch, move.yaw)]


@dataclass(frozen=True)
class EnvAConfig:
    scene: str = str(WORLDS / "rubble_a.yaml")
    move_m: list[Real] = field(default_factory=lambda: [0.35, 0.30, 0.05])
    attitude_deg: list[Real] = field(default_factory=lambda: _degrees(PAPER_MOVES["A"]))
    move_seconds: Seconds = 10.0
    removals: list[str] = field(default_factory=lambda: ["hough", "pcl", "none"])
    search: str = "exhaustive"
    cost: str = "mean"
    step: Resolution = 0.02
    exact_gyro_rows: bool = True
    label_objects: bool = False


@dataclass(frozen=True)
class EnvBConfig(EnvAConfig):
    scene: str = str(WORLDS / "rubble_b.yaml")
    attitude_deg: list[Real] = field(default_factory=lambda: _degrees(PAPER_MOVES["B"]))
    label_objects: bool = True


def _move(config: EnvAConfig) -> Pose6:
    if len(config.move_m) != 3 or len(config.attitude_deg) != 3:
        raise ValueError("terrain-env: move_m and attitude_deg take 3 values each")
    return Pose6.from_degrees(*config.move_m, *config.attitude_deg)


def preflight(config: EnvAConfig) -> None:
    check_common("terrain-env", config.removals, config.search, config.cost, config.step)
    _move(config)
    if not Path(config.scene).is_file():
        raise FileNotFoundError(f"terrain-env: scene {config.scene} not found")


def search_move(config: EnvAConfig, seed: int, exact: bool):
    maps = local_maps(config.scene, _move(config), seed, config.move_seconds, exact)
    labels = None
    if config.label_objects and not exact:
        labels = [
            object_cells(config.scene, m, p, g)
            for m, p, g in zip((maps.previous, maps.current), maps.poses, maps.gyro, strict=True)
        ]
    found = [match(maps, m, config.search, config.cost, config.step, seed) for m in config.removals]
    return maps, labels, found


def _object_shares(maps, labels, m) -> dict[str, float]:
    """The share of the object cells (both maps) that ``m``'s removal took out, of those the
    share higher than 4 cm above the floor (an object's face, not its foot within a floor
    line's or plane's 3 cm), and the share of the other cells removed."""
    objects = int(sum(lab.sum() for lab in labels))
    removed = sum(int((lab & rem).sum()) for lab, rem in zip(labels, m.removed, strict=True))
    above = 0
    for sdem, pose, gyro, lab, rem in zip(
        (maps.previous, maps.current), maps.poses, maps.gyro, labels, m.removed, strict=True
    ):
        points, cells = sdem.to_points()
        z = (points @ attitude_matrix(*(float(a) for a in gyro)) @ pose[:3, :3].T)[:, 2]
        hit = (lab & rem).reshape(-1)[cells]
        above += int((z[hit] + pose[2, 3] > 0.04).sum())
    cells = sum(int(np.isfinite(x.ranges).sum()) for x in (maps.previous, maps.current))
    other = sum(int(r.sum()) for r in m.removed) - removed
    return {
        "object_cells": objects,
        f"{m.method}_objects_removed": removed / objects if objects else float("nan"),
        f"{m.method}_objects_removed_above_4cm": above / objects if objects else float("nan"),
        f"{m.method}_others_removed": other / max(1, cells - objects),
    }


def _rise(costs, step: float, reach: float = 0.10) -> tuple[float, float]:
    """How much the cost rises ``reach`` from its minimum along x and along y (the mean of the
    two sides, relative to the minimum): a flat valley along x (small first figure) leaves
    the along-track position to small differences. NaN without a cost surface."""
    if costs is None or not np.isfinite(costs).any():
        return float("nan"), float("nan")
    i, j, k = np.unravel_index(int(np.nanargmin(np.where(np.isfinite(costs), costs, np.nan))),
                               costs.shape)  # fmt: skip
    n, low = max(1, round(reach / step)), float(costs[i, j, k])

    def side(values) -> float:
        finite = [v for v in values if np.isfinite(v)]
        return float(np.mean(finite) / low - 1.0) if finite and low > 0 else float("nan")

    nx, ny = costs.shape[:2]
    along = [costs[x, j, k] for x in (i - n, i + n) if 0 <= x < nx]
    across = [costs[i, y, k] for y in (j - n, j + n) if 0 <= y < ny]
    return side(along), side(across)


def trial(config: EnvAConfig, index: int, seed: int) -> TrialOutput:
    record, timings = {}, {}
    for exact in (False, True) if config.exact_gyro_rows else (False,):
        maps, labels, found = search_move(config, seed, exact)
        tag = "exact_" if exact else ""
        if not exact:
            gyro_error = np.degrees(maps.gyro[1] - maps.gyro[0]) - np.asarray(config.attitude_deg)
            for k, v in zip("rpy", gyro_error, strict=True):
                record[f"gyro_{k}_deg"] = float(v)
        for m in found:
            for k, v in zip("xyz", m.translation, strict=True):
                record[f"{tag}{m.method}_{k}"] = round(float(v), 6)
            record[f"{tag}{m.method}_error"] = float(np.linalg.norm(m.error))
            record[f"{tag}{m.method}_along"] = float(m.error[0])
            record[f"{tag}{m.method}_kept"] = float(np.mean(m.kept))
            timings[f"{tag}{m.method}_seconds"] = m.seconds
            rise = _rise(m.costs, config.step)
            record[f"{tag}{m.method}_rise_along"], record[f"{tag}{m.method}_rise_across"] = rise
            if labels is not None:
                record.update(_object_shares(maps, labels, m))
    return TrialOutput(record, timings)


def _summary(config: EnvAConfig, ok: pd.DataFrame) -> pd.DataFrame:
    rows = []
    for tag in ("", "exact_") if config.exact_gyro_rows else ("",):
        for m in config.removals:
            if f"{tag}{m}_error" not in ok:
                continue
            err = ok[f"{tag}{m}_error"]
            row = {
                "removal": m,
                "gyro": "exact" if tag else "with error",
                "x_cm": 100 * ok[f"{tag}{m}_x"].mean(),
                "y_cm": 100 * ok[f"{tag}{m}_y"].mean(),
                "z_cm": 100 * ok[f"{tag}{m}_z"].mean(),
                "error_mean_cm": 100 * err.mean(),
                "error_median_cm": 100 * err.median(),
                "error_max_cm": 100 * err.max(),
                "within_5cm": float((err <= TOLERANCE).mean()),
                "kept_share": ok[f"{tag}{m}_kept"].mean(),
            }
            if f"{m}_objects_removed" in ok and not tag:
                row["objects_removed"] = ok[f"{m}_objects_removed"].mean()
                row["objects_removed_above_4cm"] = ok[f"{m}_objects_removed_above_4cm"].mean()
                row["others_removed"] = ok[f"{m}_others_removed"].mean()
            rows.append(row)
    return pd.DataFrame(rows)


def _analyze(env: str, paper_xyz, config, trials, timings, figures: Path) -> Analysis:
    ok = trials[trials["error"].isna()]
    if ok.empty:
        return Analysis(notes="every trial failed: nothing to analyse")
    summary = _summary(config, ok)
    first = summary.iloc[0]
    truth = 100 * np.asarray(config.move_m)
    paper = pd.DataFrame(
        [
            {"source": "truth", "x_cm": truth[0], "y_cm": truth[1], "z_cm": truth[2]},
            {"source": "paper (Hough)", "x_cm": paper_xyz[0], "y_cm": paper_xyz[1],
             "z_cm": paper_xyz[2]},
            *({"source": f"kiseki {r.removal}, gyro {r.gyro} (mean of {len(ok)} seeds)",
               "x_cm": r.x_cm, "y_cm": r.y_cm, "z_cm": r.z_cm} for r in summary.itertuples()),
        ]
    )  # fmt: skip
    paper_err = float(np.linalg.norm(np.asarray(paper_xyz) - truth))
    claims = [
        Claim(
            claim=f"environment {env}: the motion is found within 5 cm with the paper's method "
            f"({first.removal}, {config.search} search)",
            paper_value=f"({paper_xyz[0]}, {paper_xyz[1]}, {paper_xyz[2]}) cm, "
            f"{paper_err:.1f} cm from the truth",
            measured_value=f"median {first.error_median_cm:.1f} cm, mean "
            f"{first.error_mean_cm:.1f} cm, {100 * first.within_5cm:.0f} % of {len(ok)} seeds "
            "within 5 cm",
            unit="cm",
            holds=bool(first.error_median_cm <= 100 * TOLERANCE),
            note="holds when the median over seeds is within 5 cm",
        )
    ]
    seed0 = int(ok.sort_values("trial")["seed"].iloc[0])
    path = figures / f"terrain_env_{env.lower()}.png"
    maps, _, found = search_move(config, seed0, False)
    draw_match(path, maps, found, config.step, f"environment {env}, first trial")
    return Analysis(
        {"summary": summary, "paper_vs_kiseki": paper}, [path], claims,
        _notes(config, ok),
    )  # fmt: skip


def _notes(config: EnvAConfig, ok: pd.DataFrame) -> str:
    gyro = ok[["gyro_r_deg", "gyro_p_deg", "gyro_y_deg"]].abs().mean()
    return (
        "The move is the sensor's, in the first sensor's level frame (terrain_common). The "
        "S-DEMs are levelled with the gyro and the search is over translation only, as in the "
        f"paper; the gyro's error between the two sweeps ({config.move_seconds:g} s apart) "
        f"averaged |{gyro.iloc[0]:.2f}|, |{gyro.iloc[1]:.2f}|, |{gyro.iloc[2]:.2f}| deg in roll, "
        "pitch, yaw: a yaw error of 1 deg shifts a point 3 m away by 5 cm, which the search "
        "takes as translation. The 'exact' rows are the same sweeps' noise with a gyro without "
        "error. The scene's objects are kiseki's assumptions (the paper gives only the rooms' "
        "sizes and photographs), so the figures are not expected to equal the paper's."
    )


def analyze_a(config, trials, timings, figures):
    return _analyze("A", (32, 26, 6), config, trials, timings, figures)


def analyze_b(config, trials, timings, figures):
    analysis = _analyze("B", (44, -26, 20), config, trials, timings, figures)
    if not analysis.claims:
        return analysis
    summary = analysis.tables["summary"]
    first = summary.iloc[0]
    analysis.claims[0] = Claim(
        claim="environment B: the paper's method (Hough) fails",
        paper_value="(44, -26, 20) cm against (35, 30, 5): 59 cm off",
        measured_value=f"median {first.error_median_cm:.1f} cm, max {first.error_max_cm:.1f} cm",
        unit="cm",
        holds=bool(first.error_median_cm > 100 * TOLERANCE),
        note="holds when the median error over seeds is above 5 cm (environment A's "
        "tolerance); the paper's estimate was 59 cm off, with y of the wrong sign",
    )
    by = summary[summary["gyro"] == "with error"].set_index("removal")
    if {"hough", "pcl"} <= set(by.index) and "objects_removed" in by:
        analysis.claims.append(
            Claim(
                claim="the Hough step removes objects on the floor (the paper's reason for B)",
                paper_value="objects on the floor removed",
                measured_value=f"Hough removes {100 * by.loc['hough', 'objects_removed']:.0f} % "
                f"of the object cells, PCL {100 * by.loc['pcl', 'objects_removed']:.0f} %",
                unit="%",
                holds=bool(by.loc["hough", "objects_removed"] > by.loc["pcl", "objects_removed"]),
                note="holds when Hough removes a larger share of the object cells than PCL",
            )
        )
        analysis.claims.append(
            Claim(
                claim="the 3-D plane removal (PCL) fixes environment B",
                paper_value="not tried",
                measured_value=f"median {by.loc['pcl', 'error_median_cm']:.1f} cm vs Hough "
                f"{by.loc['hough', 'error_median_cm']:.1f} cm",
                unit="cm",
                holds=bool(by.loc["pcl", "error_median_cm"] <= 100 * TOLERANCE),
                note="holds when PCL's median error is within 5 cm",
            )
        )
        analysis.notes += _b_notes(by)
    return analysis


def _b_notes(by: pd.DataFrame) -> str:
    hough = [100 * by.loc["hough", k] for k in ("objects_removed", "objects_removed_above_4cm")]
    pcl = [100 * by.loc["pcl", k] for k in ("objects_removed", "objects_removed_above_4cm")]
    return (
        "\n\nObject cells: the cells of the scene's boxes standing on the floor below 1 m, "
        "found by casting each cell's ray against them alone. Hough took out "
        f"{hough[0]:.1f} % of them, {hough[1]:.1f} % "
        "higher than 4 cm: only the objects' feet, within the floor line's 3 cm; an object "
        "makes no line of its own, since a line needs 30 cells of 1 deg within 3 cm and a "
        "0.5 m face at 1 m spans 28 deg. PCL took out "
        f"{pcl[0]:.1f} %, {pcl[1]:.1f} % "
        "higher than 4 cm: a box's flat side seen from about 1 m gives more than PCL's 400 "
        "inliers and is removed as a plane (a check of seeds 0 and 1: in the current map PCL's "
        "fifth plane, normal (0.33, -0.95, 0), is the side of the 0.5 m box turned 20 deg). "
        "So in kiseki's environment B the mechanism the paper "
        "gives (objects removed with the planes) is PCL's, not Hough's; the Hough lines of the "
        "paper are not described beyond 'straight lines', so kiseki's 30-cell, 3 cm lines may "
        "be stricter than the paper's."
    )


ENV_A = Experiment(
    name="terrain-env-a",
    paper=PAPER,
    artefact="sec. 7.3, environment A, Figs. 11-12",
    description="one move in environment A: (35, 30, 5) cm, attitude (-2, -10, 15) deg",
    config_type=EnvAConfig,
    trial=trial,
    analyze=analyze_a,
    default_runs=5,
    preflight=preflight,
)

ENV_B = Experiment(
    name="terrain-env-b",
    paper=PAPER,
    artefact="sec. 7.3, environment B",
    description="one move in environment B: (35, 30, 5) cm, attitude (-2, -11, 22) deg; "
    "object cells removed by each plane removal",
    config_type=EnvBConfig,
    trial=trial,
    analyze=analyze_b,
    default_runs=5,
    preflight=preflight,
)
