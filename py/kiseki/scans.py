# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Laser scans of one log, as kiseki's own type: what every log reader returns and what the
localization pipelines take, with the one rule every reader applies to what it reads.

:class:`LaserScans` is made by the readers of recorded data (``kiseki.datasets``: CARMEN logs,
the CMU Wean Hall logs, ROS bags) and by simulated runs
(``kiseki.io.runlog.SimRun.laser_scans``), so a simulated run replays through the interface
of a real log. Readers and the simulator import it from here, not from one another.

Each reader's docstring says what its logs put in the fields (which pose is the laser's, whether
the odometry is raw, how ``max_range`` was found). What every reader does alike:

* **Range readings** (:func:`apply_range_rule`): a reading that measured no distance -- NaN,
  ``-inf``, negative or zero -- is *invalid*: it is stored as NaN, which every sensor model,
  map builder and local map of kiseki skips (never a hit, never free space), and it is counted
  (:attr:`LaserScans.invalid_ranges`), not refused. A reading of ``+inf`` ("nothing within
  range", as ROS' REP 117 has it) is a *no return* and is stored as ``max_range``; a reading at
  or beyond ``max_range`` is a no return too, as it always was. A log without a stated maximum
  range takes its largest finite reading, or its no-return value when a few stray readings lie
  above it (:func:`largest_reading`).
* **Other fields** (poses, odometry, timestamps) that are NaN or infinite are errors naming the
  file and the line or scan, as before.
* **Odometry jumps** (:func:`check_odometry_jumps`): two consecutive scans whose odometry lies
  more than :data:`MAX_ODOMETRY_JUMP` metres apart make the log an error naming both scans and
  their times. The limit is the engine's own (``kiseki._core.MAX_ODOMETRY_JUMP``), which the
  filter checks again at every update.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from kiseki import _core
from kiseki._support.real_numbers import check_number
from kiseki._support.schema import MAGNITUDE_LIMIT
from kiseki.errors import LogFormatError

__all__ = [
    "MAX_ODOMETRY_JUMP",
    "LaserScans",
    "apply_range_rule",
    "beams_of_one_turn",
    "check_log_max_range",
    "check_max_range",
    "check_odometry_jumps",
    "largest_reading",
]

# Metres between two consecutive scans (and between two filter updates): the engine's
# kMaxOdometryJump, 10 m. That is over five times the largest step between consecutive scans in
# the seven recorded logs kiseki reads (CSAIL 1.78 m, ACES 1.54 m, Intel 1.15 m, Freiburg 079
# 0.34 m, Wean 0.20 m), and a robot at 2 m/s would need 5 s without a scan; a longer step is a
# fault of the log (an odometry reset, a corrupt value), which the filter would take as a motion.
MAX_ODOMETRY_JUMP: float = float(_core.MAX_ODOMETRY_JUMP)


@dataclass(frozen=True, eq=False)
class LaserScans:
    """Laser scans of one log, in file order."""

    times: np.ndarray  # (N,) float64 message timestamp, seconds
    poses: np.ndarray  # (N, 3) float64 laser pose in the log (x, y, theta); NaN if it has none
    odometry: np.ndarray  # (N, 3) float64 odometry pose as logged (see the reader's docstring)
    ranges: np.ndarray  # (N, B) float32 metres, C-contiguous; NaN: invalid (skipped)
    angles: np.ndarray  # (B,) float64 beam angles in the laser frame, radians
    max_range: float  # readings >= max_range mean no return

    def __post_init__(self) -> None:
        # the fields must describe the same scans: with times or odometry shorter than the
        # ranges, localize returned an estimate for only the shorter one's scans, without a word
        for name in ("times", "angles"):
            if np.ndim(getattr(self, name)) != 1:
                raise ValueError(
                    f"LaserScans: {name} has shape {np.shape(getattr(self, name))}, expected one "
                    "value per " + ("scan" if name == "times" else "beam")
                )
        n, b = len(self.times), len(self.angles)
        for name, shape in (("poses", (n, 3)), ("odometry", (n, 3)), ("ranges", (n, b))):
            if np.shape(getattr(self, name)) != shape:
                raise ValueError(
                    f"LaserScans: {name} has shape {np.shape(getattr(self, name))}, expected "
                    f"{shape} ({n} scans in times, {b} beams in angles)"
                )
        check_max_range("LaserScans", self.max_range)

    def __len__(self) -> int:
        return int(self.times.shape[0])

    def first(self, n: int) -> LaserScans:
        """The first n scans (all of them when n is 0 or at least the log's length)."""
        if n < 0:
            raise ValueError(f"first: n must be >= 0, got {n}")
        if not n or n >= len(self):
            return self
        return LaserScans(
            self.times[:n],
            self.poses[:n],
            self.odometry[:n],
            np.ascontiguousarray(self.ranges[:n]),
            self.angles,
            self.max_range,
        )

    @property
    def has_reference_poses(self) -> bool:
        """False for logs without reference poses (e.g. the Wean Hall logs: ``poses`` all NaN)."""
        return bool(np.isfinite(self.poses).all())

    @property
    def invalid_ranges(self) -> int:
        """The number of invalid readings, which the models skip: NaN after a reader's
        :func:`apply_range_rule` (any NaN, ``-inf``, negative or zero reading)."""
        return int(np.count_nonzero(~(np.asarray(self.ranges) > 0)))


NO_RETURN_READINGS = 100
"""Readings of one value, and scans that hold it, that make it a logger's no-return value for
:func:`largest_reading`: the shared logs write theirs hundreds to thousands of times (Intel
4,172, ACES 620, Wean 693 to 11,285), in hundreds of scans; a flat wall seen by 179 beams of one
scan is not one."""
NO_RETURN_SCANS = 10
STRAY_SHARE = 0.01
"""The most readings above a no-return value, as a share of its count, that
:func:`largest_reading` takes as corrupt (one in the Intel log would be 0.02 %)."""


def check_max_range(where: str, max_range) -> float:
    """``max_range`` as a float: a number in (0, MAGNITUDE_LIMIT] m, refused naming ``where``
    otherwise (a NaN one compared false with every reading, so that every reading counted as an
    endpoint; 1e300 overflowed the float32 readings it is compared with)."""
    return check_number(
        max_range, f"{where}: max_range", 0.0, MAGNITUDE_LIMIT, low_open=True, unit="m"
    )


def check_log_max_range(where: str, max_range) -> float:
    """:func:`check_max_range` for a maximum range a log states or gives (a PARAM, a laser
    message's field, its largest reading): a LogFormatError naming ``where`` (the file, and its
    line where there is one) instead of a ValueError."""
    try:
        return check_max_range(where, max_range)
    except ValueError as err:
        raise LogFormatError(str(err)) from None


def largest_reading(ranges: np.ndarray) -> float | None:
    """The no-return value of a log that does not state its maximum range: its largest finite,
    positive reading (float32), or None if there is no valid reading -- unless a value below the
    largest is the logger's (at least ``NO_RETURN_READINGS`` readings in at least
    ``NO_RETURN_SCANS`` scans report it) and the readings above it are at most ``STRAY_SHARE``
    of its count. A logger writes its no-return value on many beams of many scans (81.83 m in
    4,172 readings of the Intel log); one corrupt reading above it (500 m in an 80 m laser's
    log), taken as the maximum range, made every real no return a wall. Those few readings are
    no returns themselves (``>= max_range``). A log without such a value (a short one, one
    without no returns) keeps its largest reading."""
    with np.errstate(over="ignore"):  # beyond float32: +inf, a no return
        rows = np.atleast_2d(np.asarray(ranges, dtype=np.float32))
    rows = rows.reshape(len(rows), -1)
    valid = rows[np.isfinite(rows) & (rows > 0)]
    if valid.size == 0:
        return None
    values, counts = np.unique(valid, return_counts=True)
    above = 0  # readings above the value looked at
    for k in range(len(values) - 1, -1, -1):
        if above > STRAY_SHARE * counts[k]:
            break  # more above than strays: the largest reading is the log's own
        if counts[k] >= NO_RETURN_READINGS and (
            np.count_nonzero((rows == values[k]).any(axis=1)) >= NO_RETURN_SCANS
        ):
            return float(values[k])
        above += int(counts[k])
    return float(values[-1])


def beams_of_one_turn(start: float, step: float, beams: int) -> bool:
    """Whether ``beams`` beams from ``start`` every ``step`` rad are a scanner's: a finite start
    within +-2 pi, a finite non-zero step (any finite step for a single beam), and one turn at
    most (a sliver over it for rounding). A log's step of 0 put every beam on one ray; 1000 rad,
    or a start of 1e30, were read as given."""
    span = abs(step) * (beams - 1)
    moves = step != 0 or beams == 1
    return bool(abs(start) <= 2 * math.pi and moves and span <= 2.01 * math.pi)


def apply_range_rule(ranges: np.ndarray, max_range: float) -> np.ndarray:
    """Readings as kiseki keeps them (float32, C-contiguous, a new array): invalid readings
    (NaN, -inf, negative, zero) as NaN, +inf (no return) as ``max_range``."""
    max_range = check_max_range("apply_range_rule", max_range)  # -1 was every no return
    with np.errstate(over="ignore", invalid="ignore"):  # beyond float32: +inf, a no return
        out = np.array(ranges, dtype=np.float32, order="C", copy=True)
        out[~(out > 0)] = np.nan
    out[np.isposinf(out)] = np.float32(max_range)
    return out


def check_odometry_jumps(
    source: str | os.PathLike,
    times: np.ndarray,
    odometry: np.ndarray,
    lines: Sequence[int] | None = None,
) -> None:
    """Raises LogFormatError (naming ``source``, the two scans, their times and, with ``lines``,
    their line numbers) at the first pair of consecutive scans whose odometry positions lie more
    than :data:`MAX_ODOMETRY_JUMP` apart. Scans without odometry (NaN) are not compared. Scan
    numbers count from 0 in the order of the LaserScans."""
    odometry = np.asarray(odometry, dtype=np.float64)
    if len(odometry) < 2:
        return
    with np.errstate(over="ignore", invalid="ignore"):
        steps = np.hypot(*(odometry[1:, :2] - odometry[:-1, :2]).T)
        jumps = steps > MAX_ODOMETRY_JUMP
    if not jumps.any():
        return
    k = int(np.argmax(jumps))

    def scan(i: int) -> str:
        line = f"line {lines[i]}, " if lines is not None else ""
        return f"scan {i} ({line}t = {float(times[i]):.3f} s)"

    raise LogFormatError(
        f"{source}: odometry jumps {steps[k]:.4g} m between {scan(k)} and {scan(k + 1)}: more "
        f"than kiseki's limit of {MAX_ODOMETRY_JUMP:g} m between two scans (a fault of the log, "
        "such as an odometry reset, not a motion)"
    )
