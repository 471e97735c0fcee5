# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""One rule for invalid readings and odometry jumps (``kiseki.scans``) in every log reader.

Each reader (CARMEN text log, Wean robotdata log, kiseki MCAP run log, ROS 1 and ROS 2 bags)
reads a small log with NaN, -inf, negative and zero ranges as the same scans as the clean log
with those readings marked invalid (NaN) and counts them alike; +inf is a no return (stored as
max_range). An odometry jump over the limit fails with one line naming the scans and their
times, one just under it is accepted, and the engine uses the same limit."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from kiseki import _core
from kiseki.core import Pose2
from kiseki.datasets import BAG_KINDS, read_bag_scans, read_carmen_log, read_wean_log, write_bag
from kiseki.datasets.carmen import flaser_angles
from kiseki.errors import LogFormatError
from kiseki.filters import (
    LocalizeConfig,
    MclConfig,
    MonteCarloLocalizer,
    ScanSpaceObservation,
    scan_model,
)
from kiseki.grid import OccupancyGrid
from kiseki.io.ros_map import save_map
from kiseki.io.runlog import RunWriter, read_run
from kiseki.scans import MAX_ODOMETRY_JUMP, LaserScans, apply_range_rule

SCANS, BEAMS = 6, 180  # 180 beams: the Wean logs' count
MAX_RANGE = 20.0
T0, DT = 100.0, 0.1
NO_RETURN = (5, 50)  # a no-return reading of the clean log, +inf in the dirty one
OTHER_NO_RETURN = (0, 0)  # one in both (a log without a stated max range takes the largest)
# (scan, beam, value in metres): readings that measured nothing
INVALID = [(0, 3, np.nan), (1, 10, -np.inf), (2, 20, -0.5), (3, 30, 0.0), (4, 40, np.nan)]


def clean_ranges() -> np.ndarray:
    """Quarter metres (exact in float32) from 0.5 to 15 m, two no returns at MAX_RANGE."""
    ranges = np.random.default_rng(0).integers(2, 61, size=(SCANS, BEAMS)) / 4.0
    ranges[NO_RETURN] = ranges[OTHER_NO_RETURN] = MAX_RANGE
    return ranges


def dirty_ranges() -> np.ndarray:
    ranges = clean_ranges()
    for scan, beam, value in INVALID:
        ranges[scan, beam] = value
    ranges[NO_RETURN] = np.inf
    return ranges


def invalid_mask() -> np.ndarray:
    mask = np.zeros((SCANS, BEAMS), dtype=bool)
    for scan, beam, _ in INVALID:
        mask[scan, beam] = True
    return mask


def odometry(jump: float = 0.3) -> np.ndarray:
    """A smooth path; the step from scan 3 to scan 4 is ``jump`` metres along x."""
    steps = np.full(SCANS - 1, 0.3)
    steps[3] = jump
    x = 1.0 + np.concatenate([[0.0], np.cumsum(steps)])
    return np.column_stack([x, np.full(SCANS, 2.0), 0.05 * np.arange(SCANS)])


def times() -> np.ndarray:
    return T0 + DT * np.arange(SCANS)


def number(value: float) -> str:
    return repr(float(value))  # nan, inf, -inf as CARMEN and Wean logs would spell them


# --- one writer per reader: (path, ranges in metres, odometry) -> the reader's LaserScans ---


def carmen(path: Path, ranges: np.ndarray, odom: np.ndarray, param: bool = True) -> LaserScans:
    lines = [f"PARAM robot_front_laser_max {MAX_RANGE} nohost 0"] if param else []
    for k, t in enumerate(times()):
        nums = [*ranges[k], *odom[k], *odom[k], t]
        lines.append(f"FLASER {BEAMS} " + " ".join(map(number, nums)) + f" host {t}")
    path.write_text("\n".join(lines) + "\n")
    return read_carmen_log(path).scans


def wean(path: Path, ranges: np.ndarray, odom: np.ndarray) -> LaserScans:
    lines = []
    for k, t in enumerate(times()):
        cm = [odom[k, 0] * 100, odom[k, 1] * 100, odom[k, 2]]
        nums = [*cm, *cm, *np.where(np.isfinite(ranges[k]), ranges[k] * 100, ranges[k]), t]
        lines.append("L " + " ".join(map(number, nums)))
    path.write_text("\n".join(lines) + "\n")
    return read_wean_log(path).scans


def mcap(path: Path, ranges: np.ndarray, odom: np.ndarray) -> LaserScans:
    angles = flaser_angles(BEAMS)
    with RunWriter(path) as w:
        for k, t in enumerate(times()):
            w.write_pose("/ground_truth", t, odom[k])
            w.write_odometry("/odom", t, odom[k])
            w.write_laser_scan("/scan", t, odom[k], angles, ranges[k], max_range=MAX_RANGE)
    return read_run(path).laser_scans()


def bag(kind: str) -> Callable[[Path, np.ndarray, np.ndarray], LaserScans]:
    def write_and_read(path: Path, ranges: np.ndarray, odom: np.ndarray) -> LaserScans:
        scans = LaserScans(
            times(), odom, odom, ranges.astype(np.float32), flaser_angles(BEAMS), MAX_RANGE
        )
        write_bag(scans, path, kind)
        return read_bag_scans(path, reference_topic="/ground_truth")

    return write_and_read


READERS = {"carmen": carmen, "wean": wean, "mcap": mcap} | {k: bag(k) for k in BAG_KINDS}
SUFFIX = {"carmen": ".log", "wean": ".log", "mcap": ".mcap", "ros1": ".bag"}


def log_path(tmp_path: Path, reader: str, name: str) -> Path:
    return tmp_path / (name + SUFFIX.get(reader, ""))


# --- invalid readings ---


@pytest.mark.parametrize("reader", READERS)
def test_invalid_readings_are_skipped_and_counted_alike_by_every_reader(tmp_path, reader):
    read = READERS[reader]
    clean = read(log_path(tmp_path, reader, "clean"), clean_ranges(), odometry())
    dirty = read(log_path(tmp_path, reader, "dirty"), dirty_ranges(), odometry())
    assert clean.invalid_ranges == 0 and dirty.invalid_ranges == len(INVALID)
    expected = clean.ranges.copy()
    expected[invalid_mask()] = np.nan
    assert dirty.ranges.dtype == np.float32 and dirty.ranges.flags.c_contiguous
    np.testing.assert_array_equal(dirty.ranges, expected)  # +inf: the no return of the clean log
    assert dirty.max_range == clean.max_range == dirty.ranges[NO_RETURN]
    for name in ("times", "poses", "odometry", "angles"):
        np.testing.assert_array_equal(getattr(dirty, name), getattr(clean, name), err_msg=name)
    assert dirty.first(2).invalid_ranges == 2


def test_a_log_without_a_max_range_takes_its_largest_finite_reading(tmp_path):
    ranges = dirty_ranges()
    ranges[OTHER_NO_RETURN] = 1.0
    scans = carmen(tmp_path / "no-param.log", ranges, odometry(), param=False)
    assert scans.max_range == 15.0  # not +inf, not NaN: the no return at +inf becomes 15 m
    assert scans.ranges[NO_RETURN] == 15.0 and scans.invalid_ranges == len(INVALID)


def test_non_range_fields_that_are_not_finite_remain_errors(tmp_path):
    odom = odometry()
    odom[2, 1] = np.nan  # scan 2: line 4 of the CARMEN log (after a PARAM), 3 of the Wean log
    with pytest.raises(LogFormatError, match=r"bad\.log:4: non-finite value \(NaN or inf\)"):
        carmen(tmp_path / "bad.log", dirty_ranges(), odom)
    with pytest.raises(LogFormatError, match=r"bad-wean\.log:3: non-finite value"):
        wean(tmp_path / "bad-wean.log", dirty_ranges(), odom)


def test_the_stored_invalid_reading_is_one_every_model_skips():
    """NaN, the readers' invalid reading, weighs as if the beam were not there, in every model;
    +inf as the no return max_range."""
    cells = np.zeros((100, 160), np.int8)
    cells[0, :] = cells[-1, :] = cells[:, 0] = cells[:, -1] = 100
    cells[60:80, 110:140] = 100
    grid = OccupancyGrid(cells, 0.05, Pose2(-1.0, -1.0, 0.0))
    angles = np.linspace(-np.pi / 2, np.pi / 2, 61)
    pose = np.array([2.0, 2.0, 0.1])
    truth = grid.cast_scans(pose[None], angles, max_range=8.0)[0].astype(np.float32)
    raw = truth.copy()
    raw[[3, 11, 29, 40]] = [np.nan, -np.inf, -1.0, 0.0]
    raw[50] = np.inf
    kept = apply_range_rule(raw, 8.0)
    assert np.isnan(kept[[3, 11, 29, 40]]).all() and kept[50] == np.float32(8.0)
    # -1 was stored for every no return; True was taken as 1 m
    for bad in (-1.0, 0.0, np.nan, np.inf, True, 1e9 * (1 + 1e-15)):
        with pytest.raises(
            ValueError,
            match=r"apply_range_rule: max_range must be a finite number in \(0, 1e\+09\] m",
        ):
            apply_range_rule(raw, bad)
    keep = np.ones(len(angles), dtype=bool)
    keep[[3, 11, 29, 40]] = False
    without = truth.copy()
    without[50] = 8.0
    poses = pose[None] + np.array([[0.0, 0.0, 0.0], [0.3, -0.2, 0.05], [-1.0, 0.5, -0.3]])
    for method in ("likelihood-field", "beam", "space-observation"):
        model = scan_model(method, grid, LocalizeConfig(method=method, beams=0))  # every beam
        engine = model.model if isinstance(model, ScanSpaceObservation) else model
        model.set_scan(angles, kept, 8.0)
        got = engine.log_likelihoods(poses)
        model.set_scan(angles[keep], without[keep], 8.0)
        np.testing.assert_allclose(got, engine.log_likelihoods(poses), rtol=1e-12, err_msg=method)


def test_localize_and_map_from_log_skip_and_report_invalid_readings(tmp_path):
    cells = np.zeros((100, 160), np.int8)
    cells[0, :] = cells[-1, :] = cells[:, 0] = cells[:, -1] = 100
    cells[60:80, 110:140] = 100
    grid = OccupancyGrid(cells, 0.05, Pose2(-1.0, -1.0, 0.0))
    save_map(grid, tmp_path / "room.yaml")
    angles = flaser_angles(181)
    poses = np.column_stack([np.linspace(1.0, 2.5, 10), np.full(10, 1.5), np.zeros(10)])
    ranges = grid.cast_scans(poses, angles, max_range=8.0)
    ranges[2, 5], ranges[4, 100], ranges[7, 33], ranges[6, 7] = np.nan, -1.0, 0.0, np.inf
    lines = ["PARAM robot_front_laser_max 8.0 nohost 0"]
    for k, t in enumerate(T0 + DT * np.arange(10)):
        nums = [*ranges[k], *poses[k], *poses[k], t]
        lines.append("FLASER 181 " + " ".join(map(number, nums)) + f" host {t}")
    log = tmp_path / "nan.log"
    log.write_text("\n".join(lines) + "\n")
    kiseki = [sys.executable, "-m", "kiseki.cli"]
    localize = [*kiseki, "localize", str(log), "--map", str(tmp_path / "room.yaml")]
    localize += ["--particles", "100", "--threads", "1"]
    done = subprocess.run(
        [*localize, "-o", str(tmp_path / "a.csv")], capture_output=True, text=True
    )
    assert done.returncode == 0, done.stderr
    assert "; 3 invalid range readings skipped" in done.stdout
    done = subprocess.run(
        [*localize, "-o", str(tmp_path / "b.csv"), "--json"], capture_output=True, text=True
    )
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    assert report["invalid_ranges"] == 3 and report["position_rmse_m"] < 0.2
    done = subprocess.run(
        [*kiseki, "map", "from-log", str(log), "-o", str(tmp_path / "m.yaml")],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr
    assert "from 10 scans (3 invalid range readings skipped)" in done.stdout


# --- odometry jumps ---


def test_one_limit_in_the_engine_and_in_python():
    assert MAX_ODOMETRY_JUMP == _core.MAX_ODOMETRY_JUMP == 10.0
    engine = _core.MonteCarloLocalization(MclConfig(particles=10).to_core(), 1)
    engine.initialize_gaussian(Pose2(0.0, 0.0, 0.0), 0.0, 0.0, 0.0)
    engine.predict(Pose2(0.0, 0.0, 0.0), Pose2(MAX_ODOMETRY_JUMP - 0.01, 0.0, 0.0))
    message = "odometry jumps 10.01 m between two updates: more than kiseki's limit of 10 m"
    with pytest.raises(ValueError, match=message):
        engine.predict(Pose2(0.0, 0.0, 0.0), Pose2(MAX_ODOMETRY_JUMP + 0.01, 0.0, 0.0))
    localizer = MonteCarloLocalizer(MclConfig(particles=10), 1)
    localizer.initialize((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    log_l = lambda poses: np.zeros(len(poses))  # noqa: E731
    localizer.step_log_likelihoods((0.0, 0.0, 0.0), log_l)
    localizer.step_log_likelihoods((MAX_ODOMETRY_JUMP - 0.01, 0.0, 0.0), log_l)
    with pytest.raises(ValueError, match="more than kiseki's limit of 10 m between two updates"):
        localizer.step_log_likelihoods((2 * MAX_ODOMETRY_JUMP, 0.0, 0.0), log_l)
    with pytest.raises(ValueError, match="update_min_d must be below kiseki's limit of 10 m"):
        MclConfig(update_min_d=MAX_ODOMETRY_JUMP)


@pytest.mark.parametrize("reader", READERS)
def test_an_odometry_jump_over_the_limit_fails_naming_the_scans(tmp_path, reader):
    read = READERS[reader]
    under = read(log_path(tmp_path, reader, "under"), clean_ranges(), odometry(9.99))
    assert np.hypot(*(under.odometry[4, :2] - under.odometry[3, :2])) == pytest.approx(9.99)
    path = log_path(tmp_path, reader, "over")
    with pytest.raises(LogFormatError) as caught:
        read(path, clean_ranges(), odometry(10.01))
    message = str(caught.value)
    line = r"line \d+, " if reader in ("carmen", "wean") else ""
    assert re.fullmatch(
        rf"{re.escape(str(path))}: odometry jumps 10\.01 m between scan 3 \({line}t = 100\.300 s\)"
        rf" and scan 4 \({line}t = 100\.400 s\): more than kiseki's limit of 10 m between two "
        r"scans \(a fault of the log, such as an odometry reset, not a motion\)",
        message,
    ), message


def test_the_command_line_refuses_a_jump_in_one_line(tmp_path):
    log = tmp_path / "jump.log"
    with pytest.raises(LogFormatError):
        carmen(log, clean_ranges(), odometry(12.3))
    save_map(OccupancyGrid(np.zeros((20, 20), np.int8), 0.1), tmp_path / "m.yaml")
    done = subprocess.run(
        [sys.executable, "-m", "kiseki.cli", "localize", str(log), "--map",
         str(tmp_path / "m.yaml"), "-o", str(tmp_path / "t.csv")],
        capture_output=True, text=True,
    )  # fmt: skip
    assert done.returncode == 1
    (line,) = done.stderr.strip().splitlines()
    assert line.startswith(f"kiseki: error: {log}: odometry jumps 12.3 m between scan 3 (line 5,")
