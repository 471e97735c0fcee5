# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Tests of the CARMEN log reader: synthetic logs with known values, bad input, real logs."""

from __future__ import annotations

import gzip
import math
from pathlib import Path

import numpy as np
import pytest

from kiseki.datasets.carmen import flaser_angles, read_carmen_log
from kiseki.errors import LogFormatError
from kiseki.scans import LaserScans

RANGES = [[1.5, 2.25, 3.0, 81.91], [0.5, 81.91, 7.125, 4.0]]
POSES = [[1.0, 2.0, 0.5], [1.25, 2.5, -3.0]]
ODOMS = [[10.0, 20.0, 0.25], [10.5, 20.25, 0.75]]
TIMES = [100.5, 100.75]


def flaser(ranges, pose, odom, t) -> str:
    nums = [len(ranges), *ranges, *pose, *odom, t]
    return "FLASER " + " ".join(map(str, nums)) + f" host {t + 0.01}"


def odom_line(pose, tv, rv, t) -> str:
    return "ODOM " + " ".join(map(str, [*pose, tv, rv, 0.0, t])) + f" host {t}"


def robotlaser(ranges, remissions, laser, robot, t, start=-1.5, fov=3.0, res=1.0, rmax=30.0):
    nums = [0, start, fov, res, rmax, 0.01, 0, len(ranges), *ranges, len(remissions)]
    nums += [*remissions, *laser, *robot, 0.3, 0.1, 1.0, 0.5, 0.0, t]
    return "ROBOTLASER1 " + " ".join(map(str, nums)) + f" host {t}"


def sample_text() -> str:
    lines = [
        "# message formats defined: PARAM SYNC ODOM FLASER RLASER",
        "PARAM robot_front_laser_max 81.9 nohost 0",
        "PARAM robot_use_laser on nohost 0",
        odom_line([0.0, 0.0, 0.0], 0.0, 0.0, 100.0),
        flaser(RANGES[0], POSES[0], ODOMS[0], TIMES[0]),
        "NEFF 30",
        "RLASER 2 9 9 0 0 0 0 0 0 100.6 host 100.6",
        "",
        odom_line([0.5, -0.25, 1.5], 0.3, -0.2, 100.6),
        flaser(RANGES[1], POSES[1], ODOMS[1], TIMES[1]),
    ]
    return "\n".join(lines) + "\n"


def write(path: Path, text: str, compress: bool = False) -> Path:
    data = text.encode()
    path.write_bytes(gzip.compress(data) if compress else data)
    return path


def check_sample(scans: LaserScans) -> None:
    assert len(scans) == 2
    assert scans.ranges.dtype == np.float32
    assert scans.ranges.flags.c_contiguous
    np.testing.assert_array_equal(scans.ranges, np.array(RANGES, dtype=np.float32))
    np.testing.assert_array_equal(scans.poses, POSES)
    np.testing.assert_array_equal(scans.odometry, ODOMS)
    np.testing.assert_array_equal(scans.times, TIMES)
    np.testing.assert_allclose(scans.angles, -np.pi / 2 + np.pi / 3 * np.arange(4), atol=1e-15)
    assert scans.max_range == float(np.float32(81.9))


@pytest.mark.parametrize("compress", [False, True])
def test_synthetic_log_exact_values(tmp_path: Path, compress: bool) -> None:
    # The gzip file deliberately has no .gz suffix: gzip is detected from the magic bytes.
    log = read_carmen_log(write(tmp_path / "sample.log", sample_text(), compress))
    assert log.path == tmp_path / "sample.log"
    check_sample(log.scans)
    assert log.params == {"robot_front_laser_max": "81.9", "robot_use_laser": "on"}
    np.testing.assert_array_equal(log.odometry.times, [100.0, 100.6])
    np.testing.assert_array_equal(log.odometry.poses, [[0, 0, 0], [0.5, -0.25, 1.5]])
    np.testing.assert_array_equal(log.odometry.velocities, [[0, 0], [0.3, -0.2]])


def test_plain_text_with_gz_suffix_is_read_as_text(tmp_path: Path) -> None:
    check_sample(read_carmen_log(write(tmp_path / "sample.log.gz", sample_text())).scans)


def test_crlf_line_endings(tmp_path: Path) -> None:
    path = write(tmp_path / "crlf.log", sample_text().replace("\n", "\r\n"))
    check_sample(read_carmen_log(path).scans)


@pytest.mark.parametrize(
    ("n", "step", "last"),
    [
        (180, math.pi / 180, math.pi / 2 - math.pi / 180),
        (181, math.pi / 180, math.pi / 2),
        (360, math.pi / 360, math.pi / 2 - math.pi / 360),
        (361, math.pi / 360, math.pi / 2),
    ],
)
def test_flaser_beam_angles(tmp_path: Path, n: int, step: float, last: float) -> None:
    angles = flaser_angles(n)
    assert angles.shape == (n,)
    assert angles[0] == -math.pi / 2
    np.testing.assert_allclose(np.diff(angles), step, rtol=1e-12)
    assert angles[-1] == pytest.approx(last, abs=1e-12)
    line = flaser([1.0] * n, [0, 0, 0], [0, 0, 0], 1.0)
    scans = read_carmen_log(write(tmp_path / "n.log", line + "\n")).scans
    np.testing.assert_array_equal(scans.angles, angles)
    assert scans.ranges.shape == (1, n)


def test_max_range_without_param_is_largest_reading(tmp_path: Path) -> None:
    text = "\n".join(
        flaser(r, p, o, t) for r, p, o, t in zip(RANGES, POSES, ODOMS, TIMES, strict=True)
    )
    scans = read_carmen_log(write(tmp_path / "noparam.log", text)).scans
    assert scans.max_range == float(np.float32(81.91))
    assert np.count_nonzero(scans.ranges >= scans.max_range) == 2
    assert np.count_nonzero(scans.ranges.astype(np.float64) >= scans.max_range) == 2


def test_max_range_param_matches_equal_readings_in_float32_and_float64(tmp_path: Path) -> None:
    line = flaser([80.99, 1.0], [0] * 3, [0] * 3, 1.0)
    text = "PARAM robot_front_laser_max 80.99 nohost 0\n" + line
    scans = read_carmen_log(write(tmp_path / "p.log", text)).scans
    assert np.count_nonzero(scans.ranges >= scans.max_range) == 1
    assert np.count_nonzero(scans.ranges.astype(np.float64) >= scans.max_range) == 1


def test_robotlaser1(tmp_path: Path) -> None:
    lines = [
        robotlaser([1.0, 2.0, 3.0], [0.5, 0.25], [1.0, 2.0, 0.1], [0.9, 1.9, 0.2], 5.0),
        robotlaser([4.0, 5.0, 30.0], [], [1.5, 2.5, 0.3], [1.4, 2.4, 0.4], 6.0),
    ]
    scans = read_carmen_log(write(tmp_path / "rl.log", "\n".join(lines))).scans
    np.testing.assert_array_equal(scans.ranges, [[1, 2, 3], [4, 5, 30]])
    np.testing.assert_array_equal(scans.angles, [-1.5, -0.5, 0.5])
    np.testing.assert_array_equal(scans.poses, [[1.0, 2.0, 0.1], [1.5, 2.5, 0.3]])
    np.testing.assert_array_equal(scans.odometry, [[0.9, 1.9, 0.2], [1.4, 2.4, 0.4]])
    np.testing.assert_array_equal(scans.times, [5.0, 6.0])
    assert scans.max_range == 30.0


def test_flaser_is_preferred_over_robotlaser1(tmp_path: Path) -> None:
    rl = robotlaser([1.0, 2.0, 3.0], [], [0, 0, 0], [0, 0, 0], 5.0)
    check_sample(read_carmen_log(write(tmp_path / "both.log", rl + "\n" + sample_text())).scans)


def test_robotlaser1_configuration_change_raises(tmp_path: Path) -> None:
    lines = [
        robotlaser([1.0, 2.0], [], [0, 0, 0], [0, 0, 0], 5.0),
        robotlaser([1.0, 2.0], [], [0, 0, 0], [0, 0, 0], 6.0, res=0.5),
    ]
    with pytest.raises(LogFormatError, match=r"cfg\.log:2: .*configuration"):
        read_carmen_log(write(tmp_path / "cfg.log", "\n".join(lines)))


# --- bad input -------------------------------------------------------------------------------


def test_missing_file(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError, match="nothere.log"):
        read_carmen_log(tmp_path / "nothere.log")


@pytest.mark.parametrize("text", ["", "\n  \n"])
def test_empty_file(tmp_path: Path, text: str) -> None:
    with pytest.raises(LogFormatError, match=r"empty\.log: empty"):
        read_carmen_log(write(tmp_path / "empty.log", text))


def test_no_laser_messages(tmp_path: Path) -> None:
    text = "# comment\nPARAM a b\n" + odom_line([0, 0, 0], 0, 0, 1.0) + "\n"
    with pytest.raises(LogFormatError, match=r"odom\.log: no FLASER or ROBOTLASER1"):
        read_carmen_log(write(tmp_path / "odom.log", text))


def test_truncated_gzip(tmp_path: Path) -> None:
    data = gzip.compress(sample_text().encode() * 20)
    path = tmp_path / "cut.log.gz"
    path.write_bytes(data[: len(data) // 2])
    with pytest.raises(LogFormatError, match=r"cut\.log\.gz: truncated or corrupt gzip"):
        read_carmen_log(path)


def test_corrupt_gzip(tmp_path: Path) -> None:
    data = bytearray(gzip.compress(sample_text().encode() * 20))
    data[len(data) // 2] ^= 0xFF
    path = tmp_path / "bad.log.gz"
    path.write_bytes(bytes(data))
    with pytest.raises(LogFormatError, match=r"bad\.log\.gz: truncated or corrupt gzip"):
        read_carmen_log(path)


def replace_line(lineno: int, new: str) -> str:
    lines = sample_text().split("\n")
    lines[lineno - 1] = new
    return "\n".join(lines)


GOOD_FLASER = flaser(RANGES[1], POSES[1], ODOMS[1], TIMES[1])  # line 10 of sample_text()


@pytest.mark.parametrize(
    ("line", "message"),
    [
        (GOOD_FLASER.rsplit(" ", 3)[0], "FLASER has 12 fields, expected 15"),  # truncated
        (GOOD_FLASER + " extra", "FLASER has 16 fields, expected 15"),
        ("FLASER", "FLASER has 1 fields"),
        (GOOD_FLASER.replace("7.125", "7.1x5"), "non-numeric value '7.1x5' in FLASER"),
        # PEP 515 underscores are not numbers in a log (float() read 7_125 as 7125)
        (GOOD_FLASER.replace("7.125", "7_125"), "non-numeric value '7_125' in FLASER"),
        (GOOD_FLASER.replace("10.5 ", "1_0.5 ", 1), "non-numeric value '1_0.5' in FLASER"),
        (GOOD_FLASER.replace("FLASER 4 ", "FLASER 4_0 "), "beam count '4_0' is not an integer"),
        (GOOD_FLASER.replace("-3.0", "nan"), r"non-finite value \(NaN or inf\) in FLASER"),
        (GOOD_FLASER.replace("10.5 ", "inf ", 1), "non-finite value"),  # odometry x
        # a pose of 1e300 m made the pose error infinite (exit 0); a reading of 1e300 is none
        (GOOD_FLASER.replace("10.5 ", "1e300 ", 1), r"value 1e\+300 in FLASER beyond \+-1e\+12"),
        (GOOD_FLASER.replace("FLASER 4 ", "FLASER 4.0 "), "beam count '4.0' is not an integer"),
        (flaser([1.0, 2.0, 3.0], [0] * 3, [0] * 3, 101.0), "FLASER has 3 beams, line 5 has 4"),
    ],
)
def test_corrupt_flaser_line(tmp_path: Path, line: str, message: str) -> None:
    path = write(tmp_path / "corrupt.log", replace_line(10, line))
    with pytest.raises(LogFormatError, match=rf"corrupt\.log:10: {message}"):
        read_carmen_log(path)


@pytest.mark.parametrize(
    ("line", "message"),
    [
        ("ODOM 0.5 -0.25 1.5 0.3 -0.2 0 100.6 host", "ODOM has 9 fields, expected 10"),
        ("ODOM 0.5 -0.25 nan 0.3 -0.2 0 100.6 host 100.6", "non-finite value"),
        ("ODOM 0.5 -0.25 1.5 0.3 -0.2 0 100.6 host 1e13", r"value 1e\+13 in ODOM beyond"),
        ("ODOM 0.5 -0.25 1.5 0.3 -0.2 0 abc host 100.6", "non-numeric value 'abc' in ODOM"),
        ("ODOM 0.5 -0.25 1.5 0.3 -0.2 0 10_0.6 host 1", "non-numeric value '10_0.6' in ODOM"),
        ("PARAM lonely", "PARAM needs a name and a value"),
    ],
)
def test_corrupt_other_lines(tmp_path: Path, line: str, message: str) -> None:
    path = write(tmp_path / "corrupt.log", replace_line(9, line))
    with pytest.raises(LogFormatError, match=rf"corrupt\.log:9: {message}"):
        read_carmen_log(path)


def test_corrupt_robotlaser1_line(tmp_path: Path) -> None:
    good = robotlaser([1.0, 2.0], [0.5], [0, 0, 0], [0, 0, 0], 5.0)
    for bad, message in [
        (good.rsplit(" ", 2)[0], "ROBOTLASER1 has 25 fields, expected at least 26"),
        (good.replace(" 1 0.5 ", " x 0.5 "), "ROBOTLASER1 remission count 'x' is not"),
        (good.replace(" 1 0.5 ", " 0_1 0.5 "), "ROBOTLASER1 remission count '0_1' is not"),
        (good.replace(" 2.0 1 0.5 ", " 2_0 1 0.5 "), "non-numeric value '2_0' in ROBOTLASER1"),
        ("ROBOTLASER1 0 -1.5 3.0", "ROBOTLASER1 has 4 fields, expected at least 24"),
    ]:
        path = write(tmp_path / "rl.log", good + "\n" + bad + "\n")
        with pytest.raises(LogFormatError, match=rf"rl\.log:2: {message}"):
            read_carmen_log(path)


@pytest.mark.parametrize(("start", "res"), [(-1.5, 0.0), (-1.5, 100.0), (1e9, 1.0), (-1.5, -7.0)])
def test_robotlaser1_beams_beyond_one_turn_are_refused(tmp_path: Path, start, res) -> None:
    """A resolution of 0 put every beam on one ray; 100 rad, or a start of 1e9, read as given."""
    line = robotlaser([1.0, 2.0], [0.5], [0, 0, 0], [0, 0, 0], 5.0, start=start, res=res)
    path = write(tmp_path / "rl.log", line + "\n")
    with pytest.raises(LogFormatError, match=r"rl\.log:1: ROBOTLASER1 start_angle .* not beams of"):
        read_carmen_log(path)


@pytest.mark.parametrize("max_range", [1e10, 0.0, -5.0])
def test_robotlaser1_maximum_range_past_the_bound_is_refused(tmp_path: Path, max_range) -> None:
    """A maximum_range of 1e10 was read, then refused by the range rule naming no file."""
    line = robotlaser([1.0, 2.0], [0.5], [0, 0, 0], [0, 0, 0], 5.0, rmax=max_range)
    path = write(tmp_path / "rl.log", line + "\n")
    message = (
        r"rl\.log:1: ROBOTLASER1 maximum_range: "
        r"max_range must be a finite number in \(0, 1e\+09\] m"
    )
    with pytest.raises(LogFormatError, match=message):
        read_carmen_log(path)


@pytest.mark.parametrize("value", ["fifty", "8_0"])  # float() read 8_0 as 80
def test_bad_max_range_param(tmp_path: Path, value: str) -> None:
    text = f"# a log\nPARAM robot_front_laser_max {value}\n" + GOOD_FLASER
    message = rf"p\.log:2: PARAM robot_front_laser_max '{value}' is not a number"
    with pytest.raises(LogFormatError, match=message):
        read_carmen_log(write(tmp_path / "p.log", text))


# --- real data ---------------------------------------------------------------------------------


def test_intel_corrected(shared_data: Path) -> None:
    log = read_carmen_log(shared_data / "carmen" / "intel-corrected.log.gz")
    scans = log.scans
    assert scans.ranges.shape == (910, 180)
    assert len(log.odometry) == 14541
    # First and last FLASER as zcat shows them.
    assert scans.times[0] == 32.9068
    np.testing.assert_array_equal(scans.poses[0], [0.600266, -0.0320327, -0.354665])
    np.testing.assert_array_equal(scans.ranges[0, :3], np.float32([1.09, 1.08, 1.08]))
    np.testing.assert_array_equal(scans.ranges[0, -2:], np.float32([1.22, 1.23]))
    np.testing.assert_array_equal(scans.ranges[-1, :3], np.float32([1.01, 1.01, 1.01]))
    np.testing.assert_array_equal(scans.poses[-1], [-0.596494, -0.101202, 0.0119294])
    assert scans.times[-1] == 2683.77
    np.testing.assert_array_equal(log.odometry.poses[-1], [-0.322783, -0.0967671, 0.00578343])
    assert log.odometry.times[-1] == 2691.29
    # No PARAM robot_front_laser_max: the no-return value 81.83 is the largest reading.
    assert scans.max_range == float(np.float32(81.83))
    assert log.params == {"robot_frontlaser_offset": "0.0", "robot_rearlaser_offset": "0.0"}


def test_freiburg_079_corrected(shared_data: Path) -> None:
    log = read_carmen_log(shared_data / "carmen" / "freiburg-079-corrected.log.gz")
    scans = log.scans
    assert scans.ranges.shape == (4791, 360)
    assert len(log.odometry) == 9725
    np.testing.assert_array_equal(scans.poses[0], [0.00123601, -0.00106807, 2.85e-05])
    np.testing.assert_array_equal(scans.ranges[-1, :3], np.float32([6.5, 9.9, 12.5]))
    np.testing.assert_array_equal(scans.poses[-1], [0.0319692, -0.94701, -1.8314])
    assert scans.max_range == float(np.float32(80.99))  # PARAM robot_front_laser_max
    assert np.all(scans.ranges[scans.ranges >= scans.max_range] == np.float32(81.91))
    np.testing.assert_allclose(np.diff(scans.angles), np.pi / 360)


def carmen_logs(shared_data: Path) -> list[Path]:
    logs = sorted((shared_data / "carmen").glob("*.log.gz"))
    assert len(logs) >= 4
    return logs


def test_every_log_has_plausible_corrected_path(shared_data: Path) -> None:
    for path in carmen_logs(shared_data):
        scans = read_carmen_log(path).scans
        assert len(scans) > 100, path
        step = np.hypot(*np.diff(scans.poses[:, :2], axis=0).T)
        turn = np.abs(np.angle(np.exp(1j * np.diff(scans.poses[:, 2]))))
        # A wheeled indoor robot between two scans of a corrected log (largest seen: 1.78 m and
        # 1.37 rad in CSAIL; ACES and CSAIL keep a scan about every metre).
        assert step.max() < 2.0, path
        assert turn.max() < np.pi / 2, path
        assert np.sum(step) > 100.0, path  # the robot did travel
        # Every log has some no-return beams and the rule does not swallow real returns.
        no_return = np.mean(scans.ranges >= scans.max_range)
        assert 0.001 < no_return < 0.05, path
        assert np.all(scans.ranges > 0), path


def test_corrected_logs_hold_no_raw_odometry(shared_data: Path) -> None:
    # Documented in the reader: FLASER odom_* repeats the corrected pose in these logs.
    for path in carmen_logs(shared_data):
        scans = read_carmen_log(path).scans
        np.testing.assert_array_equal(scans.odometry, scans.poses, err_msg=str(path))


@pytest.mark.parametrize(
    ("text", "needle"),
    [
        (
            "PARAM robot_front_laser_max 1e10 nohost 0\n" + GOOD_FLASER,
            ":1: PARAM robot_front_laser_max",
        ),
        (
            flaser([1.0, 1e10], [0] * 3, [0] * 3, 1.0),
            ": the largest reading \\(the maximum range\\)",
        ),
    ],
)
def test_a_maximum_range_past_a_billion_metres_is_refused_naming_the_log(tmp_path, text, needle):
    """1e10 m was read, and the map built from the log refused it naming no file."""
    path = write(tmp_path / "far.log", text + "\n")
    with pytest.raises(LogFormatError, match=f"far\\.log{needle}.*in \\(0, 1e\\+09\\] m"):
        read_carmen_log(path)
