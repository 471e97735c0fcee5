# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Reader for CARMEN laser logs (plain text or gzip), such as the Radish "-corrected" logs.

Messages read, one per line (``#`` lines are comments)::

    FLASER n r1..rn x y theta odom_x odom_y odom_theta timestamp hostname logger_timestamp
    ROBOTLASER1 laser_type start_angle fov angular_resolution maximum_range accuracy
        remission_mode n r1..rn k rem1..remk laser_x laser_y laser_theta robot_x robot_y
        robot_theta tv rv forward_safety_dist side_safety_dist turn_axis timestamp hostname
        logger_timestamp
    ODOM x y theta tv rv accel timestamp hostname logger_timestamp
    PARAM name value ...

Laser scans come from the FLASER messages; only a log without FLASER uses its ROBOTLASER1
messages. Everything else (RLASER rear laser, RAWLASER*, NEFF, SYNC, TRUEPOS, ...) is skipped.
Remission values of ROBOTLASER1 are skipped too. A PARAM value is its first token. All laser
messages used must have the same beam count (LogFormatError otherwise; no Radish log mixes them).

FLASER beam angles follow CARMEN's own reader (``carmen_laser_guess_angle_increment``): the first
beam is at -pi/2 (right) and beams go counter-clockwise with a step of pi/180 for 180 or 181
beams, pi/360 for 360 or 361 and pi/720 for 400 or 401, otherwise pi/(n-1). So 181 and 361 beams
span [-pi/2, pi/2], and 180 and 360 beams stop one step short of +pi/2. The ``laser_front_laser_*``
PARAMs are not used, just as CARMEN ignores them for FLASER. ROBOTLASER1 messages carry their own
``start_angle + i * angular_resolution``.

Max range (readings >= ``max_range`` mean "no return"): the PARAM ``robot_front_laser_max`` if
present, else the largest reading in the log, which is the no-return value the logger wrote
(``kiseki.scans.largest_reading``: a few corrupt readings above a value the logger wrote many
times are no returns themselves; a log without any no-return reading would lose its single
largest return this way). For
ROBOTLASER1 it is the message's ``maximum_range`` field. The value is rounded to float32, like the
ranges, so the comparison gives the same answer in float32 and float64. In the Radish logs:
Intel has no PARAM and no returns are 81.83; ACES has no PARAM and readings are clipped at 50;
CSAIL has ``robot_front_laser_max 50`` and no returns are 81.91 (largest return 35.12);
Freiburg 079 has ``robot_front_laser_max 80.99`` and no returns are 81.91.

Range readings follow kiseki's rule (``kiseki.scans``): NaN, ``-inf``, negative and zero readings
are invalid, kept as NaN and counted (``LaserScans.invalid_ranges``), ``+inf`` is a no return
(stored as ``max_range``), and the largest reading above is the largest finite one. Any other
field that is NaN or infinite is an error naming the line, and so is an odometry jump of more
than ``kiseki.scans.MAX_ODOMETRY_JUMP`` between two consecutive laser messages.

Records are returned in file order and as written, with no sorting or filtering. Facts of the
Radish "-corrected" logs (Intel, ACES, CSAIL, Freiburg 079) that users should know:

* the FLASER ``odom_*`` fields equal the corrected ``x y theta`` fields, and the ODOM messages
  follow the corrected path too, so none of them is raw odometry: make noisy odometry from the
  increments of the corrected poses;
* almost every FLASER is followed by an ODOM with timestamp 0 that repeats its pose, so ODOM
  times are not sorted; a few Intel FLASER timestamps also step back (by up to 0.86 s);
* the CSAIL log writes timestamps with 6 significant digits (``1.13486e+09``): 10 s steps.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from kiseki._support.inputs import GIB
from kiseki._support.numbers_text import parse_float, parse_int
from kiseki.datasets._files import read_maybe_gzipped
from kiseki.datasets._log_numbers import log_numbers
from kiseki.errors import LogFormatError
from kiseki.scans import (
    LaserScans,
    apply_range_rule,
    beams_of_one_turn,
    check_log_max_range,
    check_odometry_jumps,
    largest_reading,
)

__all__ = [
    "MAX_LOG_BYTES",
    "CarmenLog",
    "OdometryRecords",
    "flaser_angles",
    "read_carmen_log",
]

MAX_LOG_BYTES = 1 * GIB
"""A log's text (after gunzip) is read up to this size: the largest Radish logs hold a few hundred
MB, and parsing takes about 16 times the text's size in memory (Freiburg 079: 9.5 MB of text,
160 MB)."""

_MAX_RANGE_PARAM = "robot_front_laser_max"
# Step of CARMEN's FLASER guess for the usual SICK beam counts.
_FLASER_STEPS = {
    180: np.pi / 180,
    181: np.pi / 180,
    360: np.pi / 360,
    361: np.pi / 360,
    400: np.pi / 720,
    401: np.pi / 720,
}

_Row = tuple[int, list[str]]  # (1-based line number, whitespace-separated tokens)
_Param = tuple[int, str]  # a PARAM's (1-based line number, value text)


@dataclass(frozen=True, eq=False)
class OdometryRecords:
    """ODOM messages of one log, in file order."""

    times: np.ndarray  # (M,) float64 seconds
    poses: np.ndarray  # (M, 3) float64 x, y, theta
    velocities: np.ndarray  # (M, 2) float64 tv (m/s), rv (rad/s)

    def __len__(self) -> int:
        return int(self.times.shape[0])


@dataclass(frozen=True, eq=False)
class CarmenLog:
    """Everything kiseki reads from one CARMEN log."""

    path: Path
    scans: LaserScans
    odometry: OdometryRecords
    params: dict[str, str]


def flaser_angles(num_beams: int) -> np.ndarray:
    """Beam angles (radians, laser frame) CARMEN assumes for a FLASER with ``num_beams``."""
    if num_beams < 2:
        raise ValueError(f"a FLASER needs at least 2 beams, got {num_beams}")
    step = _FLASER_STEPS.get(num_beams, np.pi / (num_beams - 1))
    return -np.pi / 2 + step * np.arange(num_beams, dtype=np.float64)


def read_carmen_log(path: str | os.PathLike) -> CarmenLog:
    """Read a CARMEN log (gzip if the file starts with the gzip magic bytes)."""
    path = Path(path)
    rows, params = _split_messages(path, _read_text(path))
    if rows["FLASER"]:
        scans = _parse_flaser(path, rows["FLASER"], params)
    elif rows["ROBOTLASER1"]:
        scans = _parse_robotlaser(path, rows["ROBOTLASER1"])
    else:
        raise LogFormatError(f"{path}: no FLASER or ROBOTLASER1 messages")
    odometry = _parse_odom(path, rows["ODOM"])
    values = {name: text for name, (_, text) in params.items()}
    return CarmenLog(path=path, scans=scans, odometry=odometry, params=values)


def _read_text(path: Path) -> str:
    text = read_maybe_gzipped(path, LogFormatError, "CARMEN logs", MAX_LOG_BYTES)
    if not text.strip():
        raise LogFormatError(f"{path}: empty log")
    return text


def _split_messages(path: Path, text: str) -> tuple[dict[str, list[_Row]], dict[str, _Param]]:
    """The rows of each message read, and each PARAM's line and value (the last one given)."""
    rows: dict[str, list[_Row]] = {"FLASER": [], "ROBOTLASER1": [], "ODOM": []}
    params: dict[str, _Param] = {}
    for lineno, line in enumerate(text.split("\n"), start=1):
        tokens = line.split()
        if not tokens or tokens[0].startswith("#"):
            continue
        kind = tokens[0]
        if kind in rows:
            rows[kind].append((lineno, tokens))
        elif kind == "PARAM":
            if len(tokens) < 3:
                raise LogFormatError(f"{path}:{lineno}: PARAM needs a name and a value")
            params[tokens[1]] = (lineno, tokens[2])
    return rows, params


def _int_field(path: Path, lineno: int, token: str, what: str) -> int:
    try:
        value = parse_int(token)
    except ValueError:
        raise LogFormatError(f"{path}:{lineno}: {what} {token!r} is not an integer") from None
    if value < 0:
        raise LogFormatError(f"{path}:{lineno}: {what} {value} is negative")
    return value


def _check_count(path: Path, lineno: int, tokens: list[str], expected: int, kind: str) -> None:
    if len(tokens) != expected:
        msg = f"{path}:{lineno}: {kind} has {len(tokens)} fields, expected {expected}"
        raise LogFormatError(msg)


def _check_min_count(path: Path, lineno: int, tokens: list[str], minimum: int, kind: str) -> None:
    if len(tokens) < minimum:
        msg = f"{path}:{lineno}: {kind} has {len(tokens)} fields, expected at least {minimum}"
        raise LogFormatError(msg)


def _laser_scans(
    path: Path,
    rows: Sequence[_Row],
    values: np.ndarray,
    columns: tuple[int, int, int],
    angles: np.ndarray,
    max_range: float | None,
    kind: str,
) -> LaserScans:
    """The scans of laser messages whose ``values`` hold, from ``columns``, the ranges, then
    the laser pose and odometry (6 values), then the timestamp: the ranges by kiseki's rule
    (``max_range`` None: ``largest_reading``), the odometry checked for jumps."""
    first, pose, time = columns
    readings = values[:, first : first + len(angles)]
    if max_range is None:
        max_range = largest_reading(readings)
        if max_range is None:
            raise LogFormatError(f"{path}:{rows[0][0]}: no valid range reading in any {kind}")
        check_log_max_range(f"{path}: the largest reading (the maximum range)", max_range)
    scans = LaserScans(
        times=values[:, time].copy(),
        poses=values[:, pose : pose + 3].copy(),
        odometry=values[:, pose + 3 : pose + 6].copy(),
        ranges=apply_range_rule(readings, max_range),
        angles=angles,
        max_range=max_range,
    )
    lines = [lineno for lineno, _ in rows]
    check_odometry_jumps(path, scans.times, scans.odometry, lines)
    return scans


def _parse_flaser(path: Path, rows: list[_Row], params: dict[str, _Param]) -> LaserScans:
    first_line, first = rows[0]
    _check_min_count(path, first_line, first, 2, "FLASER")
    n = _int_field(path, first_line, first[1], "FLASER beam count")
    if n < 2:
        raise LogFormatError(f"{path}:{first_line}: FLASER beam count {n} is below 2")
    fields = []
    for lineno, tokens in rows:
        _check_min_count(path, lineno, tokens, 2, "FLASER")
        if tokens[1] != first[1] and _int_field(path, lineno, tokens[1], "beam count") != n:
            msg = f"{path}:{lineno}: FLASER has {tokens[1]} beams, line {first_line} has {n}"
            raise LogFormatError(msg)
        _check_count(path, lineno, tokens, n + 11, "FLASER")
        fields.append(tokens[2 : n + 9] + tokens[n + 10 :])  # skip count and hostname
    values = log_numbers(path, [r[0] for r in rows], fields, "FLASER", ranges=slice(0, n))
    max_range = _flaser_max_range(path, params)
    return _laser_scans(path, rows, values, (0, n, n + 6), flaser_angles(n), max_range, "FLASER")


def _flaser_max_range(path: Path, params: dict[str, _Param]) -> float | None:
    if _MAX_RANGE_PARAM not in params:
        return None
    lineno, text = params[_MAX_RANGE_PARAM]
    where = f"{path}:{lineno}: PARAM {_MAX_RANGE_PARAM} {text!r}"
    try:
        value = float(np.float32(parse_float(text)))
    except ValueError:
        raise LogFormatError(f"{where} is not a number") from None
    return check_log_max_range(where, value)  # 1e10 was read, refused by the map naming no file


def _robotlaser_fields(path: Path, lineno: int, tokens: list[str]) -> list[str]:
    """Numeric fields of one ROBOTLASER1: config(4), ranges(n), poses(6), timestamp."""
    kind = "ROBOTLASER1"
    _check_min_count(path, lineno, tokens, 24, kind)
    n = _int_field(path, lineno, tokens[8], "ROBOTLASER1 beam count")
    _check_min_count(path, lineno, tokens, n + 24, kind)
    k = _int_field(path, lineno, tokens[9 + n], "ROBOTLASER1 remission count")
    _check_count(path, lineno, tokens, n + k + 24, kind)
    base = 10 + n + k
    return tokens[2:6] + tokens[9 : 9 + n] + tokens[base : base + 6] + [tokens[base + 11]]


def _parse_robotlaser(path: Path, rows: list[_Row]) -> LaserScans:
    fields = [_robotlaser_fields(path, lineno, tokens) for lineno, tokens in rows]
    n = len(fields[0]) - 11
    for (lineno, _), row in zip(rows, fields, strict=True):
        if len(row) - 11 != n:
            msg = f"{path}:{lineno}: ROBOTLASER1 has {len(row) - 11} beams, the first has {n}"
            raise LogFormatError(msg)
    values = log_numbers(path, [r[0] for r in rows], fields, "ROBOTLASER1", ranges=slice(4, 4 + n))
    config = values[:, :4]  # start_angle, fov, angular_resolution, maximum_range
    changed = (config != config[0]).any(axis=1)
    if changed.any():
        lineno = rows[int(np.argmax(changed))][0]
        raise LogFormatError(f"{path}:{lineno}: ROBOTLASER1 laser configuration changes")
    start, _, step, max_range = config[0]
    if n == 0:
        raise LogFormatError(f"{path}:{rows[0][0]}: ROBOTLASER1 with no beams")
    # 1e10 was read, then refused by the range rule naming no file
    where = f"{path}:{rows[0][0]}: ROBOTLASER1 maximum_range"
    max_range = check_log_max_range(where, float(np.float32(max_range)))
    if not beams_of_one_turn(start, step, n):
        raise LogFormatError(
            f"{path}:{rows[0][0]}: ROBOTLASER1 start_angle {start:g} and angular_resolution "
            f"{step:g} rad for {n} beams: not beams of one turn at most (start within +-2 pi, "
            "a non-zero resolution)"
        )
    angles = start + step * np.arange(n, dtype=np.float64)
    limit = float(np.float32(max_range))
    return _laser_scans(path, rows, values, (4, n + 4, n + 10), angles, limit, "ROBOTLASER1")


def _parse_odom(path: Path, rows: list[_Row]) -> OdometryRecords:
    if not rows:
        empty = np.empty((0, 3))
        return OdometryRecords(times=np.empty(0), poses=empty, velocities=np.empty((0, 2)))
    for lineno, tokens in rows:
        _check_count(path, lineno, tokens, 10, "ODOM")
    fields = [tokens[1:8] + tokens[9:] for _, tokens in rows]  # skip hostname
    values = log_numbers(path, [r[0] for r in rows], fields, "ODOM")
    return OdometryRecords(
        times=values[:, 6].copy(),
        poses=values[:, 0:3].copy(),
        velocities=values[:, 3:5].copy(),
    )
