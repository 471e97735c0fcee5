# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Where the experiments' inputs are: the project's own scenes and maps (data/worlds,
data/maps), and the recorded data sets kept beside the project (../shared/data/<name>)."""

from __future__ import annotations

from pathlib import Path

__all__ = ["CARMEN_LOGS", "MAPS", "PROJECT", "WORLDS", "shared_data"]

PROJECT = Path(__file__).resolve().parents[3]
"""The kiseki checkout (py/kiseki_experiments/harness/paths.py is three folders below it)."""
WORLDS = PROJECT / "data" / "worlds"
"""The scene files of the simulated experiments."""
MAPS = PROJECT / "data" / "maps"
"""The maps the project keeps (ROS map YAML)."""
CARMEN_LOGS = ["intel-corrected", "aces-corrected", "csail-corrected", "freiburg-079-corrected"]
"""The CARMEN logs with SLAM-corrected poses in ../shared/data/carmen."""


def shared_data(name: str, given: str = "") -> Path:
    """The folder of a recorded data set: ``given`` when set (a config's ``data_dir``), else
    ``shared/data/<name>`` beside the project or beside the working directory, the first that
    exists (the one beside the project when neither does, so a message can name it)."""
    if given:
        return Path(given)
    for base in (PROJECT, Path.cwd()):
        candidate = base.parent / "shared" / "data" / name
        if candidate.is_dir():
            return candidate
    return PROJECT.parent / "shared" / "data" / name
