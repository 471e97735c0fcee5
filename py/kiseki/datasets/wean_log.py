# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Reader for the CMU Wean Hall robot logs (``robotdata1.log.gz`` ...; plain text or gzip).

Lines, units centimetres and radians, as described by the data set's ``instruct.txt``::

    O x y theta ts                                odometry of the robot centre
    L x y theta xl yl thetal r1 .. r180 ts        a laser scan: robot and laser pose in the
                                                  odometry frame (interpolated), 180 ranges

The scans become a :class:`~kiseki.scans.LaserScans` in metres:

* ``odometry`` is the *laser* pose ``xl yl thetal`` of each ``L`` line (the laser sits 25 cm ahead
  of the robot centre), because the particle filters of kiseki track sensor poses;
* ``poses`` is all NaN: the logs carry raw odometry only, no reference pose
  (``LaserScans.has_reference_poses`` is False), so they are for global localization;
* the 180 beams start at the right and go counter-clockwise, one degree apart, i.e. the angles
  of a CARMEN FLASER with 180 beams (``-pi/2 + i * pi/180``);
* ``max_range`` is the largest (finite) reading of the log: the SICK's no-return code (8183 cm
  in robotdata1, 8191 cm in robotdata2 and 3), as the CARMEN reader does for logs without a
  max-range PARAM (``kiseki.scans.largest_reading``, which takes a few corrupt readings above
  that code as no returns);
* ranges follow kiseki's rule (``kiseki.scans``): NaN, ``-inf``, negative and zero readings are
  invalid, kept as NaN and counted; ``+inf`` is a no return. Any other field that is NaN or
  infinite is an error naming the line, and so is an odometry jump of more than
  ``kiseki.scans.MAX_ODOMETRY_JUMP`` between two consecutive ``L`` lines.

Recognised by content: the first non-empty line starts with ``O`` or ``L`` followed by a number.
The ``O`` lines are returned too (:class:`WeanLog`), but the scans do not need them.
"""

from __future__ import annotations

import gzip
import os
import stat
import zlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from kiseki._support.inputs import GIB, check_input
from kiseki.datasets._files import GZIP_MAGIC, read_maybe_gzipped
from kiseki.datasets._log_numbers import log_numbers
from kiseki.datasets.carmen import flaser_angles
from kiseki.errors import LogFormatError
from kiseki.scans import (
    LaserScans,
    apply_range_rule,
    check_log_max_range,
    check_odometry_jumps,
    largest_reading,
)

__all__ = ["MAX_LOG_BYTES", "WeanLog", "is_wean_log", "read_wean_log"]

MAX_LOG_BYTES = 1 * GIB
"""A log's text (after gunzip) is read up to this size (``robotdata2.log.gz`` holds 1.9 MB), as
for CARMEN logs (:data:`kiseki.datasets.carmen.MAX_LOG_BYTES`)."""

BEAMS = 180
CM = 0.01  # metres per centimetre
_L_FIELDS = 1 + 6 + BEAMS + 1  # tag, two poses, ranges, timestamp
_O_FIELDS = 1 + 3 + 1


@dataclass(frozen=True, eq=False)
class WeanLog:
    """One Wean Hall log: its laser scans and its odometry lines (metres, radians, seconds)."""

    path: Path
    scans: LaserScans
    odometry_times: np.ndarray  # (M,) seconds
    odometry_poses: np.ndarray  # (M, 3) robot centre, odometry frame


def is_wean_log(path: str | os.PathLike) -> bool:
    """Whether the file looks like a Wean robotdata log: its first non-empty line is an ``O`` or
    ``L`` line starting with a number. Reads only the head of a regular file."""
    try:
        if not stat.S_ISREG(os.stat(path).st_mode):  # a FIFO would block, a device not end
            return False
        with Path(path).open("rb") as raw:
            magic = raw.read(2)
        opener = gzip.open if magic == GZIP_MAGIC else open
        with opener(path, "rt", encoding="latin-1") as handle:
            head = handle.read(4096)
    except (OSError, EOFError, zlib.error):
        return False
    for line in head.split("\n"):
        tokens = line.split()
        if not tokens:
            continue
        if tokens[0] not in ("O", "L") or len(tokens) < 2:
            return False
        try:  # leniently: a number read_wean_log refuses (1_0) is its to name
            float(tokens[1])
        except ValueError:
            return False
        return True
    return False


def read_wean_log(path: str | os.PathLike) -> WeanLog:
    """Read a Wean Hall robotdata log; a malformed line raises LogFormatError naming it."""
    path = Path(path)
    check_input(path, error=LogFormatError)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: log file not found")
    text = read_maybe_gzipped(path, LogFormatError, "Wean robotdata logs", MAX_LOG_BYTES)
    lasers: list[list[str]] = []
    laser_lines: list[int] = []
    odoms: list[list[str]] = []
    odom_lines: list[int] = []
    for lineno, line in enumerate(text.split("\n"), start=1):
        tokens = line.split()
        if not tokens:
            continue
        if tokens[0] == "L":
            _check(path, lineno, tokens, _L_FIELDS)
            lasers.append(tokens[1:])
            laser_lines.append(lineno)
        elif tokens[0] == "O":
            _check(path, lineno, tokens, _O_FIELDS)
            odoms.append(tokens[1:])
            odom_lines.append(lineno)
        else:
            raise LogFormatError(
                f"{path}:{lineno}: unknown line type {tokens[0][:20]!r} (expected O or L)"
            )
    if not lasers:
        raise LogFormatError(f"{path}: no laser (L) lines")
    values = log_numbers(path, laser_lines, lasers, ranges=slice(6, 6 + BEAMS))
    readings = values[:, 6 : 6 + BEAMS] * CM
    max_range = largest_reading(readings)
    if max_range is None:
        raise LogFormatError(f"{path}:{laser_lines[0]}: no valid range reading in any L line")
    check_log_max_range(f"{path}: the largest reading (the maximum range)", max_range)
    odometry = np.column_stack([values[:, 3:5] * CM, values[:, 5]])
    scans = LaserScans(
        times=values[:, -1].copy(),
        poses=np.full((len(values), 3), np.nan),
        odometry=odometry,
        ranges=apply_range_rule(readings, max_range),
        angles=flaser_angles(BEAMS),
        max_range=max_range,
    )
    check_odometry_jumps(path, scans.times, scans.odometry, laser_lines)
    odo = log_numbers(path, odom_lines, odoms) if odoms else np.empty((0, 4))
    return WeanLog(
        path=path,
        scans=scans,
        odometry_times=odo[:, 3].copy(),
        odometry_poses=np.column_stack([odo[:, :2] * CM, odo[:, 2]]),
    )


def _check(path: Path, lineno: int, tokens: list[str], expected: int) -> None:
    if len(tokens) != expected:
        raise LogFormatError(
            f"{path}:{lineno}: {tokens[0]} line has {len(tokens)} fields, expected {expected}"
        )
