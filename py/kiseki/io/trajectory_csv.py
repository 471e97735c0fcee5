# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The model of a trajectory CSV (``kiseki map render --trajectory FILE``): a header naming its
columns, among them ``x`` and ``y`` (m, map frame), then one row of numbers a pose::

    t,x,y,theta
    0,1.5,3.0,0      # '#' starts a comment; blank lines are skipped
    1,3.0,3.2,0.5

Every cell must be a finite number. A problem is one line naming the file, the line number,
the column and the value (``path.csv:3: y: must be a finite number, got 'nan'``); a trajectory
holds at most :data:`MAX_ROWS` rows of at most :data:`MAX_COLUMNS` columns, with the limit in
the message."""

from __future__ import annotations

import os
from functools import lru_cache
from pathlib import Path

import numpy as np
from pydantic import Field, create_model

from kiseki._support.csv import CsvNumber, data_rows
from kiseki._support.inputs import CSV_LIMIT, check_input, read_input_text
from kiseki._support.schema import FileModel, parse

__all__ = ["MAX_COLUMNS", "MAX_ROWS", "read_trajectory_csv"]

MAX_ROWS = 1_000_000  # 16 MB of (x, y); a day of poses at 10 Hz is 864,000
MAX_COLUMNS = 64


@lru_cache(maxsize=8)
def _row_model(columns: tuple[str, ...]) -> type[FileModel]:
    """The model of a row under `columns` (the header's names, as the error paths show them)."""
    fields = {f"c{i}": (CsvNumber, Field(alias=name)) for i, name in enumerate(columns)}
    return create_model("TrajectoryRow", __base__=FileModel, **fields)


def read_trajectory_csv(path: str | os.PathLike) -> np.ndarray:
    """The (n, 2) x, y columns of the trajectory CSV at `path`: FileNotFoundError when there is
    none, ValueError naming the file (and the line, the column and the value) otherwise."""
    path = Path(path)
    check_input(path)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: trajectory file not found")
    try:
        lines = read_input_text(path, "trajectory CSV files", CSV_LIMIT).splitlines()
    except UnicodeDecodeError:
        raise ValueError(f"{path}: not a trajectory CSV (not UTF-8 text)") from None
    columns = tuple(c.strip() for c in lines[0].split(",")) if lines else ()
    if "x" not in columns or "y" not in columns:
        raise ValueError(f"{path}: a trajectory CSV needs a header with columns x and y")
    if len(columns) > MAX_COLUMNS:
        raise ValueError(f"{path}: a trajectory CSV has at most {MAX_COLUMNS} columns")
    if len(set(columns)) != len(columns) or not all(columns):
        raise ValueError(f"{path}: the header's column names must be unique and not empty")
    model, x, y = _row_model(columns), columns.index("x"), columns.index("y")
    rows: list[tuple[float, float]] = []
    for number, cells, line in data_rows(lines):
        where = f"{path}:{number}"
        if len(cells) != len(columns):
            raise ValueError(
                f"{where}: a row has {len(columns)} values ({','.join(columns)}), got {line[:80]!r}"
            )
        if len(rows) == MAX_ROWS:
            raise ValueError(f"{where}: a trajectory CSV holds at most {MAX_ROWS:,} rows")
        row = parse(model, dict(zip(columns, cells, strict=True)), where)
        rows.append((getattr(row, f"c{x}"), getattr(row, f"c{y}")))
    if not rows:
        raise ValueError(f"{path}: no poses below the header")
    return np.array(rows, dtype=np.float64)
