# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What an experiment is: a typed config (defaults from the paper), a trial function (one
seeded trial -> a record), the claims it tests, declared before the run (criterion and control,
:mod:`.verdict`), and an analysis (records -> tables, figures, the evidence of each claim)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd

from kiseki_experiments.harness.verdict import ClaimSpec, Evidence

__all__ = ["Analysis", "ClaimSpec", "Evidence", "Experiment", "TrialOutput"]


@dataclass(frozen=True)
class TrialOutput:
    """A trial's result: ``record`` must depend only on the config and the seed (it goes to
    trials.parquet, compared between serial and parallel runs); ``timings`` holds wall times
    and other machine-dependent measurements (timings.parquet)."""

    record: dict[str, Any]
    timings: dict[str, float] = field(default_factory=dict)


@dataclass
class Analysis:
    """What an analysis produces from the records of all trials."""

    tables: dict[str, pd.DataFrame] = field(default_factory=dict)
    figures: list[Path] = field(default_factory=list)
    notes: str = ""
    evidence: list[Evidence] = field(default_factory=list)  # of the declared claims


@dataclass(frozen=True)
class Experiment:
    """A registered experiment. ``trial(config, index, seed)`` runs one trial;
    ``analyze(config, trials, timings, figures_dir)`` turns all records into an Analysis;
    ``preflight(config)`` checks inputs before any trial runs (raise with a clear message)."""

    name: str
    paper: str  # the paper's file name in the papers folder, or what the claims come from
    artefact: str  # "Table 4.5", "Fig. 3.14", ...
    description: str
    config_type: type
    trial: Callable[[Any, int, int], TrialOutput]
    analyze: Callable[[Any, pd.DataFrame, pd.DataFrame, Path], Analysis]
    default_runs: int = 10
    preflight: Callable[[Any], None] | None = None
    # For an experiment whose trials are the settings of its config (one trial per setting):
    # the number of trials a config has; the default --runs, and the most it accepts.
    trial_count: Callable[[Any], int] | None = None
    # The claims the experiment tests, each with its criterion and control (declared here,
    # before any run); the analysis gives their Evidence.
    claims: tuple[ClaimSpec, ...] = ()
    # Scene files (names in data/worlds) the experiment uses beyond those its default config
    # names: the calibration test reads their calibration marks against the claims.
    scenes: tuple[str, ...] = ()
