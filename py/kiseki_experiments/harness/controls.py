# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Negative controls: every declared claim names a config override under which its criterion
must fail (:class:`~.verdict.Control`). This runs an experiment under a control at the
control's trial count and says what is wrong when the claim's verdict there is not ``fails``
(``holds``: the control leaves what the claim is about in place; ``inconclusive``: too few
trials to show the failure)."""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path

import pandas as pd

from kiseki_experiments.harness.registry import get_experiment
from kiseki_experiments.harness.runner import run_experiment
from kiseki_experiments.harness.verdict import ClaimSpec, Control

__all__ = ["control_groups", "control_problems", "rows_of", "run_control"]


def rows_of(claims: pd.DataFrame, spec: ClaimSpec) -> pd.DataFrame:
    """The rows of claims.csv that judge ``spec`` (one, or one per subject: "claim [log]")."""
    text = claims["claim"].astype(str)
    return claims[text.eq(spec.claim) | text.str.startswith(spec.claim + " [")]


def run_control(name: str, control: Control, out: Path) -> pd.DataFrame:
    """The claims.csv of ``name`` run under ``control`` (its overrides, its trials, seed 0)."""
    result = run_experiment(
        name, runs=control.runs, overrides=list(control.overrides), out=out, progress=False
    )
    return pd.read_csv(result.run_dir / "claims.csv", keep_default_na=False)


def control_problems(claims: pd.DataFrame, spec: ClaimSpec) -> list[str]:
    """What is wrong with ``spec``'s control, given the claims.csv of a run under it: each of
    the claim's rows must fail; a row that holds or is inconclusive makes the control too weak
    (or too small), and a claim without rows was not judged at all."""
    control = spec.control
    if control is None:
        return [f"{spec.key}: no control (a claim no control can fail is a table row)"]
    rows = rows_of(claims, spec)
    if rows.empty:
        return [f"{spec.key}: not judged under control {control.name!r}"]
    return [
        f"{spec.key}: under control {control.name!r} ({', '.join(control.overrides)}; "
        f"{control.runs} trials) the verdict is {row.verdict}, not fails "
        f"(kiseki {row.measured_value}, interval [{row.ci_low}, {row.ci_high}])"
        for row in rows.itertuples(False)
        if row.verdict != "fails"
    ]


def control_groups(name: str) -> dict[Control, list[ClaimSpec]]:
    """An experiment's claims by control: claims that share a control share one run of it."""
    groups: dict[Control, list[ClaimSpec]] = defaultdict(list)
    for spec in get_experiment(name).claims:
        if spec.control is not None:
            groups[spec.control].append(spec)
    return dict(groups)
