# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Experiment runs as the harness' tests read them: the command line in a subprocess and a
run's trial records."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pandas as pd


def cli(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "kiseki.cli", *args], cwd=cwd, capture_output=True, text=True
    )


def frame(run_dir: Path) -> pd.DataFrame:
    return pd.read_parquet(run_dir / "trials.parquet")
