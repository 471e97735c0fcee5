# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The model of the points file of ``kiseki magnetic predict --at POINTS.csv``: a CSV whose
header names the columns x, y (and z for a 3-D map; other columns are ignored, names in any
case), one point a row, in metres::

    x,y,z
    0.5,1.25,0.3
    2.0,1e-1,0.3

A problem is one line naming the file, the line number, the column and the value
(``points.csv:3: y: must be a finite number, got 'nan'``); a file holds at most
:data:`MAX_POINTS` points, with the limit in the message."""

from __future__ import annotations

import csv
import io
import os
from pathlib import Path

import numpy as np

from kiseki._support.csv import CsvNumber
from kiseki._support.inputs import CSV_LIMIT, read_input_text
from kiseki._support.schema import FileModel, parse

__all__ = ["MAX_POINTS", "Point2", "Point3", "read_points"]

MAX_POINTS = 1_000_000
"""Points a file may hold: each becomes an output row of 9 numbers (~100 MB of CSV for a
million) and, with a map that keeps its measurements, a GP evaluation against all of them."""


class Point2(FileModel):
    """A row of a 2-D map's points: x, y (m)."""

    x: CsvNumber
    y: CsvNumber


class Point3(FileModel):
    """A row of a 3-D map's points: x, y, z (m)."""

    x: CsvNumber
    y: CsvNumber
    z: CsvNumber


def read_points(path: str | os.PathLike, d: int) -> tuple[np.ndarray, bool]:
    """(points (m, d), whether a z column was dropped) from the points CSV at `path` for a
    `d`-D map (d = 2 or 3): ValueError naming the file (and the line, the column and the
    value) for a bad file."""
    path = Path(path)
    model, need = (Point2, ("x", "y")) if d == 2 else (Point3, ("x", "y", "z"))
    points: list[list[float]] = []
    try:
        text = read_input_text(path, "points CSV files", CSV_LIMIT)
        with io.StringIO(text, newline="") as f:
            reader = csv.reader(f)
            names = None
            for row in reader:
                if not any(cell.strip() for cell in row):
                    continue
                if names is None:
                    names = [n.strip().lower() for n in row]
                    missing = [n for n in need if n not in names]
                    if missing:
                        raise ValueError(
                            f"{path}: the header has no {', '.join(missing)} column (got {row})"
                        )
                    columns = [names.index(n) for n in need]
                    continue
                where = f"{path}:{reader.line_num}"
                if len(row) <= max(columns):
                    raise ValueError(
                        f"{where}: a row needs the header's columns {', '.join(need)} "
                        f"(at least {max(columns) + 1} values), got {','.join(row)[:60]!r}"
                    )
                # a value no column names ('0,0,0' under 'x,y'); empty cells past the header's,
                # a spreadsheet's trailing commas, are none
                if any(cell.strip() for cell in row[len(names) :]):
                    raise ValueError(
                        f"{where}: {len(row)} values where the header names {len(names)} "
                        f"columns ({','.join(names)}), got {','.join(row)[:60]!r}"
                    )
                if len(points) == MAX_POINTS:
                    raise ValueError(f"{where}: a points file holds at most {MAX_POINTS:,} points")
                point = parse(model, {n: row[c] for n, c in zip(need, columns, strict=True)}, where)
                points.append([getattr(point, n) for n in need])
    except UnicodeDecodeError:
        raise ValueError(f"{path}: not a CSV file (not UTF-8 text)") from None
    except csv.Error as err:
        raise ValueError(f"{path}: not a CSV file ({err})") from None
    if names is None:
        raise ValueError(f"{path}: empty file: expected a header x,y[,z] and rows")
    if not points:
        raise ValueError(f"{path}: header but no points")
    return np.array(points, dtype=np.float64).reshape(-1, d), d == 2 and "z" in names
