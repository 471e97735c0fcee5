# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Localization along a real log: the likelihood-field baseline against dead reckoning, the
odometry noise model, determinism and bad input."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from kiseki.datasets import read_carmen_log
from kiseki.localization import LocalizeConfig, localize, noisy_odometry
from kiseki.mapping import build_map
from kiseki.metrics import ape


def test_noisy_odometry_has_the_requested_spread():
    steps = np.column_stack([np.arange(2001) * 0.1, np.zeros(2001), np.zeros(2001)])
    clean = noisy_odometry(steps, 0.0, seed=1)
    np.testing.assert_allclose(clean, steps, atol=1e-12)
    noisy = noisy_odometry(steps, 0.1, seed=1)
    forward = np.diff(noisy[:, 0])  # headings stay 0: only the x increments carry noise
    assert abs(forward.std() / (0.1 * 0.1) - 1) < 0.1 and abs(forward.mean() - 0.1) < 0.002
    assert np.array_equal(noisy, noisy_odometry(steps, 0.1, seed=1))


def test_likelihood_field_tracks_the_intel_log_far_better_than_odometry(shared_data):
    scans = read_carmen_log(shared_data / "carmen" / "intel-corrected.log.gz").scans
    grid = build_map(scans.poses, scans.ranges, scans.angles, scans.max_range)
    odometry = localize(scans, grid, LocalizeConfig(method="odometry", odometry_noise=0.1))
    tracked = localize(scans, grid, LocalizeConfig(method="likelihood-field", odometry_noise=0.1))
    odo, lf = ape(odometry, scans.poses).rmse, ape(tracked, scans.poses).rmse
    assert lf < 0.2 and lf < odo / 10, (lf, odo)
    again = localize(scans, grid, LocalizeConfig(method="likelihood-field", odometry_noise=0.1))
    assert np.array_equal(tracked, again)


def test_bad_input(tmp_path):
    with pytest.raises(ValueError, match="method"):
        LocalizeConfig(method="guess")
    with pytest.raises(ValueError, match="noise"):
        LocalizeConfig(odometry_noise=-0.1)
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "kiseki.cli",
            "localize",
            str(tmp_path / "none.log"),
            "--map",
            str(tmp_path / "m.yaml"),
            "-o",
            str(tmp_path / "t.csv"),
        ],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 1 and "none.log" in done.stderr
