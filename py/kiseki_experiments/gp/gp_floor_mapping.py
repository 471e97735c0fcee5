# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""gp-floor-mapping: the thesis' robotized mapping of a 450 m^2 floor (``002_74cea16d239c028f
.txt``, secs. 6.5-6.6, Figs. 6.10-6.14) on the simulated floor (data/worlds/magnetic_floor.yaml).

* ``2d`` (sec. 6.5.1, Fig. 6.13): mapper_2d's three magnetometers 0.15 m above the floor, a
  reading every 0.1 m of its lawn-mower route; the exact GP of mx, my, mz on all readings
  (one shared kernel); mean and variance (eqs. 6.8, 6.9) on a 0.1 m grid; the map's RMSE
  against the simulator's noise-free field at every free cell, by distance from the survey.
* ``3d`` (sec. 6.5.2, Fig. 6.14): mapper_3d's arm (two sensors 0.6 m apart on a yaw-pitch
  bar) read at 10 Hz, averaged in 0.2 m voxels; the exact GP on the voxels and its mean and
  variance on every voxel of the floor up to 2.2 m (about 125,000), fit and prediction timed
  apart; RMSE on a seeded random set of free voxels. The thesis stored only eq. 6.16's
  magnitude per voxel; a shared kernel makes the three components cost one factorisation, so
  kiseki maps all three (the magnitude's error is reported from them).

Compute times (wall, with the load average) are rows beside the thesis' 30 min and 29 h (sec.
6.9.1), not claims; the time on all points extrapolates one evaluation of eq. 6.11 on all of them
(:func:`_on_all_points`). The surveys' sizes are no results (the routes were fitted to the
thesis' counts). A trial is one survey of one map; ``runs_per_map`` of each give the intervals.
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.spatial import cKDTree

from kiseki.gp import ExactGP, SquaredExponential
from kiseki.gp.kernel import log_marginal_likelihood
from kiseki.magnetic.field_map import MagneticFieldMap
from kiseki.magnetic.render import render_field_map
from kiseki.plots import new_figure, save_figure
from kiseki.sim.scene import load_scene
from kiseki_experiments.gp.gp_common import (
    FLOOR,
    SENSOR_NOISE,
    floor_map_2d,
    free_mask,
    magnetic_world,
    patch_hyperparameters,
    survey_3d,
)
from kiseki_experiments.gp.gp_floor_mapping_report import (
    CLAIMS,
    THESIS,
    calibrated,
    claim_evidence,
    gp_all,
)
from kiseki_experiments.harness.base import Analysis, Experiment, TrialOutput
from kiseki_experiments.harness.config import (
    Count,
    FitPoints,
    NonNegativeReal,
    PositiveReal,
    Rate,
    Resolution,
    Restarts,
    Runs,
    Share,
    Voxel,
)
from kiseki_experiments.harness.records import load_average, pack, unpack

__all__ = ["EXPERIMENT", "FloorMappingConfig"]

MAPS = ("2d", "3d")
MODELS = ("gp", "constant")
BANDS = ((0.0, 0.25, "on the tracks"), (0.25, 0.75, "between lanes"), (0.75, np.inf, "unsurveyed"))


@dataclass(frozen=True)
class FloorMappingConfig:
    scene: str = str(FLOOR)
    maps: list[str] = field(default_factory=lambda: list(MAPS))
    resolution: Resolution = 0.1  # m, the 2-D map's cells
    voxel: Voxel = 0.2  # m, the thesis' 3-D voxels
    top: PositiveReal = 2.2  # m, the voxel grid's height (11 layers of 0.2 m)
    rate_hz: Rate = 10.0  # the arm's sensors (the thesis' 10 Hz)
    hyper_points: FitPoints = 1000  # readings or voxels the hyperparameters are fitted on
    restarts: Restarts = 2
    truth_voxels: Count = 20000  # free voxels the 3-D map is scored on (seeded)
    share: Share = 1.0  # the part of each route surveyed (tests use less)
    noise_sd: NonNegativeReal = SENSOR_NOISE
    runs_per_map: Runs = 5  # surveys (noise seeds) of each map: the claims' intervals
    # "gp": eq. 6.8's mean; "constant": the training readings' mean everywhere (the claims'
    # control: a map that reproduces no disturbance)
    model: str = "gp"


def preflight(config: FloorMappingConfig) -> None:
    if not Path(config.scene).is_file():
        raise FileNotFoundError(f"gp-floor-mapping: {config.scene} not found")
    bad = [m for m in config.maps if m not in MAPS]
    if bad or not config.maps:
        raise ValueError(f"gp-floor-mapping: maps must be among {MAPS}, got {config.maps}")
    if not (config.resolution > 0 and config.voxel > 0 and config.top > 0):
        raise ValueError("gp-floor-mapping: resolution, voxel and top must be > 0")
    if config.model not in MODELS:
        raise ValueError(f"gp-floor-mapping: model must be one of {MODELS}, got {config.model!r}")


def _scores(mean, var, truth, distance, reference) -> dict:
    """RMSE per component and by band of distance to the nearest reading, R^2 of the
    disturbance (over the cells, and per band against `reference`, the training readings' mean:
    the share of the field's variation about it that the map explains), and the share of errors
    within 1 and 2 predicted SD."""
    err = mean - truth
    out = {f"rmse_{c}": float(np.sqrt(np.mean(err[:, k] ** 2))) for k, c in enumerate("xyz")}
    out["rmse"] = float(np.sqrt(np.mean(err**2)))
    out["r2"] = float(1 - np.mean(err**2) / np.mean(np.var(truth, axis=0)))
    mag = np.linalg.norm(mean, axis=1) - np.linalg.norm(truth, axis=1)
    out["rmse_magnitude"] = float(np.sqrt(np.mean(mag**2)))
    z = np.abs(err) / np.sqrt(np.maximum(var, 1e-300))
    out["within_1sd"], out["within_2sd"] = float(np.mean(z <= 1)), float(np.mean(z <= 2))
    for lo, hi, name in BANDS:
        band = (distance >= lo) & (distance < hi)
        key = name.replace(" ", "_")
        out[f"cells_{key}"] = int(band.sum())
        out[f"rmse_{key}"] = float(np.sqrt(np.mean(err[band] ** 2))) if band.any() else np.nan
        spread = np.mean((truth[band] - reference) ** 2) if band.any() else np.nan
        out[f"r2_{key}"] = float(1 - np.mean(err[band] ** 2) / spread) if band.any() else np.nan
    return out


def _map_2d(config: FloorMappingConfig, seed: int) -> TrialOutput:
    floor = floor_map_2d(
        config.scene,
        seed,
        config.resolution,
        config.hyper_points,
        config.restarts,
        config.noise_sd,
        config.share,
    )
    scene, survey = load_scene(config.scene), floor.survey
    fmap = _modelled(config, floor.field_map, survey.field)
    centres = fmap.cell_centres()
    start = time.perf_counter()
    truth = magnetic_world(scene).static_field_at(
        np.column_stack([centres, np.full(len(centres), fmap.height)])
    )
    truth_s = time.perf_counter() - start
    free = free_mask(scene, centres, fmap.height)
    distance = cKDTree(survey.positions).query(centres)[0]
    mean, var = fmap.mean.reshape(-1, 3), fmap.variance.reshape(-1, 3)
    record = _record("2d", survey, floor.hyperparameters.kernel, fmap)
    reference = np.mean(survey.field, axis=0)
    record.update(_scores(mean[free], var[free], truth[free], distance[free], reference))
    record["free_cells"] = int(free.sum())
    record["truth"] = pack(truth)
    record["free"] = pack(free)
    record["samples"] = pack(survey.positions)
    timings = dict(floor.seconds, truth_s=truth_s)
    timings["gp_s"] = timings["hyperparameters_s"] + timings["fit_s"] + timings["predict_s"]
    timings.update(_on_all_points(survey, floor.hyperparameters, timings["fit_s"]))
    return TrialOutput(record, timings)


def _map_3d(config: FloorMappingConfig, seed: int) -> TrialOutput:
    scene = load_scene(config.scene)
    start = time.perf_counter()
    survey = survey_3d(scene, seed, config.rate_hz, config.voxel, share=config.share)
    surveyed, cpu = time.perf_counter(), time.process_time()
    hyper = patch_hyperparameters(
        survey.positions,
        survey.field,
        config.hyper_points,
        noise_sd=config.noise_sd,
        restarts=config.restarts,
        seed=seed,
    )
    fitted = time.perf_counter()
    gp = ExactGP.fit(survey.positions, survey.field, hyper.kernel)
    factorised = time.perf_counter()
    lo, hi = scene.bounds
    upper = np.array([hi[0], hi[1], config.top])
    fmap = MagneticFieldMap.from_gp(gp, [lo[0], lo[1], 0.0], upper, config.voxel, units="G")
    fmap = _modelled(config, fmap, survey.field)
    predicted, cpu = time.perf_counter(), time.process_time() - cpu
    centres = fmap.cell_centres()
    free = np.flatnonzero(free_mask(scene, centres, 1.0))
    rng = np.random.default_rng(seed)
    pick = np.sort(rng.choice(free, min(config.truth_voxels, len(free)), replace=False))
    truth = magnetic_world(scene).static_field_at(centres[pick])
    truth_s = time.perf_counter() - predicted
    distance = cKDTree(survey.positions).query(centres[pick])[0]
    mean, var = fmap.mean.reshape(-1, 3)[pick], fmap.variance.reshape(-1, 3)[pick]
    record = _record("3d", survey, hyper.kernel, fmap)
    record.update(_scores(mean, var, truth, distance, np.mean(survey.field, axis=0)))
    record["scored_voxels"] = len(pick)
    timings = {
        "survey_s": surveyed - start,
        "hyperparameters_s": fitted - surveyed,
        "fit_s": factorised - fitted,
        "predict_s": predicted - factorised,
        "gp_s": predicted - surveyed,
        "cpu_s": cpu,
        "truth_s": truth_s,
        "load": load_average(),
    }
    timings.update(_on_all_points(survey, hyper, timings["fit_s"]))
    return TrialOutput(record, timings)


def _modelled(config: FloorMappingConfig, fmap: MagneticFieldMap, field) -> MagneticFieldMap:
    """The map the trial scores: the GP's, or for the control the training readings' mean in
    every cell (the GP's variance kept)."""
    if config.model == "gp":
        return fmap
    constant = np.broadcast_to(np.mean(field, axis=0), fmap.mean.shape)
    return dataclasses.replace(fmap, mean=np.array(constant))


def _on_all_points(survey, hyper, fit_s: float) -> dict:
    """The hyperparameter fit's cost on all training points, from what is measured on them.
    The fit ran on a subsample (``hyper_points``); the thesis fitted on all its points. One
    evaluation of eq. 6.11 with its gradient (eqs. 6.12-6.15) is timed here on all points; one
    without the gradient costs one Cholesky factorisation, which is what ``fit_s`` measured on
    all points. The fit on all points is extrapolated as the subsample fit's evaluations at
    those costs (it assumes the optimiser takes as many steps on all points)."""
    start, cpu = time.perf_counter(), time.process_time()
    log_marginal_likelihood(survey.positions, survey.field, hyper.kernel)
    gradient_s, gradient_cpu_s = time.perf_counter() - start, time.process_time() - cpu
    values = hyper.evaluations - hyper.gradients
    return {
        "evaluation_all_s": gradient_s,
        "evaluation_all_cpu_s": gradient_cpu_s,  # every thread's: what the load does not add
        "hyper_evaluations": float(hyper.evaluations),
        "hyper_gradients": float(hyper.gradients),
        "hyperparameters_all_s": hyper.gradients * gradient_s + values * fit_s,
    }


def _record(kind: str, survey, kernel: SquaredExponential, fmap: MagneticFieldMap) -> dict:
    return {
        "map": kind,
        "training_points": len(survey.field),
        "readings": survey.readings,
        "survey_min": survey.duration / 60.0,
        "route_m": survey.length,
        "sigma_f": kernel.sigma_f,
        "length_scale": kernel.length_scale,
        "sigma_n": kernel.sigma_n,
        "cells": int(fmap.mean.size // 3),
        "shape": list(fmap.mean.shape),
        "origin": fmap.origin.tolist(),
        "resolution": fmap.resolution,
        "height": fmap.height if fmap.height is not None else np.nan,
        "prior_mean": fmap.prior_mean.tolist(),
        "mean": pack(fmap.mean),
        "variance": pack(fmap.variance),
    }


def trial(config: FloorMappingConfig, index: int, seed: int) -> TrialOutput:
    kind = config.maps[index % len(config.maps)]
    return _map_2d(config, seed) if kind == "2d" else _map_3d(config, seed)


def _field_map(row) -> MagneticFieldMap:
    shape = tuple(int(v) for v in row["shape"])
    kernel = SquaredExponential(row["sigma_f"], row["length_scale"], row["sigma_n"])
    return MagneticFieldMap(
        origin=np.asarray(row["origin"], dtype=float),
        resolution=float(row["resolution"]),
        mean=unpack(row["mean"]).reshape(shape),
        variance=unpack(row["variance"]).reshape(shape),
        prior_mean=np.asarray(row["prior_mean"], dtype=float),
        prior_variance=np.full(3, row["sigma_f"] ** 2),
        kernel=kernel,
        units="G",
        height=float(row["height"]) if len(shape) == 3 else None,
    )


def analyze(config: FloorMappingConfig, trials, timings, figures: Path) -> Analysis:
    ok = trials[trials["error"].isna()].merge(timings, on="trial").sort_values("trial")
    cost, accuracy = [], []
    for _, r in ok.iterrows():
        kind, thesis = r["map"], THESIS[r["map"]]
        cost.append(
            {
                "map": kind,
                "trial": r["trial"],
                "training_points": r["training_points"],
                "thesis_points": thesis["data"],
                "readings": r["readings"],
                "survey_min": r["survey_min"],
                "thesis_survey_min": thesis["survey_min"],
                "cells": r["cells"],
                "hyperparameters_s": r["hyperparameters_s"],
                "fit_s": r["fit_s"],
                "predict_s": r["predict_s"],
                "fit_predict_s": r["fit_s"] + r["predict_s"],
                "gp_s": r["gp_s"],
                "gp_cpu_s": r["cpu_s"],
                "hyper_points": min(config.hyper_points, int(r["training_points"])),
                "hyper_evaluations": r["hyper_evaluations"],
                "evaluation_all_s": r["evaluation_all_s"],
                "evaluation_all_cpu_s": r["evaluation_all_cpu_s"],
                "hyperparameters_all_s_extrapolated": r["hyperparameters_all_s"],
                "gp_all_s_extrapolated": gp_all(r),
                "thesis_gp_s": thesis["gp_s"],
                "speed_up_extrapolated": thesis["gp_s"] / gp_all(r),
                "load_average": r["load"],
            }
        )
        keys = [k for k in r.index if k.startswith(("rmse", "r2", "within", "cells_"))]
        accuracy.append({"map": kind, "trial": r["trial"], **{k: r[k] for k in keys}})
        accuracy[-1].update(sigma_f=r["sigma_f"], length_scale=r["length_scale"])
        accuracy[-1]["sigma_n"] = r["sigma_n"]
    first = {r["map"]: r for _, r in ok.iloc[::-1].iterrows()}  # each map's first survey
    figs = []
    for kind, r in sorted(first.items()):
        fmap = _field_map(r)
        what = "Fig. 6.13: 2-D" if kind == "2d" else "Fig. 6.14: 3-D"
        figs.append(
            render_field_map(
                fmap, figures / f"gp_floor_{kind}_map.png", 4, f"{what} magnetic map (kiseki)"
            )
        )
        if kind == "2d":
            figs.append(_plot_truth(fmap, r, figures))
    tables = {
        "cost": pd.DataFrame(cost),
        "accuracy": pd.DataFrame(accuracy),
        "calibrated": calibrated(first),
    }
    return Analysis(tables, figs, notes=NOTES, evidence=claim_evidence(ok))


def _plot_truth(fmap: MagneticFieldMap, row, figures: Path) -> Path:
    """The simulator's true mz, the map's, and the error, with the survey's readings."""
    shape = fmap.mean.shape
    truth = unpack(row["truth"]).reshape(shape)
    free = unpack(row["free"]).reshape(shape[:2]) > 0.5
    samples = unpack(row["samples"])
    lo, hi = fmap.lower, fmap.upper
    extent = [lo[0], hi[0], lo[1], hi[1]]
    error = np.where(free, np.abs(fmap.mean[..., 2] - truth[..., 2]), np.nan)
    vmin, vmax = np.percentile(truth[..., 2][free], [1, 99])
    fig = new_figure(figsize=(15, 3.6), dpi=110)
    axes = fig.subplots(1, 3)
    for ax, image, title, kw in (
        (axes[0], truth[..., 2], "true mz (simulator)", {"vmin": vmin, "vmax": vmax}),
        (axes[1], fmap.mean[..., 2], "map mz (GP mean)", {"vmin": vmin, "vmax": vmax}),
        (axes[2], error, "|error| of mz, free cells", {"vmin": 0, "vmax": 0.03, "cmap": "magma"}),
    ):
        shown = ax.imshow(image, origin="lower", extent=extent, **kw)
        fig.colorbar(shown, ax=ax, shrink=0.8, label="G")
        ax.set_title(title, fontsize=9)
    axes[2].plot(samples[::3, 0], samples[::3, 1], ",", color="cyan", alpha=0.5)
    fig.tight_layout()
    return save_figure(fig, figures / "gp_floor_2d_truth.png")


NOTES = """
Positions are the simulator's true poses (the thesis localized its robots with LIDAR MCL; that
error is not modelled) and readings are turned to the world frame with them. The 2-D map is
the GP at the sensors' height, 0.15 m; cells inside walls, pillars and the elevator shaft are
left out of the scores. RMSE by band: within 0.25 m of a reading (on the sensors' tracks),
0.25-0.75 m (between the lanes, 1.8 m apart, or the three sensors' 0.25 m spacing), beyond
(never surveyed: the GP returns towards its prior). within_1sd/2sd: share of component errors
inside 1 and 2 predicted SD (a calibrated GP: 0.68 and 0.95). The thesis could not score its
maps against a truth (a manual survey of the floor would take 37-38 h, sec. 6.9.1); it judged
them by localization (gp-mcl). Hyperparameters: eq. 6.11 on 1,000 readings or voxels taken in
5 runs of consecutive samples, BFGS from the sensor's noise (see gp_common). Times are wall
clock on the machine that ran the experiment; the load average says how busy it was. The cost
table gives the subsample fit's time (hyperparameters_s) and, beside the thesis', the time on all
points: evaluation_all_s is one evaluation of eq. 6.11 with its gradient measured on all
training points, hyperparameters_all_s_extrapolated that times the subsample fit's gradient
evaluations plus fit_s (one Cholesky factorisation on all points) times its other evaluations.
fit_predict_s: the factorisation and the prediction with variance (for the 3-D map kiseki's own
2 minute target: a benchmark figure, not a claim). One row per survey. The calibrated table: the
surveys' sizes and the 2-D survey's duration, which magnetic_floor.yaml's routes were built to
give (calibrated, not results). The claims are decided on runs_per_map surveys of each map.
"""


EXPERIMENT = Experiment(
    name="gp-floor-mapping",
    paper="002_74cea16d239c028f.txt",
    artefact="Figs. 6.10-6.14, sec. 6.9.1 (2-D and 3-D robotized mapping)",
    description="2-D and 3-D GP magnetic maps of a 450 m^2 floor from the robots' surveys",
    config_type=FloorMappingConfig,
    trial=trial,
    analyze=analyze,
    default_runs=10,
    preflight=preflight,
    claims=CLAIMS,
    trial_count=lambda config: len(config.maps) * config.runs_per_map,
)
