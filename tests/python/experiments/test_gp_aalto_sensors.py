# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""gp-aalto-sensors on the recorded Aalto run 5: its single-sensor arm against the library's
single-map filter on the same stream, its record's drop against its own trusted-sensor history,
and a check that cannot drop giving the trusting filter exactly."""

from __future__ import annotations

import dataclasses

import numpy as np
import pandas as pd
import pytest

from kiseki.magnetic.localization import MagneticMclConfig, localize_on_magnetic_map
from kiseki_experiments.gp.gp_aalto import GpAaltoConfig
from kiseki_experiments.gp.gp_aalto_sensors import (
    SensorsConfig,
    in_control,
    in_control_windows,
    maps_and_stream,
    trial,
    window_means,
)
from kiseki_experiments.gp.gp_aalto_tasks import noisy_odometry


def test_arms_against_the_single_map_filter(shared_data):
    folder = shared_data / "magnetic"
    if not (folder / "aalto" / "nexus" / "5-mag.csv").is_file():
        pytest.skip(f"{folder}/aalto not found")
    config = SensorsConfig(data_dir=str(folder), particles=200)
    record = trial(config, 0, 7).record
    maps, xy, z = maps_and_stream(config)
    aalto = GpAaltoConfig(data_dir=str(folder))
    d = np.diff(xy, axis=0)
    heading = np.arctan2(d[:, 1], d[:, 0])
    truth = np.column_stack([xy, np.concatenate([heading[:1], heading])])
    odometry = noisy_odometry(
        truth, np.random.default_rng(7), aalto.odometry_scale_sd, aalto.heading_walk
    )
    mcl = MagneticMclConfig(particles=200, alphas=tuple(aalto.alphas))
    single = localize_on_magnetic_map(
        maps[0], odometry, z[:, :1], [[0, 0]], initial_pose=truth[0], config=mcl, seed=7,
        frame="world",
    )  # fmt: skip
    e = np.hypot(*(single.estimates[:, :2] - xy).T)
    assert record["invensense_mean"] == pytest.approx(e.mean(), rel=1e-9)
    assert record["nexus_dropped"] == ("nexus at update" in record["dropped"])
    never = trial(dataclasses.replace(config, limit=1000.0), 0, 7).record
    assert never["dropped"] == "" and never["checked_mean"] == never["both_mean"]


def test_window_means_are_the_means_of_every_window():
    z = np.random.default_rng(3).normal(size=(57, 3)) * [1.0, 10.0, 1e-3]
    brute = np.array([z[i : i + 20].mean(axis=0) for i in range(57 - 20 + 1)])
    np.testing.assert_allclose(window_means(z, 20), brute, rtol=1e-12, atol=1e-15)


def test_the_in_control_table_is_the_committed_one_and_counts_windows_past_the_limit(
    shared_data, project_root
):
    folder = shared_data / "magnetic"
    if not (folder / "aalto" / "nexus" / "4-mag.csv").is_file():
        pytest.skip(f"{folder}/aalto not found")
    config = SensorsConfig(data_dir=str(folder))
    windows = in_control_windows(config)
    table = in_control(config, windows)
    committed = pd.read_csv(
        project_root / "docs/reproduction/results/gp-aalto-sensors/run/tables/in_control.csv"
    )
    assert list(table["sensor"]) == list(committed["sensor"])
    np.testing.assert_array_equal(table["windows"], committed["windows"])
    np.testing.assert_allclose(table["largest_abs_mean"], committed["largest_abs_mean"], rtol=1e-6)
    np.testing.assert_allclose(table["share_past_limit"], committed["share_past_limit"], atol=1e-12)
    never = in_control(dataclasses.replace(config, limit=1000.0), windows)
    always = in_control(dataclasses.replace(config, limit=1e-9), windows)
    assert (never["share_past_limit"] == 0).all() and (always["share_past_limit"] == 1).all()
