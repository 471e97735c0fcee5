# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The number type of the CSV files kiseki reads (command scripts, trajectories): a cell's text
(``0.5``, `` 1e-1 ``) read as a finite number inside a pydantic model, so that a problem names
the column and the cell as it was written (``v: must be a finite number, got 'nan'``)."""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from typing import Annotated, Any

from pydantic import BeforeValidator, Field

from kiseki._support.numbers_text import parse_float
from kiseki._support.schema import MAGNITUDE_LIMIT

__all__ = ["CsvNumber", "data_rows", "number_text"]


def number_text(text: Any) -> Any:
    """A CSV cell's text as a number: ``nan`` and ``inf`` are numbers that are not finite,
    anything else that is not a number is refused as it was written."""
    if isinstance(text, str):
        try:
            value = parse_float(text)  # 1_0 is not 10
        except ValueError:
            raise ValueError("must be a number") from None
        if not math.isfinite(value):
            raise ValueError("must be a finite number")
        return value
    return text


CsvNumber = Annotated[
    float,
    BeforeValidator(number_text),
    Field(strict=True, ge=-MAGNITUDE_LIMIT, le=MAGNITUDE_LIMIT, allow_inf_nan=False),
]
"""A finite number from a CSV cell, within +-kiseki._support.schema.MAGNITUDE_LIMIT; tighter bounds
go in a further ``Field`` (``Annotated[CsvNumber, Field(ge=0)]``)."""


def data_rows(lines: Sequence[str]) -> Iterator[tuple[int, list[str], str]]:
    """The data rows under a CSV's header line: (line number from 1, its cells, the line),
    with ``#`` comments cut off and blank rows skipped."""
    for number, line in enumerate(lines[1:], 2):
        cells = line.split("#", 1)[0].split(",")
        if "".join(cells).strip():
            yield number, cells, line
