# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Runs an experiment's trials in-process or on Dask (a local cluster or a user's scheduler),
writes every finished trial at once, resumes interrupted runs, and writes the results folder:
config.yaml, manifest.json, trials.parquet, timings.parquet, tables/*.csv, figures/*.png,
claims.csv, report.md; ``results/<name>/latest`` points at the newest run."""

from __future__ import annotations

import contextlib
import datetime as dt
import logging
import os
import socket
import time
import traceback
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any

import yaml
from pydantic import Field, RootModel
from tqdm import tqdm

from kiseki._support.atomic import atomic_write, check_writable_folder
from kiseki._support.replaced_files import refuse_replacing
from kiseki._support.schema import FileModel, SchemaError, Seed, parse
from kiseki._support.yaml import read_yaml_file
from kiseki.core import check_seed, derive_seed
from kiseki.errors import KisekiError
from kiseki_experiments.harness.config import (
    ConfigError,
    Runs,
    apply_overrides,
    config_from_dict,
    config_to_dict,
)
from kiseki_experiments.harness.manifest import build_manifest, git_state
from kiseki_experiments.harness.registry import get_experiment
from kiseki_experiments.harness.report import write_failed_outputs, write_outputs
from kiseki_experiments.harness.trials_log import TrialLog

__all__ = ["RunResult", "run_experiment", "run_trial"]


@dataclass(frozen=True)
class RunResult:
    run_dir: Path
    runs: int
    failed: int
    executed: int
    wall_seconds: float


def run_trial(name: str, config_values: dict[str, Any], index: int, seed: int) -> dict[str, Any]:
    """One trial, as a worker runs it: never raises; an error is recorded with the trial."""
    experiment = get_experiment(name)
    config = config_from_dict(experiment.config_type, config_values, experiment=name)
    start = time.perf_counter()
    entry: dict[str, Any] = {"trial": index, "seed": seed, "error": None, "record": {}}
    timings: dict[str, float] = {}
    try:
        output = experiment.trial(config, index, seed)
        entry["record"] = dict(output.record)
        timings = dict(output.timings)
    except Exception as err:  # the sweep goes on; the report counts failures
        last = traceback.extract_tb(err.__traceback__)[-1]
        entry["error"] = f"{type(err).__name__}: {err} ({Path(last.filename).name}:{last.lineno})"
    timings["trial_seconds"] = time.perf_counter() - start
    entry["timings"] = timings
    entry["worker"] = f"{socket.gethostname()}:{os.getpid()}"
    return entry


def _results_dir(name: str, root: Path) -> Path:
    stamp = dt.datetime.now().strftime("%Y%m%d-%H%M%S-%f")
    return root / name / stamp


def _link_latest(run_dir: Path) -> None:
    latest = run_dir.parent / "latest"
    tmp = run_dir.parent / f".latest-{os.getpid()}"
    tmp.unlink(missing_ok=True)
    tmp.symlink_to(run_dir.name, target_is_directory=True)
    os.replace(tmp, latest)


def _option(kind: Any, value: Any, flag: str) -> Any:
    """A command-line option checked by its config type: ``"--runs: must be ..., got X"``."""
    try:
        return parse(RootModel[kind], value, flag).root
    except SchemaError as err:
        raise ConfigError(str(err), err.errors) from None


class SavedRun(FileModel):
    """A run's config.yaml, as written when the run starts and read by ``--resume``: the
    experiment, the trials, the run seed and the experiment's config (checked by its own
    model once the experiment is known)."""

    experiment: Annotated[str, Field(strict=True)]
    runs: Runs
    seed: Seed
    config: dict[str, Any]


def _saved_run(run_dir: Path) -> SavedRun:
    path = run_dir / "config.yaml"
    if not path.is_file():
        raise KisekiError(f"{run_dir}: no config.yaml here: not a run that can be resumed")
    try:  # the shared reader: also refuses YAML nested too deeply for the parser
        saved = read_yaml_file(path, "run's config")
    except ValueError as err:
        raise KisekiError(str(err)) from None
    if not isinstance(saved, dict):
        raise KisekiError(f"{path}: not a run's config (a mapping), got {type(saved).__name__}")
    try:
        return parse(SavedRun, saved, path)
    except SchemaError as err:
        raise ConfigError(str(err), err.errors) from None


def _serial(jobs, name, values) -> Iterator[dict[str, Any]]:
    for index, seed in jobs:
        yield run_trial(name, values, index, seed)


@contextlib.contextmanager
def _dask_client(workers: int | None, scheduler: str | None):
    """A Dask client: on a user's scheduler, or on a local cluster of `workers` processes."""
    try:
        # here, not at the top: dask.distributed takes ~0.3 s to load; only parallel runs use it
        from dask.distributed import Client, LocalCluster
    except ImportError as err:
        raise KisekiError(
            "parallel runs need dask.distributed: pip install 'dask[distributed]'"
        ) from err
    if scheduler is not None:
        if not scheduler.startswith(("tcp://", "tls://", "inproc://", "ws://", "wss://")):
            raise KisekiError(
                f"scheduler address must look like tcp://HOST:PORT, got {scheduler!r}"
            )
        try:
            client = Client(scheduler, timeout="5s")
        except (OSError, TimeoutError) as err:
            raise KisekiError(f"cannot reach the Dask scheduler at {scheduler} ({err})") from err
        with client:
            yield client
        return
    cluster = LocalCluster(
        n_workers=workers,
        threads_per_worker=1,
        processes=True,
        dashboard_address=None,
        # CRITICAL, not ERROR: a worker's heartbeat that meets the scheduler already closed
        # while the cluster shuts down is logged as an ERROR with two tracebacks (once in a
        # 976-trial run, after its results were written); a trial's error and a lost worker
        # reach the run through their futures and are reported by kiseki itself
        silence_logs=logging.CRITICAL,
    )
    with cluster, Client(cluster) as client:
        yield client


def _on_dask(client, jobs, name, values) -> Iterator[dict[str, Any]]:
    # here, not at the top: only a parallel run loads dask.distributed (see _dask_client)
    from dask.distributed import as_completed

    futures = [client.submit(run_trial, name, values, i, s, pure=False) for i, s in jobs]
    for future in as_completed(futures):
        yield future.result()


def _extend(experiment, config, saved: SavedRun, runs: int, path: Path) -> None:
    """``--resume --runs N``: more trials for a run. A trial's seed depends only on the run's
    seed and the trial's index, so the run extended equals a fresh run of N trials; fewer than
    it holds would drop finished trials and is refused."""
    if runs < saved.runs:
        raise KisekiError(
            f"{path}: --resume --runs {runs} would drop trials: the run has {saved.runs} (give "
            f"at least {saved.runs}, or start a new run with another --out)"
        )
    settings = experiment.trial_count(config) if experiment.trial_count else None
    if settings is not None and runs > settings:
        raise ConfigError(
            f"{experiment.name}: its config has {settings} settings (one trial each), not {runs}"
        )
    text = yaml.safe_dump({**saved.model_dump(), "runs": runs}, sort_keys=False)
    atomic_write(path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))


# what a run writes in its folder besides trials.jsonl (report.write_outputs and _prepare)
RUN_FILES = (
    "config.yaml",
    "manifest.json",
    "trials.parquet",
    "timings.parquet",
    "tables",
    "figures",
    "claims.csv",
    "report.md",
)


def _prepare(name, runs, seed, overrides, out, resume, results_root):
    experiment = get_experiment(name)
    if resume:
        run_dir = Path(out) if out else results_root / name / "latest"
        saved = _saved_run(run_dir)
        check_writable_folder(run_dir, "results")
        if saved.experiment != name:
            raise KisekiError(f"{run_dir}: holds a run of {saved.experiment!r}, not {name!r}")
        if overrides or (seed is not None and seed != saved.seed):
            raise KisekiError("--resume continues a run as it was: drop --set and --seed")
        run_dir = run_dir.resolve()
        path = run_dir / "config.yaml"
        try:  # edited by hand since the run: the message names the file and the key
            config = config_from_dict(experiment.config_type, saved.config, path, ("config",), name)
        except (TypeError, ValueError) as err:  # the model's message names the file already
            text = str(err) if str(err).startswith(f"{path}: ") else f"{path}: {err}"
            raise ConfigError(text) from None
        if experiment.preflight is not None:
            experiment.preflight(config)
        if runs is not None and runs != saved.runs:
            _extend(experiment, config, saved, _option(Runs, runs, "--runs"), path)
            return experiment, run_dir, config, runs, saved.seed
        return experiment, run_dir, config, saved.runs, saved.seed
    config = apply_overrides(experiment.config_type(), list(overrides), name)
    settings = experiment.trial_count(config) if experiment.trial_count else None
    runs = (experiment.default_runs if settings is None else settings) if runs is None else runs
    runs = _option(Runs, runs, "--runs")
    if settings is not None and runs > settings:
        raise ConfigError(
            f"{name}: its config has {settings} settings (one trial each), not {runs}"
        )
    try:  # the one seed check, worded as every --seed
        seed = check_seed(0 if seed is None else seed, "--seed")
    except ValueError as err:
        raise ConfigError(str(err)) from None
    run_dir = Path(out) if out else _results_dir(name, results_root)
    if (run_dir / "trials.jsonl").exists():
        raise KisekiError(f"{run_dir}: already holds trials: use --resume or another --out")
    # --out . holding the user's own config.yaml or report.md: kept
    remedy = "give a new or empty folder (or --resume, to continue a run interrupted there)"
    refuse_replacing(run_dir, RUN_FILES, "--out", remedy, KisekiError)
    check_writable_folder(run_dir, "results")
    if experiment.preflight is not None:  # before the folder: a refused run leaves none
        experiment.preflight(config)
    run_dir.mkdir(parents=True, exist_ok=True)
    saved = {"experiment": name, "runs": runs, "seed": seed, "config": config_to_dict(config)}
    text = yaml.safe_dump(saved, sort_keys=False)
    atomic_write(run_dir / "config.yaml", lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))
    return experiment, run_dir.resolve(), config, runs, seed


def run_experiment(
    name: str,
    runs: int | None = None,
    seed: int | None = None,
    overrides: list[str] | tuple[str, ...] = (),
    workers: int | None = None,
    scheduler: str | None = None,
    out: str | os.PathLike | None = None,
    resume: bool = False,
    results_root: str | os.PathLike = "results",
    progress: bool = True,
) -> RunResult:
    """Runs (or resumes) an experiment and writes its results folder. A resumed run runs its
    missing and its failed trials. When every trial fails, the trials, the manifest and a
    report.md saying so are written and KisekiError names the first error."""
    if workers is not None and scheduler is not None:
        raise KisekiError("give --workers or --scheduler, not both")
    if workers is not None and workers < 1:
        raise ConfigError(f"--workers must be at least 1, got {workers}")
    parallel = workers is not None or scheduler is not None
    with _dask_client(workers, scheduler) if parallel else contextlib.nullcontext() as client:
        experiment, run_dir, config, runs, seed = _prepare(
            name, runs, seed, overrides, out, resume, Path(results_root)
        )
        git_at_start = git_state()  # the checkout the trials run from, not the one at the end
        log = TrialLog(run_dir / "trials.jsonl")
        done = log.read()
        # a resumed run also runs its failed trials again (after their cause was fixed)
        jobs = [
            (i, derive_seed(seed, i))
            for i in range(runs)
            if i not in done or done[i]["error"] is not None
        ]
        values = config_to_dict(config)
        start = time.perf_counter()
        if jobs:
            stream = (
                _on_dask(client, jobs, name, values) if parallel else _serial(jobs, name, values)
            )
            bar = tqdm(total=runs, initial=len(done), desc=name, unit="trial", disable=not progress)
            with bar:
                for entry in stream:
                    log.append(entry)
                    done[entry["trial"]] = entry
                    bar.update(1)
        wall = time.perf_counter() - start  # the trials only, not the cluster's start and stop
    trials, timings = TrialLog.frames(done)
    manifest = build_manifest(
        name, runs, seed, wall, workers, scheduler, len(jobs), trials, git_at_start
    )
    failed = int(trials["error"].notna().sum())
    if failed == len(trials):
        first = write_failed_outputs(experiment, trials, timings, manifest, run_dir)
        if run_dir.parent.name == name:
            _link_latest(run_dir)
        raise KisekiError(
            f"{name}: every one of its {runs} trials failed, first: {first}; trials and "
            f"report in {run_dir}; fix the cause, then run it again with --resume --out {run_dir}"
        )
    write_outputs(experiment, config, trials, timings, manifest, run_dir)
    if run_dir.parent.name == name:
        _link_latest(run_dir)
    return RunResult(run_dir, runs, failed, len(jobs), wall)
