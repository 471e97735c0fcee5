# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The experiment harness: one command per paper table or figure.

An experiment is a typed config, a trial function (one seeded trial -> a record) and an
analysis (records -> tables, figures, claims); ``run_experiment`` runs its trials in-process or
on Dask and writes a results folder; ``write_reproduction`` gathers every experiment's claims.
"""

from __future__ import annotations

from kiseki.experiments.base import Analysis, Claim, Experiment, TrialOutput
from kiseki.experiments.config import ConfigError, apply_overrides
from kiseki.experiments.registry import all_experiments, get_experiment
from kiseki.experiments.report import write_reproduction
from kiseki.experiments.runner import RunResult, run_experiment

__all__ = [
    "Analysis",
    "Claim",
    "ConfigError",
    "Experiment",
    "RunResult",
    "TrialOutput",
    "all_experiments",
    "apply_overrides",
    "get_experiment",
    "run_experiment",
    "write_reproduction",
]
