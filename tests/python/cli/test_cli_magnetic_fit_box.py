# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``kiseki magnetic fit`` on readings whose map box the map cannot take (a reading far from the
others): one line naming the data, before the fit when the cells are too many."""

from __future__ import annotations

import re

import numpy as np
import pytest

from _helpers.cli_main import kiseki


def write_aalto(prefix, positions: np.ndarray) -> None:
    """An Aalto run DIR/N: N-loc.csv, N-mag.csv and N-time.csv, no header."""
    field = 20.0 + np.sin(positions[:, :1]) + np.cos(positions[:, 1:2]) * [1.0, -2.0, 0.5]
    for part, table in (("loc", positions), ("mag", field), ("time", 0.02 * np.arange(40))):
        np.savetxt(f"{prefix}-{part}.csv", table, delimiter=",")


@pytest.mark.parametrize("model", ["curl-free", "independent"])
def test_a_reading_1e8_m_away_names_the_run_before_the_fit(
    tmp_path, monkeypatch, capsys, model
) -> None:
    positions = np.random.default_rng(2).uniform(0, 3, (40, 2))
    positions[7] = 1e8
    write_aalto(tmp_path / "1", positions)
    monkeypatch.chdir(tmp_path)
    args = ("magnetic", "fit", "1", "-o", "m", "--model", model)
    status, out, err = kiseki(monkeypatch, capsys, *args)
    lines = err.strip().splitlines()
    assert status == 1 and out == "" and len(lines) == 1
    assert re.fullmatch(
        r"kiseki: error: 1: the readings span 1e\+08 x 1e\+08 m: a map of 10000000\d\d x "
        r"10000000\d\d cells of 0\.1 m is more than 20,000,000 cells; choose a coarser "
        r"--resolution or leave out the far readings",
        lines[0],
    )
    assert not (tmp_path / "m").exists()


def test_a_3d_box_beyond_octomaps_keys_names_the_file(tmp_path, monkeypatch, capsys) -> None:
    p = np.random.default_rng(3).uniform(0, 2, (30, 3)) + [5000.0, 0.0, 0.0]
    table = np.column_stack([p, 20.0 + np.sin(p)])
    np.savetxt(tmp_path / "far.csv", table, delimiter=",", header="x,y,z,mx,my,mz", comments="")
    monkeypatch.chdir(tmp_path)
    args = ("magnetic", "fit", "far.csv", "-o", "m", "--model", "independent")
    status, _, err = kiseki(monkeypatch, capsys, *args, "--kernel", "3,1,0.1")
    lines = err.strip().splitlines()
    assert status == 1 and len(lines) == 1
    assert lines[0].startswith("kiseki: error: far.csv: the box [")
    assert lines[0].endswith("lies beyond OctoMap's keys at 0.1 m")
    assert not (tmp_path / "m").exists()


def test_a_kernel_written_with_an_underscore_is_refused(tmp_path, monkeypatch, capsys) -> None:
    """--kernel 1_0,1,1 fitted with sigma_f = 10 (float() reads PEP 515 underscores)."""
    write_aalto(tmp_path / "1", np.random.default_rng(2).uniform(0, 3, (40, 2)))
    monkeypatch.chdir(tmp_path)
    args = ("magnetic", "fit", "1", "-o", "m", "--model", "independent", "--kernel", "1_0,1,1")
    status, _, err = kiseki(monkeypatch, capsys, *args)
    assert (status, err.strip()) == (
        1,
        "kiseki: error: --kernel must be 3 numbers "
        "sigma_f,l,sigma_n (--model independent), got 1_0,1,1",
    )
    assert not (tmp_path / "m").exists()
