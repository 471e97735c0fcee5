# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What an experiment is: a typed config (defaults from the paper), a trial function (one
seeded trial -> a record) and an analysis (records -> tables, figures, claims)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd

__all__ = ["Analysis", "Claim", "Experiment", "TrialOutput"]

CLAIM_COLUMNS = ["claim", "paper_value", "measured_value", "unit", "holds", "note"]


@dataclass(frozen=True)
class Claim:
    """One claim of a paper, the paper's value beside kiseki's, and whether it holds."""

    claim: str
    paper_value: str
    measured_value: str
    unit: str
    holds: bool
    note: str = ""


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
    claims: list[Claim] = field(default_factory=list)
    notes: str = ""


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
