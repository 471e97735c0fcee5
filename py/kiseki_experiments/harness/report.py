# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Writes a run's outputs (parquet, tables, figures, claims, report.md, manifest) and the
project-wide REPRODUCTION.md that gathers the latest run of every experiment."""

from __future__ import annotations

import errno
import json
import math
import os
import shutil
import tempfile
from pathlib import Path
from typing import Any

import pandas as pd
from rich.console import Console

from kiseki._support.atomic import atomic_write, atomic_write_all, reworded
from kiseki._support.table import show
from kiseki._support.yaml import read_yaml_file
from kiseki_experiments.harness.base import Analysis, Experiment
from kiseki_experiments.harness.config import config_from_dict
from kiseki_experiments.harness.registry import all_experiments
from kiseki_experiments.harness.run_reader import read_latest, read_timings, trial_seconds
from kiseki_experiments.harness.verdict import UNMIGRATED, VERDICT_COLUMNS, judge

__all__ = [
    "claims_frame",
    "print_claims",
    "tally",
    "markdown_table",
    "write_failed_outputs",
    "write_outputs",
    "write_reproduction",
]


def _text(path: Path, text: str) -> None:
    atomic_write(path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))


def _cell(value: Any) -> str:
    if isinstance(value, float):
        return "" if math.isnan(value) else f"{value:.4g}"
    return str(value).replace("|", "\\|").replace("\n", " ")


def markdown_table(frame: pd.DataFrame) -> str:
    head = "| " + " | ".join(map(str, frame.columns)) + " |"
    rule = "|" + "---|" * len(frame.columns)
    rows = ["| " + " | ".join(_cell(v) for v in row) + " |" for row in frame.itertuples(False)]
    return "\n".join([head, rule, *rows])


def claims_frame(experiment: Experiment, analysis: Analysis, seed: int) -> pd.DataFrame:
    """Every claim's verdict row (:class:`~.verdict.Verdict`): the declared claims judged on
    their evidence with the run's seed."""
    rows = judge(experiment.claims, analysis.evidence, seed)
    return pd.DataFrame(
        [[getattr(r, k) for k in VERDICT_COLUMNS] for r in rows], columns=VERDICT_COLUMNS
    )


def tally(claims: pd.DataFrame) -> dict[str, int]:
    """Claims by verdict; ``decided`` = holds + fails (a point verdict of an old results folder
    is never decided)."""
    verdicts = claims["verdict"].astype(str)
    out = {k: int(verdicts.eq(k).sum()) for k in ("holds", "fails", "inconclusive")}
    out["not_migrated"] = int(verdicts.eq(UNMIGRATED).sum())
    out["claims"] = len(claims)
    out["decided"] = out["holds"] + out["fails"]
    return out


def tally_text(t: dict[str, int]) -> str:
    share = f"{100 * t['decided'] / t['claims']:.0f} %" if t["claims"] else "none"
    return (
        f"{t['claims']} claims: {t['holds']} hold, {t['fails']} fail, {t['inconclusive']} "
        f"inconclusive, {t['not_migrated']} not yet migrated (no interval); decided: {share}"
    )


def _shown(claims: pd.DataFrame) -> pd.DataFrame:
    """The claims as the reports show them: kiseki's value with its 95 % interval."""

    def kiseki(row) -> str:
        lo, hi = float(row.ci_low), float(row.ci_high)
        ci = "" if math.isnan(lo) or math.isnan(hi) else f" [{lo:.4g}, {hi:.4g}]"
        return f"{row.measured_value}{ci}"

    frame = pd.DataFrame(
        {
            "claim": claims["claim"],
            "paper": claims["paper_value"],
            "kiseki [95 % CI]": [kiseki(r) for r in claims.itertuples(False)],
            "unit": claims["unit"],
            "criterion": claims["criterion"],
            "verdict": claims["verdict"],
            "trials": claims["trials"],
            "control": claims["control"],
            "note": claims["note"],
        }
    )
    return frame


def duration_text(seconds: float) -> str:
    """A duration as people read it: hours from one hour on, else minutes, else seconds."""
    if math.isnan(seconds):
        return ""
    if seconds >= 3600:
        return f"{seconds / 3600:.2f} h"
    return f"{seconds / 60:.0f} min" if seconds >= 60 else f"{seconds:.0f} s"


def time_text(seconds: float, runs: int, untimed: int, cores: int = 2) -> str:
    """The sentence on how long the runs' trials took: summed (one core) and spread evenly over
    `cores` (the lower bound of a run's wall time on that many cores)."""
    which = "this run" if runs == 1 else f"these {runs} runs"
    text = (
        f"the trials of {which} took {duration_text(seconds)} on one core, "
        f"{duration_text(seconds / cores)} on {cores} cores if spread evenly"
    )
    return text + (f" ({untimed} runs without timings not counted)" if untimed else "")


def _mean_trial_seconds(timings: pd.DataFrame | None) -> float:
    if timings is None or "trial_seconds" not in timings:
        return math.nan
    return float(pd.to_numeric(timings["trial_seconds"], errors="coerce").mean())


def _undecided(
    claims: pd.DataFrame, runs: int, timings: pd.DataFrame | None, settings: int | None = None
) -> list[str]:
    """For each inconclusive claim: the trials that would decide it (verdict.trials_to_decide)
    and their wall time at the run's mean trial time (one core). ``settings``: the most trials
    the run's config has (an experiment whose trials are its settings, as leave-one-out cases);
    a claim that would need more is priced with that said: --runs cannot ask for them, a config
    with more repeats (or data with more cases) can."""
    rows = claims[claims["verdict"].astype(str).eq("inconclusive")]
    if rows.empty:
        return []
    per_trial = _mean_trial_seconds(timings)
    lines = [
        "",
        "### Undecided claims",
        "",
        "| claim | trials now | trials that would decide it | run trials | wall time (1 core) |",
        "|---|---|---|---|---|",
    ]
    for row in rows.itertuples(False):
        need, n = float(row.trials_to_decide), int(row.trials)
        if math.isnan(need) or n == 0:
            lines.append(f"| {_cell(row.claim)} | {n} | none (on the threshold) | | |")
            continue
        run_trials = math.ceil(need * runs / n)  # a claim may take k of the run's trials
        shown = str(run_trials)
        if settings is not None and run_trials > settings:  # --runs cannot ask for them
            shown += (
                f" (more than the {settings} settings of this config, one trial each: a "
                "config with more repeats or cases)"
            )
        wall = run_trials * per_trial
        when = (
            "" if math.isnan(wall) else f"{wall / 3600:.2f} h" if wall > 3600 else f"{wall:.0f} s"
        )
        lines.append(f"| {_cell(row.claim)} | {n} | {int(need)} | {shown} | {when} |")
    return lines


def trial_settings(experiment: Experiment, config: Any) -> int | None:
    """The most trials ``config`` has when the experiment's trials are its settings, else None."""
    return None if experiment.trial_count is None else int(experiment.trial_count(config))


def _saved_settings(experiment: Experiment, run_dir: Path) -> int | None:
    """trial_settings of the config saved with a run; None when it cannot be read (the report
    then gives the trials that would decide a claim without that bound)."""
    if experiment.trial_count is None:
        return None
    path = run_dir / "config.yaml"
    try:
        saved = read_yaml_file(path, "run's config")
        config = config_from_dict(experiment.config_type, saved["config"], str(path), ("config",))
    except (OSError, ValueError, TypeError, KeyError):
        return None
    return trial_settings(experiment, config)


def _report(
    experiment, analysis, manifest, claims: pd.DataFrame, timings=None, settings=None
) -> str:
    lines = [
        f"# {experiment.name}: {experiment.description}",
        "",
        f"Source: `{experiment.paper}`, {experiment.artefact}.  ",
        f"Run: {manifest['finished']}, {manifest['trials']} trials "
        f"({manifest['trials_failed']} failed), seed {manifest['seed']}, "
        f"{manifest['execution']}, commit {manifest['git']['commit'] or 'unknown'}"
        f"{' (with local changes)' if manifest['git']['dirty'] else ''}.",
        "",
        f"## Claims: {tally_text(tally(claims))}",
        "",
        "Each claim's criterion was declared before the run; the interval is 95 % (percentile "
        "bootstrap over trials, Wilson for a share); inconclusive: the interval straddles the "
        "criterion.",
        "",
        markdown_table(_shown(claims)),
        *_undecided(claims, int(manifest["trials"]), timings, settings),
    ]
    for name, table in analysis.tables.items():
        lines += ["", f"## {name}", "", markdown_table(table)]
    if analysis.figures:
        lines += ["", "## Figures", ""]
        lines += [f"![{p.stem}](figures/{p.name})" for p in analysis.figures]
    if analysis.notes:
        lines += ["", "## Notes", "", analysis.notes.strip()]
    return "\n".join(lines) + "\n"


def print_claims(title: str, claims: pd.DataFrame) -> None:
    """The claims as a table on a terminal, tab-separated lines when piped."""
    shown = _shown(claims)
    columns = ["claim", "paper", "kiseki [95 % CI]", "unit", "verdict"]
    rows = [tuple(str(v) for v in r) for r in shown[columns].itertuples(False)]
    show(title, columns, rows, as_json=False, data=None)


def _frames(trials, timings, run_dir: Path) -> list:
    return [
        (run_dir / "trials.parquet", lambda tmp: trials.to_parquet(tmp, index=False)),
        (run_dir / "timings.parquet", lambda tmp: timings.to_parquet(tmp, index=False)),
    ]


def _texts(items: dict[Path, str]) -> list:
    return [
        (path, lambda tmp, text=text: Path(tmp).write_text(text, encoding="utf-8"))
        for path, text in items.items()
    ]


def _write_frames(trials, timings, run_dir: Path) -> None:
    atomic_write_all(_frames(trials, timings, run_dir))


def write_failed_outputs(experiment, trials, timings, manifest, run_dir: Path) -> str:
    """A run whose every trial failed: the trials with their errors, the manifest and a
    report.md saying so and giving the first error; no claims (nothing to analyse). Returns
    the first error."""
    _write_frames(trials, timings, run_dir)
    (run_dir / "claims.csv").unlink(missing_ok=True)
    first = " ".join(str(trials["error"].iloc[0]).split())  # one line
    lines = [
        f"# {experiment.name}: {experiment.description}",
        "",
        f"Run: {manifest['finished']}, seed {manifest['seed']}, {manifest['execution']}.",
        "",
        f"**Every trial failed** ({manifest['trials']} of {manifest['trials']}): no claims.",
        "",
        f"First error (trial {int(trials['trial'].iloc[0])}): `{first}`",
        "",
        "Fix the cause, then `kiseki experiment run "
        f"{experiment.name} --resume --out {run_dir}` runs the failed trials again.",
    ]
    _text(run_dir / "report.md", "\n".join(lines) + "\n")
    _text(run_dir / "manifest.json", json.dumps(manifest, indent=2))
    return first


def _results_error(err: OSError, experiment: Experiment, run_dir: Path) -> OSError:
    """A failure to write the results, naming the file (or the run) and what is kept."""
    reason = err.strerror or str(err)
    where = f"{err.filename}: {reason}" if err.filename else reason
    if str(run_dir) not in where:
        where = f"{run_dir}: {where}"
    return reworded(
        err,
        f"{where}; the finished trials are kept in trials.jsonl (kiseki experiment run "
        f"{experiment.name} --resume --out {run_dir} writes the results once this is fixed)",
    )


def _drawing_error(err: OSError, drawn: Path) -> bool:
    """Whether an OSError of the analysis is one of drawing its figures into ``drawn`` (a
    full disk), not of reading its inputs."""
    if err.errno in (errno.ENOSPC, errno.EDQUOT, errno.EROFS, errno.EFBIG):
        return True
    name = os.fsdecode(err.filename) if isinstance(err.filename, str | bytes) else ""
    return bool(name) and Path(name).absolute().is_relative_to(drawn.absolute())


def write_outputs(experiment, config, trials, timings, manifest, run_dir: Path) -> pd.DataFrame:
    """Writes every output to a temporary name (figures to a hidden folder) and moves them
    into place once all are complete: a failure part-way (a full disk) leaves the previous
    outputs as they were and nothing half-written. An OSError of writing or moving them says
    the trials are kept, as does one of drawing the figures; any other raised by the
    experiment's analysis (a missing input) is raised as it is."""
    for stale in run_dir.glob(".figures.*"):  # left by a run killed while drawing
        shutil.rmtree(stale, ignore_errors=True)
    (run_dir / "tables").mkdir(exist_ok=True)
    (run_dir / "figures").mkdir(exist_ok=True)
    drawn = Path(tempfile.mkdtemp(dir=run_dir, prefix=".figures."))
    try:
        try:
            analysis = experiment.analyze(config, trials, timings, drawn)
        except OSError as err:
            if not _drawing_error(err, drawn):
                raise  # the analysis's own (a missing input file): as it is
            raise _results_error(err, experiment, run_dir) from err
        claims = claims_frame(experiment, analysis, int(manifest["seed"]))
        texts = {
            run_dir / "tables" / f"{n}.csv": t.to_csv(index=False)
            for n, t in analysis.tables.items()
        }
        texts[run_dir / "claims.csv"] = claims.to_csv(index=False)
        settings = trial_settings(experiment, config)
        texts[run_dir / "report.md"] = _report(
            experiment, analysis, manifest, claims, timings, settings
        )
        texts[run_dir / "manifest.json"] = json.dumps(manifest, indent=2)
        try:
            atomic_write_all(_frames(trials, timings, run_dir) + _texts(texts))
            for path in sorted(p for p in drawn.rglob("*") if p.is_file()):
                target = run_dir / "figures" / path.relative_to(drawn)
                target.parent.mkdir(parents=True, exist_ok=True)
                os.replace(path, target)
        except OSError as err:
            raise _results_error(err, experiment, run_dir) from err
    finally:
        shutil.rmtree(drawn, ignore_errors=True)
    print_claims(f"{experiment.name}: claims ({run_dir})", claims)
    if manifest["trials_failed"]:
        Console().print(
            f"[red]{manifest['trials_failed']} of {manifest['trials']} trials failed[/red]"
        )
    return claims


def write_reproduction(results_root: Path, out: Path) -> tuple[dict[str, int], list[str]]:
    """Gathers the latest run of every registered experiment into one markdown file: each
    claim with the paper's value, kiseki's with its interval and the verdict, the undecided
    claims with the trials that would decide them, and the share of claims decided. Returns
    (the tally of verdicts, :func:`tally`; the missing experiment names)."""
    if not results_root.is_dir():
        raise FileNotFoundError(f"{results_root}: results folder not found")
    by_paper: dict[str, list[str]] = {}
    frames: list[pd.DataFrame] = []
    missing: list[str] = []
    seconds: list[float] = []
    for name, experiment in sorted(all_experiments().items()):
        section = by_paper.setdefault(experiment.paper, [])
        found = read_latest(results_root, name)
        section += ["", f"### {name} ({experiment.artefact}): {experiment.description}", ""]
        if found is None:
            missing.append(name)
            section.append(f"**missing**: no result yet; run `kiseki experiment run {name}`.")
            continue
        latest, claims, manifest = found
        run_dir = latest.resolve()
        frames.append(claims)
        timings = read_timings(latest)
        seconds.append(trial_seconds(timings))
        section += [
            f"Result: `{run_dir.relative_to(results_root.resolve())}`, "
            f"{manifest['trials']} trials, {manifest['trials_failed']} failed, "
            f"commit {manifest['git']['commit'] or 'unknown'}; {tally_text(tally(claims))}.",
            "",
            markdown_table(_shown(claims)),
            *_undecided(
                claims, int(manifest["trials"]), timings, _saved_settings(experiment, run_dir)
            ),
        ]
    empty = pd.DataFrame({"verdict": pd.Series([], dtype=str)})
    totals = tally(pd.concat(frames, ignore_index=True) if frames else empty)
    timed = [x for x in seconds if not math.isnan(x)]
    spent = time_text(sum(timed), len(seconds), len(seconds) - len(timed))
    lines = ["# Reproduction report", "", f"{tally_text(totals)}; {spent}."]
    if missing:
        lines.append(f"Missing experiments ({len(missing)}): {', '.join(missing)}.")
    for paper, section in by_paper.items():
        lines += ["", f"## {paper}", *section]
    _text(out, "\n".join(lines) + "\n")
    return totals, missing
