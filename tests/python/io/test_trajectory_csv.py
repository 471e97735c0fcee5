# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The trajectory CSV's model (kiseki.io.trajectory_csv, ``kiseki map render --trajectory``): a
file reads to the x, y columns numpy's own CSV reader gives, and every problem is one line
naming the file, the line, the column and the value; limits with the limit."""

from __future__ import annotations

import numpy as np
import pytest

import kiseki.io.trajectory_csv as schema
from kiseki.io.trajectory_csv import MAX_COLUMNS, read_trajectory_csv


@pytest.mark.parametrize(
    "text",
    ["t,x,y,theta\n0,1.5,3.0,0\n\n1,3.0, 3.2 ,0.5  # turning\n", "y,x\n1e-1,2\n-3,4.5\n"],
)
def test_a_trajectory_reads_to_what_numpy_reads(tmp_path, text):
    path = tmp_path / "path.csv"
    path.write_text(text)
    header = text.splitlines()[0].split(",")
    reference = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)  # the reader before
    expected = reference[:, [header.index("x"), header.index("y")]]
    np.testing.assert_array_equal(read_trajectory_csv(path), expected)


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("x,y\nnan,1\n", ":2: x: must be a finite number, got 'nan'"),
        ("t,x,y\n0,0,0\n1,2,far\n", ":3: y: must be a number, got 'far'"),
        ("t,x,y\n0,0,0\n1,1_0,2\n", ":3: x: must be a number, got '1_0'"),  # was read as 10
        ("t,x,y\n0,0\n", ":2: a row has 3 values (t,x,y), got '0,0'"),
        ("t,x\n0,0\n", ": a trajectory CSV needs a header with columns x and y"),
        ("x,y,x\n0,0,0\n", ": the header's column names must be unique and not empty"),
        ("x,y\n", ": no poses below the header"),
        ("x,y," + ",".join(f"c{i}" for i in range(MAX_COLUMNS - 1)) + "\n",
         f": a trajectory CSV has at most {MAX_COLUMNS} columns"),
    ],
)  # fmt: skip
def test_a_wrong_value_is_named_by_line_and_column(tmp_path, text, expected):
    path = tmp_path / "path.csv"
    path.write_text(text)
    with pytest.raises(ValueError) as err:
        read_trajectory_csv(path)
    assert str(err.value) == f"{path}{expected}"


def test_the_row_limit_is_enforced_with_the_limit_in_the_message(tmp_path, monkeypatch):
    assert schema.MAX_ROWS == 1_000_000
    monkeypatch.setattr(schema, "MAX_ROWS", 2)  # the same check, on a small file
    path = tmp_path / "path.csv"
    path.write_text("x,y\n0,0\n1,1\n")
    assert read_trajectory_csv(path).shape == (2, 2)
    path.write_text("x,y\n0,0\n1,1\n2,2\n")
    with pytest.raises(ValueError) as err:
        read_trajectory_csv(path)
    assert str(err.value) == f"{path}:4: a trajectory CSV holds at most 2 rows"
