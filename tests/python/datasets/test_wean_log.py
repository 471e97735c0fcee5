# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Tests of the CMU Wean Hall robotdata log reader: tiny synthetic logs, bad input, real logs."""

from __future__ import annotations

import gzip
from pathlib import Path

import numpy as np
import pytest

from kiseki.datasets import is_wean_log, open_scans, read_wean_log
from kiseki.errors import LogFormatError


def laser_line(x: float, y: float, th: float, ranges: list[float], ts: float) -> str:
    xl, yl = x + 25 * np.cos(th), y + 25 * np.sin(th)
    values = [x, y, th, xl, yl, th, *ranges, ts]
    return "L " + " ".join(f"{v:.6f}" for v in values)


def tiny_log(path: Path, compress: bool = False) -> Path:
    lines = [
        "O 100.0 -50.0 0.5 0.01",
        laser_line(100.0, -50.0, 0.5, [200.0] * 179 + [8183.0], 0.05),
        "O 110.0 -50.0 0.5 0.10",
        laser_line(110.0, -50.0, 0.5, [150.0] * 180, 0.15),
        "",
    ]
    data = "\n".join(lines).encode()
    path.write_bytes(gzip.compress(data) if compress else data)
    return path


@pytest.mark.parametrize("compress", [False, True])
def test_tiny_log_units_and_layout(tmp_path: Path, compress: bool) -> None:
    log = read_wean_log(tiny_log(tmp_path / "robotdata.log", compress))
    scans = log.scans
    assert len(scans) == 2
    np.testing.assert_allclose(scans.times, [0.05, 0.15])
    # odometry = laser pose, cm -> m; the laser is 25 cm ahead of the centre
    np.testing.assert_allclose(
        scans.odometry[0, :2], [1.0 + 0.25 * np.cos(0.5), -0.5 + 0.25 * np.sin(0.5)]
    )
    assert scans.odometry[0, 2] == pytest.approx(0.5)
    assert scans.ranges.dtype == np.float32 and scans.ranges.shape == (2, 180)
    assert scans.ranges[0, 0] == pytest.approx(2.0)
    assert scans.max_range == pytest.approx(81.83)
    assert scans.angles[0] == pytest.approx(-np.pi / 2)
    assert np.diff(scans.angles) == pytest.approx(np.full(179, np.pi / 180))
    assert np.isnan(scans.poses).all() and not scans.has_reference_poses
    np.testing.assert_allclose(log.odometry_poses, [[1.0, -0.5, 0.5], [1.1, -0.5, 0.5]])
    np.testing.assert_allclose(log.odometry_times, [0.01, 0.10])
    assert is_wean_log(tmp_path / "robotdata.log")
    assert len(open_scans(tmp_path / "robotdata.log")) == 2


def test_malformed_lines_name_file_and_line(tmp_path: Path) -> None:
    good = tiny_log(tmp_path / "good.log").read_text().splitlines()
    cases = {
        "short": (
            good[:3] + [good[3].rsplit(" ", 2)[0]],
            r"short\.log:4: L line has 186 fields, expected 188",
        ),
        "text": (good[:2] + ["O 1 2 x 4"], r"text\.log:3: non-numeric value 'x'"),
        # PEP 515 underscores are not numbers in a log (float() read 1_0 as 10)
        "odo_": (good[:2] + ["O 1_0 2 3 4"], r"odo_\.log:3: non-numeric value '1_0'"),
        "range_": (
            [good[0], good[1].replace(" 200.000000", " 2_00.000000", 1)],
            r"range_\.log:2: non-numeric value '2_00\.000000'",
        ),
        "first_": (["L 1_0" + good[1][5:]], r"first_\.log:1: non-numeric value '1_0"),
        "kind": (good[:1] + ["Q 1 2 3"], r"kind\.log:2: unknown line type 'Q'"),
        "time": (  # a negative range is an invalid reading (kiseki.scans), a NaN time is not
            [good[0], good[1].replace(" 200.000000", " -200.000000", 1).rsplit(" ", 1)[0] + " nan"],
            r"time\.log:2: non-finite",
        ),
        "nan": (["O 1 2 nan 4", good[1]], r"nan\.log:1: non-finite"),
        # odometry of 1e300 was taken (CARMEN's readers bound it at +-1e12)
        "huge": (["O 1e300 2 3 4", good[1]], r"huge\.log:1: value 1e\+300 beyond \+-1e\+12"),
    }
    for name, (lines, message) in cases.items():
        path = tmp_path / f"{name}.log"
        path.write_text("\n".join(lines) + "\n")
        with pytest.raises(LogFormatError, match=message):
            read_wean_log(path)
    with pytest.raises(LogFormatError, match=r"first_\.log:1: non-numeric value '1_0"):
        open_scans(tmp_path / "first_.log")  # a Wean log still, not a CARMEN log
    (tmp_path / "odo.log").write_text("O 1 2 3 4\n")
    with pytest.raises(LogFormatError, match="no laser"):
        read_wean_log(tmp_path / "odo.log")
    with pytest.raises(FileNotFoundError, match="missing.log"):
        read_wean_log(tmp_path / "missing.log")


def test_carmen_log_is_not_a_wean_log(tmp_path: Path) -> None:
    path = tmp_path / "c.log"
    path.write_text("# CARMEN\nODOM 0 0 0 0 0 0 1.0 host 1.0\n")
    assert not is_wean_log(path)
    assert not is_wean_log(tmp_path / "nothing.log")


@pytest.mark.parametrize(
    ("run", "lasers", "odometry", "no_return"),
    [(1, 713, 1505, 81.83), (2, 2251, 3126, 81.91), (3, 1241, 1735, 81.91)],
)
def test_real_logs(
    shared_data: Path, run: int, lasers: int, odometry: int, no_return: float
) -> None:
    path = shared_data / "cmu_wean" / f"robotdata{run}.log.gz"
    if not path.is_file():
        pytest.skip(f"{path} not found")
    log = read_wean_log(path)
    scans = log.scans
    assert len(scans) == lasers and len(log.odometry_times) == odometry
    assert scans.max_range == pytest.approx(no_return, abs=1e-4)
    # metres: the robot moves tens of metres, not thousands; walls are a few metres away
    extent = np.ptp(scans.odometry[:, :2], axis=0)
    assert 3.0 < extent.max() < 100.0
    returns = scans.ranges[scans.ranges < scans.max_range]
    assert 0.5 < float(np.median(returns)) < 10.0
    assert np.all(np.diff(scans.times) >= 0)
    assert len(open_scans(path)) == lasers
