# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The sample MCAP run the run-log tests share (tests/python/io/test_sim_mcap*.py)."""

from __future__ import annotations

from pathlib import Path

import pytest

from _helpers.sim_mcap_sample import write_sample


@pytest.fixture
def sample(tmp_path: Path) -> Path:
    path = tmp_path / "run.mcap"
    write_sample(path)
    return path
