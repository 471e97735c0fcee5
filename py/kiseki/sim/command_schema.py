# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The model of a velocity-command script (``kiseki sim run --controller commands --commands
FILE``): a CSV whose header is ``t,v,w`` (diff drive: m/s, rad/s) or ``t,vx,vy,w`` (omni), one
command a row, each holding from its time (s) until the next row's::

    t,v,w
    0,0.5,0        # '#' starts a comment; blank lines are skipped
    4.0,0.3,0.25

A problem is one line naming the file, the line number, the column and the value
(``cmd.csv:3: v: must be a finite number, got 'nan'``); the script is limited to
:data:`MAX_COMMANDS` rows and :data:`MAX_COMMAND_SECONDS` of simulated time, with the limit in
the message."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Annotated

import numpy as np
from pydantic import Field

from kiseki._support.csv import CsvNumber, data_rows
from kiseki._support.inputs import CSV_LIMIT, check_input, read_input_text
from kiseki._support.schema import MAGNITUDE_LIMIT, FileModel, parse

__all__ = [
    "HEADERS",
    "MAX_COMMANDS",
    "MAX_COMMAND_SECONDS",
    "check_command_array",
    "DiffDriveCommand",
    "OmniCommand",
    "read_command_rows",
]

MAX_COMMANDS = 1_000_000  # rows: 32 MB of commands, a day at 10 Hz is 864,000
MAX_COMMAND_SECONDS = 86_400.0  # a run is at most a day of simulated time (kiseki.sim.run)


Number = CsvNumber
Seconds = Annotated[CsvNumber, Field(ge=0, le=MAX_COMMAND_SECONDS)]


class DiffDriveCommand(FileModel):
    """A row of ``t,v,w``: from time t (s), forward speed v (m/s) and turn rate w (rad/s)."""

    t: Seconds
    v: Number
    w: Number


class OmniCommand(FileModel):
    """A row of ``t,vx,vy,w``: from time t (s), body velocity (vx, vy) (m/s), turn rate w."""

    t: Seconds
    vx: Number
    vy: Number
    w: Number


HEADERS: dict[str, type[FileModel]] = {"t,v,w": DiffDriveCommand, "t,vx,vy,w": OmniCommand}


def read_command_rows(path: str | os.PathLike) -> np.ndarray:
    """The command script at `path` as an (n, len(header)) array in the header's column order:
    FileNotFoundError when there is none, ValueError naming the file (and the line, the column
    and the value) otherwise."""
    path = Path(path)
    check_input(path)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: command file not found")
    try:
        lines = read_input_text(path, "command CSV files", CSV_LIMIT).splitlines()
    except UnicodeDecodeError:
        raise ValueError(f"{path}: not a command CSV (not UTF-8 text)") from None
    if not lines:
        raise ValueError(f"{path}: empty command file (header t,v,w or t,vx,vy,w)")
    header = ",".join(cell.strip() for cell in lines[0].split(","))
    if header not in HEADERS:
        raise ValueError(f"{path}: header must be t,v,w or t,vx,vy,w, got {lines[0][:60]!r}")
    model, columns = HEADERS[header], header.split(",")
    rows: list[list[float]] = []
    for number, cells, line in data_rows(lines):
        where = f"{path}:{number}"
        if len(cells) != len(columns):
            raise ValueError(f"{where}: a row is {header} ({len(columns)} values), got {line!r}")
        if len(rows) == MAX_COMMANDS:
            raise ValueError(f"{where}: a command script holds at most {MAX_COMMANDS:,} rows")
        row = parse(model, dict(zip(columns, cells, strict=True)), where)
        if rows and row.t < rows[-1][0]:
            raise ValueError(
                f"{where}: t: must not decrease (the row before is at {rows[-1][0]:g} s), "
                f"got {row.t:g}"
            )
        rows.append([getattr(row, c) for c in columns])
    if not rows:
        raise ValueError(f"{path}: no commands below the header")
    return np.array(rows, dtype=np.float64)


def check_command_array(commands) -> np.ndarray | None:
    """Commands given as an array (the API's ``simulate(commands=...)``), checked by the rules
    of a command script: (n, 4) rows t, vx, vy, w (as :func:`kiseki.sim.run.read_commands` gives
    them) of numbers within +-MAGNITUDE_LIMIT, 1 to MAX_COMMANDS rows, t in [0,
    MAX_COMMAND_SECONDS] and not decreasing; None stays None. A list was a TypeError, an (n, 3)
    array an IndexError, and rows out of time order were followed in the wrong order."""
    if commands is None:
        return None
    try:
        c = np.asarray(commands, dtype=float)
    except (TypeError, ValueError):
        c = np.empty((0, 0))
    if (
        c.ndim != 2
        or c.shape[1:] != (4,)
        or not 0 < len(c) <= MAX_COMMANDS
        or not np.all(np.abs(c) <= MAGNITUDE_LIMIT)
    ):
        raise ValueError(
            f"commands must be an (n, 4) array of 1 to {MAX_COMMANDS:,} rows t, vx, vy, w (see "
            f"read_commands), finite numbers within +-{MAGNITUDE_LIMIT:g}, got "
            f"{np.array2string(c, threshold=8)}"
        )
    t = c[:, 0]
    if not (t[0] >= 0 and t[-1] <= MAX_COMMAND_SECONDS and np.all(np.diff(t) >= 0)):
        raise ValueError(
            f"commands: the times (column 0) must lie in [0, {MAX_COMMAND_SECONDS:,.0f}] s and "
            f"not decrease, got {np.array2string(t, threshold=8)}"
        )
    return c
