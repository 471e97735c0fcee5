# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""gp-floor-mapping's claims. The surveys' sizes and the 2-D survey's duration are no results:
magnetic_floor.yaml's routes were fitted to the thesis' 6432 readings in about 30 min and 6556
voxels (its ``calibrated`` marks); they are shown in the ``calibrated`` table, not claimed. The
GP times are compared with the thesis' fits on all points: kiseki fits its hyperparameters on a
subsample, so its time on all points is extrapolated from one evaluation of eq. 6.11 measured on
all of them (gp_floor_mapping._on_all_points), and says so."""

from __future__ import annotations

import pandas as pd

from kiseki_experiments.harness.base import Claim

__all__ = ["CALIBRATED", "THESIS", "calibrated", "claims", "gp_all"]

THESIS = {  # sec. 6.5-6.9: data, survey time (min), GP time (s)
    "2d": {"data": 6432, "survey_min": 30.0, "gp_s": 30 * 60.0},
    "3d": {"data": 6556, "survey_min": 60.0, "gp_s": 29 * 3600.0},
}
#: The label of a thesis number that a scene parameter was fitted to (the scene's ``calibrated``).
CALIBRATED = "calibrated, not a result"


def gp_all(r) -> float:
    """s: GP regression on all points as the thesis ran it: the hyperparameter fit on all of
    them (extrapolated), the fit and the map with variance (measured)."""
    return float(r["hyperparameters_all_s"] + r["fit_s"] + r["predict_s"])


def calibrated(rows: dict) -> pd.DataFrame:
    """The surveys' sizes beside the thesis' numbers their routes were fitted to."""
    out = []
    for kind, r in rows.items():
        unit = "readings" if kind == "2d" else "voxels"
        out.append((kind, f"{unit} of the survey", THESIS[kind]["data"], r["training_points"]))
        if kind == "2d":
            out.append((kind, "survey min", THESIS[kind]["survey_min"], r["survey_min"]))
    return pd.DataFrame(
        [
            {"map": k, "quantity": q, "thesis": t, "kiseki": float(v), "status": CALIBRATED}
            for k, q, t, v in out
        ]
    )


def _time_claim(kind: str, r, thesis_text: str) -> Claim:
    total, limit = gp_all(r), THESIS[kind]["gp_s"]
    what = "2-D" if kind == "2d" else "3-D"
    return Claim(
        f"{what} GP regression time on all {int(r['training_points'])} training points "
        "(hyperparameters, fit, map with variance; sec. 6.9.1)",
        thesis_text,
        f"{total:.0f} s ({limit / total:.2g} x the thesis' speed): hyperparameters "
        f"{r['hyperparameters_all_s']:.0f} s extrapolated ({int(r['hyper_evaluations'])} "
        f"evaluations, {r['evaluation_all_s']:.1f} s each with the gradient measured on all "
        f"points, {r['evaluation_all_cpu_s']:.1f} s of CPU), fit {r['fit_s']:.1f} s and "
        f"{r['cells']} cells with variance "
        f"{r['predict_s']:.1f} s measured",
        f"s, wall, load average {r['load']:.1f}",
        bool(total < limit),
        "the hyperparameter fit ran on a subsample; its time on all points is extrapolated "
        "(as many optimiser steps as on the subsample), the rest is measured",
    )


def claims(config, rows: dict) -> list[Claim]:
    out = []
    if "2d" in rows:
        r = rows["2d"]
        out += [
            _time_claim("2d", r, "about 30 min"),
            Claim(
                "the 2-D map reproduces the disturbances (Fig. 6.13): near the survey tracks "
                "better than one reading",
                "reproduced (pictures)",
                f"RMSE {r['rmse_on_the_tracks']:.4f} G within 0.25 m of a reading; R^2 "
                f"{r['r2']:.2f} on all {int(r['free_cells'])} free cells",
                "G",
                bool(r["rmse_on_the_tracks"] < config.noise_sd),
                f"holds when that RMSE is below the sensor's {config.noise_sd} G noise",
            ),
        ]
    if "3d" in rows:
        r = rows["3d"]
        out += [
            _time_claim("3d", r, "about 29 h"),
            Claim(
                "3-D fit + prediction of 125,000 voxels with variance on 2 cores (issue 12's "
                "target, not the thesis')",
                "< 120 s",
                f"{r['fit_s'] + r['predict_s']:.1f} s",
                f"s, wall, load average {r['load']:.1f}",
                bool(r["fit_s"] + r["predict_s"] < 120),
            ),
            Claim(
                "the 3-D map is right between the arm's sensors 0.6 m apart (sec. 6.6.2)",
                "estimated correctly",
                f"RMSE {r['rmse_on_the_tracks']:.4f} G within 0.25 m of a filled voxel, "
                f"{r['rmse_between_lanes']:.4f} G at 0.25-0.75 m",
                "G",
                bool(r["rmse_between_lanes"] < config.noise_sd),
                f"holds when the 0.25-0.75 m RMSE is below the sensor's {config.noise_sd} G",
            ),
        ]
    return out
