# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The Monte Carlo engine as Python drives it: its config and the filter (`engine`), tracking
along a log with the scan sensor models (`tracking`), and localization from a uniform start
(`global_localization`, with its convergence report in `convergence`), a time budget per
update (`budget`), the reliability
estimate (`reliability`), and relocalization from one scan by branch-and-bound correlative
matching (`relocalization`). The engine itself, its motion models, resampling, KLD sampling and
recovery are C++ (``kiseki._core``).

``from kiseki.filters import MclConfig, localize, global_localize`` is the one import path."""

from __future__ import annotations

from kiseki.filters.budget import (
    BudgetChoice,
    CostModel,
    budgeted_config,
    calibrate,
    choose_counts,
)
from kiseki.filters.convergence import (
    ConvergenceReport,
    ScanFit,
    convergence_report,
    describe,
    scan_fit,
    spread_radius,
)
from kiseki.filters.engine import (
    REAL_ODOMETRY_ALPHAS,
    RECOVERY_MODES,
    RESAMPLING_METHODS,
    RESET_PROPOSALS,
    MclConfig,
    MonteCarloLocalizer,
)
from kiseki.filters.global_localization import (
    GlobalConfig,
    GlobalResult,
    global_localize,
    render_global,
    write_report,
)
from kiseki.filters.odometry_noise import motion_alphas, noisy_odometry
from kiseki.filters.reliability import (
    LEARNED_RELIABILITY,
    REAL_LOG_RELIABILITY,
    RELIABILITY_ESTIMATES,
    LearnedReliability,
    ReliabilityModel,
)
from kiseki.filters.relocalization import (
    Hypothesis,
    RelocalizeConfig,
    Relocalizer,
    SearchDisc,
    hypothesis_cloud,
    relocalize,
    render_hypotheses,
)
from kiseki.filters.tracking import (
    LOCALIZATION_METHODS,
    LocalizationResult,
    LocalizeConfig,
    ScanSpaceObservation,
    localize,
    scan_model,
    scan_preparer,
)

__all__ = [
    "LEARNED_RELIABILITY",
    "REAL_LOG_RELIABILITY",
    "LOCALIZATION_METHODS",
    "REAL_ODOMETRY_ALPHAS",
    "RECOVERY_MODES",
    "RELIABILITY_ESTIMATES",
    "RESAMPLING_METHODS",
    "RESET_PROPOSALS",
    "BudgetChoice",
    "ConvergenceReport",
    "CostModel",
    "GlobalConfig",
    "GlobalResult",
    "Hypothesis",
    "LocalizationResult",
    "LearnedReliability",
    "LocalizeConfig",
    "MclConfig",
    "MonteCarloLocalizer",
    "ReliabilityModel",
    "RelocalizeConfig",
    "Relocalizer",
    "ScanFit",
    "ScanSpaceObservation",
    "SearchDisc",
    "budgeted_config",
    "calibrate",
    "choose_counts",
    "convergence_report",
    "describe",
    "global_localize",
    "hypothesis_cloud",
    "localize",
    "motion_alphas",
    "noisy_odometry",
    "relocalize",
    "render_global",
    "render_hypotheses",
    "scan_fit",
    "scan_preparer",
    "scan_model",
    "spread_radius",
    "write_report",
]
