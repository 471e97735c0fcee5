# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Reads a finished run back: the run of an experiment the report reads (its ``latest`` link,
or a run folder itself), its claims table and its manifest, each refused in one line naming the
file when unreadable. The report (REPRODUCTION.md) and the README's tables read runs here."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pandas as pd

from kiseki._support.inputs import CSV_LIMIT, YAML_LIMIT, check_input, read_input_text
from kiseki_experiments.harness.verdict import UNMIGRATED, VERDICT_COLUMNS

__all__ = ["latest_run", "read_latest", "read_result", "read_timings", "trial_seconds"]


def latest_run(results_root: Path, name: str) -> Path | None:
    """The run of ``name`` the report reads: ``results_root/name/latest`` (the runner's link),
    else ``results_root/name`` itself when it is a run (``run 'PATTERN' --out``'s layout); None
    when neither holds a claims table."""
    for folder in (results_root / name / "latest", results_root / name):
        if (folder / "claims.csv").is_file():
            return folder
    return None


def read_latest(results_root: Path, name: str) -> tuple[Path, pd.DataFrame, dict] | None:
    """The run of ``name`` the report reads (:func:`latest_run`) with its claims and manifest
    (:func:`read_result`), or None when there is none. A ``latest`` link that leads outside
    ``results_root`` (moved or made by hand) is refused in one line."""
    latest = latest_run(results_root, name)
    if latest is None:
        return None
    run_dir = latest.resolve()
    if not run_dir.is_relative_to(results_root.resolve()):
        raise ValueError(f"{latest}: the link points outside --results ({run_dir})")
    claims, manifest = read_result(latest)
    return latest, claims, manifest


def read_timings(latest: Path) -> pd.DataFrame | None:
    """A run's timings.parquet (one row a trial), None when the run has none; refused in one
    line naming the file when unreadable."""
    path = latest / "timings.parquet"
    if not path.is_file():
        return None
    try:
        return pd.read_parquet(path)
    except (OSError, ValueError) as err:
        raise ValueError(f"{path}: not a timings table ({err})") from None


def trial_seconds(timings: pd.DataFrame | None) -> float:
    """The run's trials' time summed (s, as if run one after another on one core); nan when the
    run has no timings."""
    if timings is None or "trial_seconds" not in timings:
        return math.nan
    return float(pd.to_numeric(timings["trial_seconds"], errors="coerce").sum())


def read_result(latest: Path) -> tuple[pd.DataFrame, dict]:
    """A run's claims.csv and manifest.json, refused in one line naming the file when unreadable
    or without the columns and fields the report needs. A claims table of the old form (a
    column ``holds``, no interval) is read as not yet migrated."""
    claims_path, manifest_path = latest / "claims.csv", latest / "manifest.json"
    check_input(claims_path, "claims tables", CSV_LIMIT)
    try:
        claims = pd.read_csv(claims_path, keep_default_na=False)
    except (ValueError, UnicodeDecodeError) as err:
        raise ValueError(f"{claims_path}: not a claims table ({err})") from None
    if "verdict" not in claims.columns and {"claim", "holds"} <= set(claims.columns):
        claims = _old_claims(claims)
    lacking = [c for c in VERDICT_COLUMNS if c not in claims.columns]
    if lacking:
        raise ValueError(
            f"{claims_path}: no column {lacking[0]} (a claims table has "
            f"{', '.join(VERDICT_COLUMNS)})"
        )
    for column in ("ci_low", "ci_high", "trials_to_decide"):
        claims[column] = pd.to_numeric(claims[column], errors="coerce")
    _check_claims(claims_path, claims)
    try:
        manifest = json.loads(read_input_text(manifest_path, "JSON manifests", YAML_LIMIT))
    except (ValueError, UnicodeDecodeError) as err:
        raise ValueError(f"{manifest_path}: not a JSON manifest ({err})") from None
    needed = ("trials", "trials_failed", "git")
    if not isinstance(manifest, dict) or any(k not in manifest for k in needed):
        raise ValueError(f"{manifest_path}: a manifest needs the fields {', '.join(needed)}")
    _check_manifest(manifest_path, manifest)
    return claims, manifest


def _count(value) -> bool:
    return isinstance(value, int) and not isinstance(value, bool) and 0 <= value <= 10**9


def _check_manifest(path: Path, manifest: dict) -> None:
    """The fields the report prints, of their kinds: a hand-edited ``git: null`` or
    ``trials: "many"`` gave a traceback, ``trials: -5`` was printed."""
    trials, failed, git = manifest["trials"], manifest["trials_failed"], manifest["git"]
    if not _count(trials) or not _count(failed) or failed > trials:
        raise ValueError(
            f"{path}: trials and trials_failed must be counts with trials_failed <= trials, "
            f"got {trials!r} and {failed!r}"
        )
    if (
        not isinstance(git, dict)
        or not isinstance(git.get("commit"), str | None)
        or not isinstance(git.get("dirty"), bool | None)
    ):  # both null: the run had no git checkout (manifest.git_state)
        raise ValueError(
            f"{path}: git must hold commit (text or null) and dirty (true, false or null), "
            f"got {git!r}"
        )


def _check_claims(path: Path, claims: pd.DataFrame) -> None:
    """Each claim's verdict is one the report counts, its trials a count and its interval, when
    it has one, finite: a verdict of "maybe" was counted as nothing at all."""
    known = {"holds", "fails", "inconclusive", UNMIGRATED}
    for row, verdict in enumerate(claims["verdict"], start=2):
        if verdict not in known:
            raise ValueError(
                f"{path} row {row}: verdict must be one of {', '.join(sorted(known))}, "
                f"got {verdict!r}"
            )
    trials = pd.to_numeric(claims["trials"], errors="coerce")
    bad = ~((trials >= 0) & (trials == trials.round()))
    for column in ("ci_low", "ci_high"):
        bad |= claims[column].isin([math.inf, -math.inf])
    if bad.any():
        row = int(bad.to_numpy().argmax())
        raise ValueError(
            f"{path} row {row + 2}: trials must be a count and the interval finite (or empty), "
            f"got trials {claims['trials'].iloc[row]!r}, interval "
            f"[{claims['ci_low'].iloc[row]}, {claims['ci_high'].iloc[row]}]"
        )


def _old_claims(claims: pd.DataFrame) -> pd.DataFrame:
    """A claims table written before verdicts had intervals: every row not yet migrated."""
    rows = []
    for row in claims.to_dict("records"):
        holds = str(row.get("holds", "")).lower() == "true"
        rows.append(
            {
                **{c: "" for c in VERDICT_COLUMNS},
                "claim": row.get("claim", ""),
                "paper_value": row.get("paper_value", ""),
                "measured_value": row.get("measured_value", ""),
                "unit": row.get("unit", ""),
                "ci_low": math.nan,
                "ci_high": math.nan,
                "trials": 0,
                "trials_to_decide": math.nan,
                "verdict": UNMIGRATED,
                "note": f"point verdict without an interval: {'holds' if holds else 'fails'}",
                "holds": holds,
            }
        )
    return pd.DataFrame(rows, columns=VERDICT_COLUMNS)
