# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Tests of the numbers the file readers take from text: as float() and int() read them, but a
token with a PEP 515 underscore (``1_0``, which they read as 10) is not a number."""

from __future__ import annotations

import numpy as np
import pytest

from kiseki._support.numbers_text import (
    NumberTextError,
    float_array,
    is_number,
    parse_float,
    parse_int,
)


def test_numbers_read_as_float_and_int_read_them() -> None:
    assert parse_float("-1.5e3") == -1500.0 and parse_int("42") == 42 and parse_int("-7") == -7
    assert np.isnan(parse_float("nan")) and parse_float("inf") == np.inf
    assert is_number("0.25") and not is_number("abc")


# full-width and Arabic-Indic digits: float() read both as 10
@pytest.mark.parametrize(
    "token", ["1_0", "1_000.5", "0.5_0", "1e1_0", "_1", "1_", "\uff11\uff10", "\u0661\u0660"]
)
def test_a_token_with_an_underscore_or_other_scripts_digits_is_not_a_number(token: str) -> None:
    assert not is_number(token)
    with pytest.raises(ValueError, match=f"'{token}' is not a number"):
        parse_float(token)
    with pytest.raises(NumberTextError) as bad:
        float_array([["1", "2"], ["3", token]])
    assert (bad.value.row, bad.value.token) == (1, token)


@pytest.mark.parametrize("token", ["1_0", "4_0", "x", "1.0", "\u0661\u0660"])
def test_an_integer_is_decimal_digits(token: str) -> None:
    with pytest.raises(ValueError, match=f"'{token}'"):
        parse_int(token)


def test_float_array_of_a_table_and_of_a_flat_list() -> None:
    np.testing.assert_array_equal(float_array([["1", "2.5"], ["-3", "4e1"]]), [[1, 2.5], [-3, 40]])
    np.testing.assert_array_equal(float_array(["1", "2.5", "-3"]), [1, 2.5, -3])
    assert float_array([]).shape == (0,)
    with pytest.raises(NumberTextError) as bad:
        float_array(["1", "2", "3_0", "x"])
    assert (bad.value.row, bad.value.token) == (2, "3_0")  # the token's index in a flat list
    with pytest.raises(NumberTextError) as bad:
        float_array([["1", "2"], ["x", "4"]])
    assert (bad.value.row, bad.value.token) == (1, "x")


def test_ragged_rows_are_numpys_error() -> None:
    with pytest.raises(ValueError) as err:
        float_array([["1", "2"], ["3"]])
    assert not isinstance(err.value, NumberTextError)
