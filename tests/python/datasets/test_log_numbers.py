# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The text logs' numbers (kiseki.datasets._log_numbers.log_numbers), the one conversion of the
CARMEN and Wean readers: each error names the file, the line and, when given, the record."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from kiseki.datasets._log_numbers import VALUE_LIMIT, log_numbers
from kiseki.errors import LogFormatError

LOG = Path("run.log")


def test_numbers_are_read_and_range_columns_may_be_anything():
    rows = [["1.5", "-2", "inf", "nan"], ["3e2", "0", "1e300", "-inf"]]
    values = log_numbers(LOG, [7, 9], rows, "FLASER", ranges=slice(2, 4))
    np.testing.assert_array_equal(
        values, [[1.5, -2, math.inf, math.nan], [300, 0, 1e300, -math.inf]]
    )


@pytest.mark.parametrize(
    ("rows", "kind", "message"),
    [
        (
            [["1", "2"], ["1", "x" * 30]],
            "ODOM",
            f"run.log:5: non-numeric value '{'x' * 20}' in ODOM",
        ),
        ([["1", "2"], ["nan", "2"]], "", "run.log:5: non-finite value (NaN or inf)"),
        (
            [["1", "2"], ["1", "-inf"]],
            "FLASER",
            "run.log:5: non-finite value (NaN or inf) in FLASER",
        ),
        (
            [["0", "0"], ["2e12", "0"]],
            "ODOM",
            f"run.log:5: value 2e+12 in ODOM beyond +-{VALUE_LIMIT:g}",
        ),
        ([["0", "0"], ["2e12", "0"]], "", f"run.log:5: value 2e+12 beyond +-{VALUE_LIMIT:g}"),
        ([["0", "0"], ["1_0", "0"]], "ODOM", "run.log:5: non-numeric value '1_0' in ODOM"),
        ([["0", "0"], ["1"]], "ODOM", "run.log: unreadable numbers in ODOM"),  # rows of two lengths
    ],
)
def test_each_error_names_the_file_the_line_and_the_record(rows, kind, message):
    with pytest.raises(LogFormatError) as err:
        log_numbers(LOG, [4, 5], rows, kind)
    assert str(err.value) == message
