# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``kiseki magnetic walk``: the travel-distance filter on hand-held walks of repeated laps, run
as a user would: on a synthetic walk whose true travel distance is known, on walks that leave
the map's path, on bad files, and on the recorded Kok-Solin walks."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
import scipy.io

from _helpers.synthetic_walk import RADIUS, STEP, write_walk

THESIS = ("--filter", "thesis")


def run(*args) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "kiseki.cli", "magnetic", "walk", *map(str, args)],
        capture_output=True,
        text=True,
    )


def read_trajectory(path):
    lines = path.read_text().splitlines()
    assert lines[0] == "t,s_true,s_est,s_odom"
    return np.loadtxt(lines[1:], delimiter=",", ndmin=2)


def printed_rmse(stdout: str) -> tuple[float, float]:
    line = next(x for x in stdout.splitlines() if x.startswith("RMSE"))
    words = line.replace(",", "").split()
    return float(words[2]), float(words[5])


def test_synthetic_loop_truth_and_rmse(tmp_path):
    write_walk(tmp_path / "loop.mat")
    out = tmp_path / "out"
    result = run(tmp_path / "loop.mat", "-o", out, "--seed", "1", "--scale-error", "0.06", *THESIS)
    assert result.returncode == 0, result.stderr
    rows = read_trajectory(out / "trajectory.csv")
    t, s_true, s_est, s_odom = rows.T
    # two later laps of 25.1 m at 1 m/s: the true travel distance is the lap's time
    starts = np.flatnonzero(s_odom == 0.0)  # each localized lap starts from 0
    assert len(starts) == 2 and t[starts[0]] == pytest.approx(25.1, abs=0.15)
    lap_time = t - t[starts[np.searchsorted(starts, np.arange(len(t)), side="right") - 1]]
    assert np.max(np.abs(s_true - lap_time)) < 0.15
    err_est = np.sqrt(np.mean((s_est - s_true) ** 2))
    err_odom = np.sqrt(np.mean((s_odom - s_true) ** 2))
    assert printed_rmse(result.stdout) == pytest.approx((err_est, err_odom), abs=1.5e-3)
    assert err_odom > 0.5  # 6 % of up to 25 m
    assert err_est < 0.5 * err_odom
    again = run(
        tmp_path / "loop.mat", "-o", tmp_path / "b", "--seed", "1", "--scale-error", "0.06", *THESIS
    )
    assert (tmp_path / "b" / "trajectory.csv").read_text() == (out / "trajectory.csv").read_text()
    assert again.stdout.splitlines()[-1] == result.stdout.splitlines()[-1]


def test_a_lap_off_the_path_is_reported_not_localized(tmp_path):
    write_walk(tmp_path / "detour.mat", detour=(2, 5.0))
    result = run(tmp_path / "detour.mat", "-o", tmp_path / "out", *THESIS)
    assert result.returncode == 0, result.stderr
    assert "lap 2 leaves the map's path" in result.stdout
    t = read_trajectory(tmp_path / "out" / "trajectory.csv")[:, 0]
    assert t.min() > 2 * 25.0  # only lap 3 is localized


def test_every_later_lap_off_the_path_is_an_error(tmp_path):
    write_walk(tmp_path / "detour.mat", laps=2.0, detour=(2, 5.0))
    result = run(tmp_path / "detour.mat", "-o", tmp_path / "out", *THESIS)
    assert result.returncode == 1
    assert "every later lap leaves the map's path" in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "out" / "trajectory.csv").exists()


@pytest.mark.parametrize(
    ("override", "message"),
    [
        ({"dPos": np.zeros((10, 3))}, "dPos must be"),
        ({"m": None}, "lacks m"),
        ({"t": None}, "lacks t"),
        ({"m": "nan"}, "NaN"),
    ],
)
def test_bad_files(tmp_path, override, message):
    path = tmp_path / "bad.mat"
    write_walk(path)
    data = {k: v for k, v in scipy.io.loadmat(path).items() if not k.startswith("__")}
    for key, value in override.items():
        if value is None:
            del data[key]
        elif value == "nan" if isinstance(value, str) else False:
            data[key] = data[key].copy()
            data[key][40, 2] = np.nan
        else:
            data[key] = value
    scipy.io.savemat(path, data)
    result = run(path, "-o", tmp_path / "out")
    assert result.returncode == 1
    assert message in result.stderr and str(path) in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1


def test_bad_options(tmp_path):
    write_walk(tmp_path / "loop.mat", laps=1.02)  # a 0.5 m tail is no lap
    for how in ((), THESIS):  # the walk's own problems name its file (they did not)
        result = run(tmp_path / "loop.mat", "-o", tmp_path / "out", *how)
        assert result.returncode == 1 and "one lap only" in result.stderr
        assert result.stderr.startswith(f"kiseki: error: {tmp_path / 'loop.mat'}: ")
    result = run(tmp_path / "loop.mat", "-o", tmp_path / "out", "--scale-error", "-1")
    assert result.returncode == 1 and "--scale-error must be" in result.stderr
    short = tmp_path / "short.mat"
    write_walk(short, laps=0.3)
    result = run(short, "-o", tmp_path / "out")
    assert result.returncode == 1 and "never comes back within 1.5 m" in result.stderr
    assert result.stderr.startswith(f"kiseki: error: {short}: walk: the walker never comes back")
    for bad, message in (
        (("--filter", "kalman"), "--filter must be loop or thesis"),
        (("--start", "nowhere"), "--start must be known or global"),
        ((*THESIS, "--start", "global"), "--start is for --filter loop"),
    ):
        result = run(tmp_path / "loop.mat", "-o", tmp_path / "out", *bad)
        assert result.returncode == 1 and message in result.stderr, bad
        assert len(result.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize("start", ["known", "global"])
def test_loop_filter_on_a_synthetic_walk_is_told_no_laps(tmp_path, start):
    """Three laps of a circle after the mapping lap, with 8 % long odometry: the arc is the
    truth; the loop filter's file and printout agree and it beats the odometry continued around
    the loop (that its scale approaches 1 / 1.08 is tested over seeds in
    tests/python/magnetic/test_loop_walk_scale.py: one seed's estimate moves with the machine's
    floating-point kernels)."""
    write_walk(tmp_path / "loop.mat", laps=4.0)
    out = tmp_path / "out"
    args = ("--seed", "2", "--scale-error", "0.08", "--start", start)
    result = run(tmp_path / "loop.mat", "-o", out, *args)
    assert result.returncode == 0, result.stderr
    lines = (out / "trajectory.csv").read_text().splitlines()
    assert lines[0] == "t,s_true,s_est,s_odom,scale"
    t, s_true, s_est, s_odom, scale = np.loadtxt(lines[1:], delimiter=",", ndmin=2).T
    loop = float(result.stdout.split("mapping lap of ")[1].split()[0])
    assert loop == pytest.approx(2 * np.pi * RADIUS, abs=0.1)
    assert np.max(np.abs((s_true - t * STEP / 0.1 + loop / 2) % loop - loop / 2)) < 0.3
    wrap = lambda e: (e + loop / 2) % loop - loop / 2  # noqa: E731
    err_est = np.sqrt(np.mean(wrap(s_est - s_true) ** 2))
    err_odom = np.sqrt(np.mean(wrap(s_odom - s_true) ** 2))
    assert printed_rmse(result.stdout) == pytest.approx((err_est, err_odom), abs=2e-3)
    assert err_odom > 1.5
    # an unknown start: four bumps per lap, the horizontal field flat; it is found within the
    # first of the three localized laps
    settled = slice(len(t) // 3 if start == "global" else 0, None)
    assert np.sqrt(np.mean(wrap(s_est - s_true)[settled] ** 2)) < 0.25 * err_odom
    assert np.all((scale > 0.8) & (scale < 1.2))  # the scale column: the filter's, near 1


@pytest.mark.parametrize("name", ["eight", "square"])
def test_recorded_walks(shared_data, tmp_path, name):
    walk = shared_data / "magnetic" / "kok_1d" / f"{name}.mat"
    if not walk.is_file():
        pytest.skip(f"{walk} not found")
    result = run(walk, "-o", tmp_path, "--seed", "0", *THESIS)
    assert result.returncode == 0, result.stderr
    t, s_true, s_est, s_odom = read_trajectory(tmp_path / "trajectory.csv").T
    err_est = np.sqrt(np.mean((s_est - s_true) ** 2))
    err_odom = np.sqrt(np.mean((s_odom - s_true) ** 2))
    assert printed_rmse(result.stdout) == pytest.approx((err_est, err_odom), abs=1.5e-3)
    assert "leaves the map's path" not in result.stdout  # the laps repeat within 0.8 m
    assert np.all(np.diff(t) > 0)
    within_lap = s_odom[1:] != 0.0  # each lap starts from 0
    jumps = np.abs(np.diff(s_true))[within_lap]
    assert jumps.max() < 0.6  # no jump to the other branch of the eight
    assert err_est <= err_odom * 1.05
    if name == "square":  # 35 uT of vertical anomalies: the filter halves odometry's error
        assert err_est < 0.7 * err_odom
