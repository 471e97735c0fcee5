# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""manifest.json: what produced a result (commit, package versions, seed, machine)."""

from __future__ import annotations

import datetime as dt
import importlib.metadata
import os
import platform
import subprocess
from typing import Any

import pandas as pd

from kiseki.core import library_versions
from kiseki_experiments.harness.paths import PROJECT

__all__ = ["build_manifest", "git_state"]

PACKAGES = ("numpy", "pandas", "pyarrow", "dask", "distributed", "matplotlib", "pybind11")


def git_state() -> dict[str, Any]:
    """The commit of the kiseki checkout in use, and whether it had local changes."""
    root = PROJECT
    try:
        commit = subprocess.run(
            ["git", "-C", str(root), "rev-parse", "HEAD"],
            capture_output=True,
            text=True,
            timeout=10,
        )
        status = subprocess.run(
            ["git", "-C", str(root), "status", "--porcelain", "--untracked-files=no"],
            capture_output=True,
            text=True,
            timeout=10,
        )
    except (OSError, subprocess.TimeoutExpired):
        return {"commit": None, "dirty": None}
    if commit.returncode != 0:
        return {"commit": None, "dirty": None}
    return {"commit": commit.stdout.strip(), "dirty": bool(status.stdout.strip())}


def _versions() -> dict[str, str]:
    out = {f"cpp:{k}": v for k, v in library_versions().items()}
    for name in PACKAGES:
        try:
            out[name] = importlib.metadata.version(name)
        except importlib.metadata.PackageNotFoundError:
            continue
    out["python"] = platform.python_version()
    return out


def build_manifest(
    name: str,
    runs: int,
    seed: int,
    wall_seconds: float,
    workers: int | None,
    scheduler: str | None,
    executed: int,
    trials: pd.DataFrame,
    git_at_start: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """The run's manifest. ``git`` is the checkout the trials ran from: its state when they
    started (``git_at_start``); when the checkout moved while they ran, it is marked dirty and
    ``changed_during_run`` holds the state at the end."""
    git = dict(git_at_start) if git_at_start is not None else git_state()
    if git_at_start is not None:
        at_end = git_state()
        if at_end != git_at_start:
            git["dirty"] = True
            git["changed_during_run"] = at_end
    return {
        "experiment": name,
        "finished": dt.datetime.now(dt.timezone.utc).isoformat(timespec="seconds"),
        "git": git,
        "versions": _versions(),
        "seed": seed,
        "trials": runs,
        "trials_executed_now": executed,
        "trials_failed": int(trials["error"].notna().sum()),
        "wall_seconds": round(wall_seconds, 3),
        "execution": (
            f"dask scheduler {scheduler}"
            if scheduler
            else (f"dask LocalCluster, {workers} workers" if workers else "in-process")
        ),
        "machine": {
            "hostname": platform.node(),
            "platform": platform.platform(),
            "processor": platform.processor() or platform.machine(),
            "cpus": os.cpu_count(),
        },
    }
