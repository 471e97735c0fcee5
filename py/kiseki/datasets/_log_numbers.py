# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The numbers of a text log's records (CARMEN, the Wean Hall logs): token rows to float64, each
error naming the file and the line."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from kiseki._support.numbers_text import NumberTextError, float_array
from kiseki.errors import LogFormatError

__all__ = ["VALUE_LIMIT", "log_numbers"]

# Every number but the range readings within +-1e12: poses in metres and radians, times in
# seconds since 1970 (about 1.7e9 now); 1e300 passed and made the pose error infinite
VALUE_LIMIT = 1e12


def log_numbers(
    path: Path,
    linenos: Sequence[int],
    rows: list[list[str]],
    kind: str = "",
    ranges: slice = slice(0),
) -> np.ndarray:
    """The rows of tokens (equal lengths; row i from line ``linenos[i]``) as a float64 array.
    Columns ``ranges`` (range readings) may be NaN, infinite or beyond :data:`VALUE_LIMIT` (a
    reading past the maximum range has no return); any other column must be finite and within
    +-:data:`VALUE_LIMIT`. A LogFormatError names the file, the line and, when given, the
    record ``kind``."""
    where = f" in {kind}" if kind else ""
    try:
        values = float_array(rows)
    except NumberTextError as bad:
        msg = f"{path}:{linenos[bad.row]}: non-numeric value {bad.token[:20]!r}{where}"
        raise LogFormatError(msg) from None
    except ValueError:
        raise LogFormatError(f"{path}: unreadable numbers{where}") from None
    finite = np.isfinite(values)
    finite[:, ranges] = True
    bad = ~finite.all(axis=1)
    if bad.any():
        lineno = linenos[int(np.argmax(bad))]
        raise LogFormatError(f"{path}:{lineno}: non-finite value (NaN or inf){where}")
    huge = np.abs(values) > VALUE_LIMIT
    huge[:, ranges] = False
    if huge.any():
        row = int(np.argmax(huge.any(axis=1)))
        value = values[row][huge[row]][0]
        raise LogFormatError(
            f"{path}:{linenos[row]}: value {value:g}{where} beyond +-{VALUE_LIMIT:g}"
        )
    return values
