# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The points file of ``kiseki magnetic predict --at`` (kiseki.magnetic.points_csv): a valid
file reads to its numbers as before; a bad row is refused in one line naming the file, the
line, the column and the value; the row limit is in the message."""

from __future__ import annotations

import numpy as np
import pytest

from kiseki.magnetic import points_csv
from kiseki.magnetic.points_csv import MAX_POINTS, read_points


def test_a_valid_file_reads_to_its_numbers(tmp_path):
    path = tmp_path / "p.csv"
    path.write_text("t, X ,y,z\n9,0.5,1.25,3\n\n8,2,1e-1,-0.5\n")
    points, dropped = read_points(path, 2)
    assert np.array_equal(points, [[0.5, 1.25], [2.0, 0.1]]) and dropped
    points, dropped = read_points(path, 3)
    assert np.array_equal(points, [[0.5, 1.25, 3.0], [2.0, 0.1, -0.5]]) and not dropped
    assert points.dtype == np.float64


@pytest.mark.parametrize(
    ("text", "problem"),
    [
        ("x,y\n0,1\n\n2,nan\n", "p.csv:4: y: must be a finite number, got 'nan'"),
        ("x,y\n0,1\n-inf,2\n", "p.csv:3: x: must be a finite number, got '-inf'"),
        ("x,y\n0,abc\n", "p.csv:2: y: must be a number, got 'abc'"),
        ("x,y\n0,\n", "p.csv:2: y: must be a number, got ''"),
        ("x,y\n0\n", "p.csv:2: a row needs the header's columns x, y (at least 2 values), got '0'"),
        ("a,y\n0,1\n", "p.csv: the header has no x column (got ['a', 'y'])"),
        # the third value was dropped without a word (a z under a header of x, y)
        (
            "x,y\n0,1\n0,0,0\n",
            "p.csv:3: 3 values where the header names 2 columns (x,y), got '0,0,0'",
        ),
        ("x,y\n", "p.csv: header but no points"),
        ("\n\n", "p.csv: empty file: expected a header x,y[,z] and rows"),
    ],
)
def test_a_bad_file_is_refused_in_one_line(tmp_path, text, problem):
    path = tmp_path / "p.csv"
    path.write_text(text)
    with pytest.raises(ValueError) as err:
        read_points(path, 2)
    assert str(err.value) == f"{tmp_path}/{problem}"


def test_trailing_empty_cells_are_no_values(tmp_path):
    """A spreadsheet's trailing commas ('0,1,' under 'x,y') are empty cells, not values."""
    path = tmp_path / "p.csv"
    path.write_text("x,y\n0,1,\n2,3,,\n")
    np.testing.assert_array_equal(read_points(path, 2)[0], [[0.0, 1.0], [2.0, 3.0]])


def test_the_row_limit_is_in_the_message(tmp_path, monkeypatch):
    assert MAX_POINTS == 1_000_000
    monkeypatch.setattr(points_csv, "MAX_POINTS", 3)
    path = tmp_path / "p.csv"
    path.write_text("x,y\n" + "0,1\n" * 3)
    assert read_points(path, 2)[0].shape == (3, 2)
    path.write_text("x,y\n" + "0,1\n" * 4)
    with pytest.raises(ValueError) as err:
        read_points(path, 2)
    assert str(err.value) == f"{path}:5: a points file holds at most 3 points"
