# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""gp-aalto: the chapter-6 pipeline on recorded data (the issue's "real data" item).

The Aalto robot runs (Solin et al., IEEE T-RO 2018: a small robot under Vicon, an InvenSense
and a Nexus 5 magnetometer, readings already turned into the world frame; runs 1-5 in a static
field, runs 6-9 with metal shelves brought in) and the hand-held walks of Kok and Solin (MFI
2024). One trial per task:

* ``fold-<run>`` (one per static run, on the reference sensor): the held-out map's claims over
  leave-one-run-out folds (:mod:`kiseki_experiments.gp.gp_aalto_folds`);
* ``map-<sensor>`` (one per sensor): GP maps (eqs. 6.7-6.15, one GP per component as the thesis
  fits them) of every ``thinning``-th sample of runs 1-4, predicting held-out run 5: RMSE per
  component, the share of errors inside 1 and 2 predictive sigma (sigma^2 = variance of the
  noise-free field + sigma_n^2), the hyperparameters; the same after removing a residual
  hard-iron offset fixed to the robot (estimated from runs 1-4 alone, see
  :mod:`kiseki_experiments.gp.gp_aalto_steps`); the reduced-rank HilbertGP on all samples of runs
  1-4 and on the thinned set beside the exact GP; the RMSE as the training data get denser.
* ``change``: every run scored against the map of runs 1-4 (InvenSense: the Nexus' z axis
  drifts between runs): share of samples whose standardized residual exceeds 3; the threshold
  is ``change_factor`` times the largest share of runs 1-4, each held out against the others.
* ``mcl``: magnetic-map MCL (eqs. 6.17-6.18) along run 5 with odometry made from the Vicon
  increments and seeded noise (a per-run distance scale error and a heading random walk),
  against the odometry alone.
* ``walks``: 3-D maps of the hand-held walks, each trained on its first part, predicting the
  rest.

Cost: about 3-6 minutes on 2 cores (the hyperparameter fits dominate). ``data_dir`` is the
folder holding ``aalto/`` and ``kok_1d/``; by default ``../shared/data/magnetic`` beside the
project.

Modules: ``gp_aalto_steps`` (the static map, the robot-frame offset, the scores),
``gp_aalto_tasks`` (the tasks), ``gp_aalto_folds`` (the folds and their claims),
``gp_aalto_report`` (tables and evidence), ``gp_aalto_notes``
(the report's text), ``gp_aalto_figures`` (the pictures).
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated

from kiseki_experiments.gp import gp_aalto_tasks as work
from kiseki_experiments.gp.gp_aalto_change import change_task
from kiseki_experiments.gp.gp_aalto_claims import CLAIMS
from kiseki_experiments.gp.gp_aalto_folds import (
    FOLD_CLAIMS,
    FOLD_MODELS,
    FOLD_VARIANCES,
    fold_task,
    static_runs,
)
from kiseki_experiments.gp.gp_aalto_report import analyze
from kiseki_experiments.harness.base import Experiment, TrialOutput
from kiseki_experiments.harness.config import (
    Count,
    FitPoints,
    Index,
    Lag,
    NonEmpty,
    NonNegativeReal,
    Particles,
    PositiveReal,
    Resolution,
    Restarts,
    Runs,
    Seed,
    Share,
    Spacing,
)
from kiseki_experiments.harness.paths import shared_data

__all__ = ["EXPERIMENT", "GpAaltoConfig", "data_dir", "tasks"]

AALTO_SENSORS = ("invensense", "nexus")
WALKS = ("eight", "square")


@dataclass(frozen=True)
class GpAaltoConfig:
    data_dir: str = ""  # folder with aalto/ and kok_1d/; "" = ../shared/data/magnetic
    sensors: list[str] = field(default_factory=lambda: list(AALTO_SENSORS))
    train_runs: list[Index] = field(default_factory=lambda: [1, 2, 3, 4])
    test_run: Index = 5
    changed_runs: list[Index] = field(default_factory=lambda: [6, 7, 8, 9])
    # every thinning-th reading of the 50 Hz runs: 50 = one a second (about 0.18 m of travel);
    # denser readings repeat the same along-track error (the sweep below shows it)
    thinning: Count = 50
    per_component: bool = True  # one GP per field component, as the thesis fits mx, my, mz
    max_points: FitPoints = 1000  # hyperparameters on at most this many readings (seeded subsample)
    restarts: Restarts = 2  # seeded restarts of the hyperparameter search
    gp_seed: Seed = 0  # seed of the hyperparameter search (shared by every task)
    offset_calibration: bool = True  # remove a residual hard-iron offset fixed to the robot
    sweep: Annotated[list[Count], NonEmpty] = field(default_factory=lambda: [1, 5, 10, 25, 50, 100])
    sweep_raw: bool = True  # the sweep also on the readings as recorded
    hilbert: bool = True  # the reduced-rank GP on all readings of the training runs
    hilbert_tolerance: Share = 1e-4  # its basis' spectral tolerance (HilbertGP.fit's)
    # leave-one-run-out over the static runs on the reference sensor (gp_aalto_folds): the
    # held-out map's claims; their controls: "mean" (the training readings' mean everywhere),
    # "prior" (the predictive variance without the readings' shrinkage)
    folds: bool = True
    fold_model: str = "gp"
    fold_variance: str = "posterior"
    grid_resolution: Resolution = 0.1  # m, the pictures' grid
    # map change detection
    change_sigma: PositiveReal = 3.0  # a reading departs from the map beyond this many sigma
    change_factor: PositiveReal = 2.0  # changed: share above factor x the largest static share
    # magnetic-map MCL on the test run
    mcl_seeds: Runs = 5
    particles: Particles = 1000
    mcl_step: Spacing = 0.1  # m of travel between filter updates
    map_resolution: Resolution = 0.05  # m, the MCL's field map
    odometry_scale_sd: NonNegativeReal = 0.02  # SD of the per-run distance scale error
    heading_walk: NonNegativeReal = 0.1  # rad per sqrt(m): SD of the odometry heading's random walk
    # the MCL claims' control (gp_aalto_claims): each pose paired with the reading this many
    # updates later along the run (circularly)
    mcl_reading_lag: Lag = 0
    alphas: list[NonNegativeReal] = field(default_factory=lambda: [0.05, 0.1, 0.05, 0.01])
    # hand-held walks (3-D)
    walks: list[str] = field(default_factory=lambda: list(WALKS))
    walk_train_share: Share = 0.5  # the first part of a walk trains, the rest is predicted
    walk_offset_calibration: bool = True  # sensor-frame offset from the training part


def data_dir(config: GpAaltoConfig) -> Path:
    return shared_data("magnetic", config.data_dir)


def tasks(config: GpAaltoConfig) -> list[str]:
    """The trials, in order: the folds (one per static run), one map per sensor, change, mcl,
    walks. The folds come first, so that their controls run them alone."""
    out = [f"fold-{r}" for r in static_runs(config)] if config.folds else []
    out += [f"map-{s}" for s in config.sensors] + ["change", "mcl"]
    if config.walks:
        out.append("walks")
    return out


def _reference_sensor(config: GpAaltoConfig) -> str:
    """The sensor of the change detection and the MCL: the InvenSense (the Nexus' z axis
    drifts by +10 uT in run 5 and +40 uT in run 8), or the first one given."""
    return "invensense" if "invensense" in config.sensors else config.sensors[0]


def preflight(config: GpAaltoConfig) -> None:
    folder = data_dir(config)
    if not folder.is_dir():
        raise FileNotFoundError(
            f"gp-aalto: {folder}: no magnetic data folder (set data_dir to the folder holding "
            "aalto/ and kok_1d/)"
        )
    unknown = [s for s in config.sensors if s not in AALTO_SENSORS]
    if not config.sensors or unknown:
        raise ValueError(f"gp-aalto: sensors must be some of {', '.join(AALTO_SENSORS)}")
    runs = [*config.train_runs, config.test_run, *config.changed_runs]
    if len(config.train_runs) < 2 or len(set(runs)) != len(runs):
        raise ValueError("gp-aalto: need >= 2 train_runs, and no run in two roles")
    missing = [
        f"{s}/{r}-{part}.csv"
        for s in config.sensors
        for r in runs
        for part in ("loc", "mag", "time")
        if not (folder / "aalto" / s / f"{r}-{part}.csv").is_file()
    ]
    missing += [f"{w}.mat" for w in config.walks if not (folder / "kok_1d" / f"{w}.mat").is_file()]
    if missing:
        raise FileNotFoundError(f"gp-aalto: {folder}: missing {', '.join(missing[:6])}")
    if config.fold_model not in FOLD_MODELS or config.fold_variance not in FOLD_VARIANCES:
        raise ValueError(
            f"gp-aalto: fold_model must be one of {', '.join(FOLD_MODELS)}, fold_variance one "
            f"of {', '.join(FOLD_VARIANCES)}"
        )
    if not 0 < config.hilbert_tolerance < 1:
        raise ValueError("gp-aalto: hilbert_tolerance must lie in (0, 1)")
    if config.thinning < 1 or any(s < 1 for s in config.sweep):
        raise ValueError("gp-aalto: thinning and the sweep's steps must be >= 1")
    if not 0.1 <= config.walk_train_share <= 0.9:
        raise ValueError("gp-aalto: walk_train_share must lie in 0.1..0.9")
    if config.mcl_seeds < 1 or config.particles < 10 or config.mcl_step <= 0:
        raise ValueError("gp-aalto: need mcl_seeds >= 1, particles >= 10, mcl_step > 0")
    if len(config.alphas) != 4:
        raise ValueError("gp-aalto: alphas are the motion model's 4 noise parameters")
    positive = ("change_sigma", "change_factor", "grid_resolution", "map_resolution")
    bad = [name for name in positive if not getattr(config, name) > 0]
    bad += [n for n in ("odometry_scale_sd", "heading_walk") if not getattr(config, n) >= 0]
    if bad:
        raise ValueError(f"gp-aalto: {', '.join(bad)} must be > 0 (noise SDs >= 0)")


def trial(config: GpAaltoConfig, index: int, seed: int) -> TrialOutput:
    task = tasks(config)[index]
    folder = data_dir(config)
    timings: dict[str, float] = {}
    start = time.perf_counter()
    if task.startswith("fold-"):
        sensor = _reference_sensor(config)
        payload = fold_task(config, folder, sensor, int(task[5:]), timings)
    elif task.startswith("map-"):
        payload = work.map_task(config, folder, task[4:], timings)
    elif task == "change":
        payload = change_task(config, folder, _reference_sensor(config), timings)
    elif task == "mcl":
        payload = work.mcl_task(config, folder, _reference_sensor(config), seed, timings)
    else:
        payload = work.walks_task(config, folder, timings)
    timings[f"{task}_seconds"] = time.perf_counter() - start
    # one JSON column: the tasks' results differ in shape (parquet wants one type per column)
    return TrialOutput({"task": task, "payload": json.dumps(payload)}, timings)


EXPERIMENT = Experiment(
    name="gp-aalto",
    paper="002_74cea16d239c028f.txt",
    artefact="Ch. 6 on recorded data (Aalto robot runs, Kok-Solin walks)",
    description="GP magnetic maps of real runs: held-out RMSE and calibration, change "
    "detection, magnetic-map MCL, 3-D walks",
    config_type=GpAaltoConfig,
    trial=trial,
    analyze=analyze,
    default_runs=10,
    preflight=preflight,
    claims=FOLD_CLAIMS + CLAIMS,
    trial_count=lambda config: len(tasks(config)),
)
