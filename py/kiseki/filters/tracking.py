# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Tracking a robot along a log with the engine (:func:`localize`), weighing with the sensor
models of :mod:`kiseki.filters.scan_models` (re-exported here).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
from tqdm import tqdm

from kiseki.core import derive_seed
from kiseki.filters.budget import BudgetChoice, CostModel, budgeted_config, calibrate
from kiseki.filters.engine import MonteCarloLocalizer
from kiseki.filters.localize_config import LOCALIZATION_METHODS, LocalizeConfig
from kiseki.filters.odometry_noise import motion_alphas, noisy_odometry
from kiseki.filters.reliability import (
    LearnedReliability,
    ReliabilityModel,
    learned_model,
)
from kiseki.filters.relocalization import RelocalizeConfig, Relocalizer
from kiseki.filters.scan_models import ScanSpaceObservation, scan_model, scan_preparer
from kiseki.grid import OccupancyGrid
from kiseki.scans import LaserScans, check_odometry_jumps

__all__ = [
    "LOCALIZATION_METHODS",
    "LocalizationResult",
    "LocalizeConfig",
    "ScanSpaceObservation",
    "localize",
    "scan_model",
    "scan_preparer",
]


@dataclass(frozen=True)
class LocalizationResult:
    estimates: np.ndarray  # (n, 3) estimated sensor pose after each scan
    reliability: np.ndarray  # (n,) the engine's reliability estimate after each scan
    particle_counts: np.ndarray  # (n,)
    updated: np.ndarray  # (n,) bool: a measurement update was made at this scan
    update_seconds: (
        np.ndarray
    )  # (updates,) wall time of each update (motion + weighing + resampling)
    resets: np.ndarray  # (n,) str: none, expansion or sensor
    # (n,) the engine's agreement-based estimate, whichever `reliability` holds
    agreement_reliability: np.ndarray
    # (n, 2) the learned estimate's features at each update (NaN elsewhere, and when
    # config.reliability is "agreement")
    reliability_features: np.ndarray
    config: LocalizeConfig = field(repr=False)
    # with config.budget_ms: what the budget chose, and the cost model it chose by
    budget: BudgetChoice | None = None
    cost_model: CostModel | None = None


def _check_scans(scans: LaserScans, grid: OccupancyGrid, config: LocalizeConfig) -> None:
    for name, value, kind, what in (
        ("scans", scans, LaserScans, "a LaserScans (a log's scans)"),
        ("grid", grid, OccupancyGrid, "a kiseki OccupancyGrid"),
        ("config", config, LocalizeConfig, "a LocalizeConfig"),
    ):
        if not isinstance(value, kind):  # None was an AttributeError from inside
            raise TypeError(f"localize: {name} must be {what}, got {type(value).__name__}")
    if len(scans) == 0:
        raise ValueError("the log has no scans")
    if scans.ranges.ndim != 2 or scans.ranges.shape[1] != scans.angles.shape[0]:
        raise ValueError(
            f"scans: {scans.ranges.shape[1] if scans.ranges.ndim == 2 else '?'} ranges per scan "
            f"but {scans.angles.shape[0]} beam angles"
        )
    if not np.isfinite(scans.odometry).all():
        raise ValueError("scans: the odometry has NaN or infinite poses")
    if not np.any(grid.cells == 0):
        raise ValueError("the map has no free cell (empty or all unknown): nothing to localize in")


def localize(
    scans: LaserScans,
    grid: OccupancyGrid,
    config: LocalizeConfig,
    progress: bool = False,
    reliability_model: ReliabilityModel | None = None,
    cost_model: CostModel | None = None,
) -> LocalizationResult:
    """Localization along a log: tracking from its first reference pose, or from a uniform start
    over the map's free cells with ``config.global_start``. Estimates are sensor poses. With
    ``config.budget_ms`` the particle and beam counts are chosen by ``cost_model``, calibrated
    here on this log when none is given (:mod:`kiseki.filters.budget`). The learned reliability
    estimates use ``reliability_model`` when given, else the coefficients their name stands
    for (:func:`kiseki.filters.reliability.learned_model`)."""
    _check_scans(scans, grid, config)
    odom = noisy_odometry(scans.odometry, config.odometry_noise, derive_seed(config.seed, 1))
    noise = f" with noise {config.odometry_noise:g}" if config.odometry_noise else ""
    check_odometry_jumps(f"the odometry{noise}", scans.times, odom)
    n = len(scans)
    if config.method == "odometry":
        return LocalizationResult(
            odom,
            np.full(n, np.nan),
            np.zeros(n, dtype=np.int64),
            np.zeros(n, dtype=bool),
            np.zeros(0),
            np.full(n, "none"),
            np.full(n, np.nan),
            np.full((n, 2), np.nan),
            config,
        )
    if not config.global_start and not np.isfinite(scans.poses[0]).all():
        raise ValueError("the log has no reference pose to start from: use a global start")
    alphas = motion_alphas(config, scans)
    budget, run = None, config
    if config.budget_ms is not None:
        cost_model = cost_model or calibrate(scans, grid, config, alphas)
        run, budget = budgeted_config(config, scans, cost_model)
    localizer = MonteCarloLocalizer(run.mcl(alphas), derive_seed(config.seed, 2), grid)
    if config.global_start:
        localizer.initialize_global()
    else:
        localizer.initialize(scans.poses[0], config.initial_sd)
    matcher = config.recovery == "resetting" and config.sensor_reset_proposal == "matcher"
    if matcher:  # scores with this config's likelihood-field terms, RelocalizeConfig's beams
        terms = dict(sigma_hit=config.sigma_hit, z_hit=config.z_hit, z_rand=config.z_rand)
        rc = RelocalizeConfig(**terms, threads=config.threads)
        localizer.set_matcher(Relocalizer(grid, scans.max_range, rc))
    prepare = scan_preparer(scan_model(config.method, grid, run), scans)
    model = reliability_model or learned_model(config.reliability)
    learned = None if config.reliability == "agreement" else LearnedReliability(model)
    estimates = np.empty((n, 3))
    reliability = np.empty(n)
    engine_reliability = np.empty(n)
    features = np.full((n, 2), np.nan)
    # the learned estimate before the first update: 1 from a known pose, 0 from a uniform start
    probability = 0.0 if config.global_start else 1.0
    counts = np.empty(n, dtype=np.int64)
    updated = np.zeros(n, dtype=bool)
    resets = np.full(n, "none", dtype=object)
    seconds: list[float] = []

    weighed_with: list = [None]  # the model holding the scan the last update weighed with

    def prepared(k: int):
        weighed_with[0] = prepare(k)
        return weighed_with[0]

    for k in tqdm(range(n), desc=config.method, unit="scan", disable=not progress):
        start = time.perf_counter()
        scan = (scans.angles, scans.ranges[k]) if matcher else None
        report = localizer.step(odom[k], lambda k=k: prepared(k), scan)
        if report is not None:
            seconds.append(time.perf_counter() - start)
            updated[k] = True
            resets[k] = report.reset
            if learned is not None:
                probability, features[k] = learned.update(
                    weighed_with[0], localizer.estimate, report.agreement
                )
        estimates[k] = localizer.estimate
        engine_reliability[k] = localizer.reliability
        reliability[k] = engine_reliability[k] if learned is None else probability
        counts[k] = localizer.size
    return LocalizationResult(
        estimates,
        reliability,
        counts,
        updated,
        np.asarray(seconds),
        resets.astype(str),
        engine_reliability,
        features,
        config,
        budget,
        cost_model if budget is not None else None,
    )
