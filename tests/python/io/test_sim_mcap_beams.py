# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The beam angles of a run log's laser scans obey the rule of the CARMEN and bag readers
(``kiseki.scans.beams_of_one_turn``): a start within +-2 pi, beams that do not all lie on one
ray, one turn at most. The writer refuses what the reader would refuse."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from foxglove_schemas_protobuf.LaserScan_pb2 import LaserScan
from mcap_protobuf.writer import Writer

from kiseki.errors import LogFormatError
from kiseki.io.runlog import RunWriter, read_run
from kiseki.scans import beams_of_one_turn


def write_scans(path: Path, start: float, end: float, beams: int, last_start=None) -> None:
    """Three scans of ``beams`` readings from ``start`` to ``end`` rad (the last from
    ``last_start`` if given), written as foxglove messages without kiseki's writer (a file from
    another tool)."""
    with open(path, "wb") as f, Writer(f) as writer:
        for k in range(3):
            ns = k * 100_000_000
            first = start if k < 2 or last_start is None else last_start
            message = LaserScan(start_angle=first, end_angle=end, ranges=[1.0 + k] * beams)
            message.timestamp.FromNanoseconds(ns)
            message.frame_id = "world"
            message.pose.orientation.w = 1.0
            writer.write_message("/scan", message, log_time=ns, publish_time=ns)


@pytest.mark.parametrize(
    ("start", "end", "beams", "what"),
    [
        (100.0, 101.0, 5, "start 100 rad"),
        (1e30, 1e30, 1, "one beam at 1e30 rad"),
        (math.nan, 1.0, 5, "a NaN start"),
        (0.5, math.inf, 5, "an infinite end"),
        (0.5, 0.5, 5, "five beams on one ray"),
        (-4.0, 4.0, 9, "8 rad: more than a turn"),
    ],
)
def test_reader_refuses_beams_that_are_not_one_turn(
    tmp_path: Path, start: float, end: float, beams: int, what: str
) -> None:
    path = tmp_path / "other.mcap"
    write_scans(path, start, end, beams)
    with pytest.raises(LogFormatError, match=r"other\.mcap: .*not beams of one turn") as err:
        read_run(path).laser_scans(truth_topic=None, odom_topic=None)
    assert "\n" not in str(err.value), what


@pytest.mark.parametrize("last_start", [math.nan, -1.0])
def test_reader_refuses_a_later_scan_with_other_angles(tmp_path: Path, last_start: float):
    path = tmp_path / "later.mcap"
    write_scans(path, -2.0, 2.0, 5, last_start=last_start)
    with pytest.raises(LogFormatError, match=r"later\.mcap: the scan at t=0\.2 .* other beam"):
        read_run(path).laser_scans(truth_topic=None, odom_topic=None)


@pytest.mark.parametrize(
    ("start", "end", "beams"),
    [(0.3, 0.3, 1), (-math.pi, math.pi, 361), (-2.0, 2.0, 5)],
)
def test_reader_keeps_a_scanners_beams(tmp_path: Path, start: float, end: float, beams: int):
    path = tmp_path / "ok.mcap"
    write_scans(path, start, end, beams)
    scans = read_run(path).laser_scans(truth_topic=None, odom_topic=None)
    np.testing.assert_allclose(scans.angles, np.linspace(start, end, beams), rtol=0, atol=1e-12)
    np.testing.assert_array_equal(scans.ranges[:, 0], [1.0, 2.0, 3.0])


@pytest.mark.parametrize("angles", [[7.0, 7.1, 7.2], np.linspace(-4.0, 4.0, 9).tolist(), [-7.0]])
def test_writer_refuses_angles_its_reader_would_refuse(tmp_path: Path, angles: list) -> None:
    with RunWriter(tmp_path / "run.mcap") as w, pytest.raises(ValueError, match="not beams of"):
        w.write_laser_scan("/scan", 0.0, (0, 0, 0), angles, [1.0] * len(angles))


@pytest.mark.parametrize(
    ("start", "step", "beams", "kept"),
    [
        (0.3, 0.0, 1, True),  # one beam: its step says nothing
        (0.3, 0.0, 2, False),  # two beams on one ray
        (-math.pi, 2 * math.pi / 360, 361, True),  # a whole turn, both ends
        (-math.pi, 2 * math.pi / 300, 361, False),  # past a turn
        (7.0, 0.01, 1, False),  # one beam, but a start past 2 pi
        (0.3, math.nan, 1, False),
        (0.3, math.inf, 3, False),
    ],
)
def test_the_one_turn_rule_case_by_case(start: float, step: float, beams: int, kept: bool):
    """The rule the CARMEN, bag and run-log readers share (kiseki.scans.beams_of_one_turn)."""
    assert beams_of_one_turn(start, step, beams) is kept
