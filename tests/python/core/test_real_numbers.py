# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The one check of a real number: finite, in its interval, a Python or numpy integer or float,
never a bool, text, an array (0-d too), a Fraction or a Decimal; returned as a Python float.
Messages are stated word for word."""

from __future__ import annotations

import decimal
import fractions
import math

import numpy as np
import pytest

from kiseki._support.real_numbers import check_number, number_rule


@pytest.mark.parametrize(
    ("kwargs", "rule"),
    [
        ({}, "a finite number"),
        ({"unit": "rad"}, "a finite number (rad)"),
        ({"low": 0.0, "low_open": True}, "a finite number > 0"),
        ({"low": 0.0, "unit": "m"}, "a finite number >= 0 m"),
        ({"high": 1.0, "high_open": True}, "a finite number < 1"),
        ({"high": 1.0}, "a finite number <= 1"),
        ({"low": 0.0, "high": 1.0}, "a finite number in [0, 1]"),
        (
            {"low": 0.0, "high": 10.0, "low_open": True, "unit": "m/s"},
            "a finite number in (0, 10] m/s",
        ),
        ({"low": -1.0, "high": 86400.0, "high_open": True}, "a finite number in [-1, 86,400)"),
        ({"low": 1e-9, "high": 1e50}, "a finite number in [1e-09, 1e+50]"),
        ({"low": 0.0, "high": math.pi, "unit": "rad"}, "a finite number in [0, pi] rad"),
        ({"low": -math.pi, "high": math.pi, "high_open": True}, "a finite number in [-pi, pi)"),
        ({"low": 0.0, "high": 2 * math.pi}, "a finite number in [0, 2 pi]"),
        ({"high": math.pi / 2}, "a finite number <= pi/2"),
        ({"low": math.pi / 4, "low_open": True}, "a finite number > pi/4"),
        ({"low": 0.0, "high": 3.1416}, "a finite number in [0, 3.1416]"),
    ],
)
def test_rule_words_each_interval(kwargs, rule):
    assert number_rule(**kwargs) == rule


@pytest.mark.parametrize(
    "value",
    [2, 2.0, np.float32(2.0), np.float64(2.0), np.float16(2.0), np.int64(2), np.uint8(2)],
)  # fmt: skip
def test_numbers_of_every_kind_are_taken_as_python_floats(value):
    got = check_number(value, "x", 0.0, 5.0)
    assert got == 2.0
    assert type(got) is float


def test_negative_zero_becomes_zero():
    got = check_number(-0.0, "sd", 0.0)
    assert got == 0.0 and math.copysign(1.0, got) == 1.0
    assert math.copysign(1.0, check_number(np.float64(-0.0), "sd", 0.0)) == 1.0


@pytest.mark.parametrize(
    ("value", "shown"),
    [
        (math.nan, "nan"),
        (math.inf, "inf"),
        (-math.inf, "-inf"),
        (np.float64("nan"), repr(np.float64("nan"))),
        (True, "True"),
        (np.bool_(True), repr(np.bool_(True))),
        ("1.5", "'1.5'"),
        (None, "None"),
        (1 + 0j, "(1+0j)"),
        (np.array([1.0]), "array([1.])"),
        (np.array(1.0), "array(1.)"),  # a 0-d array: callers keeping the value would hold it
        (fractions.Fraction(1, 2), "Fraction(1, 2)"),
        (decimal.Decimal("0.5"), "Decimal('0.5')"),
        (10**400, str(10**400)),
    ],
)
def test_what_is_no_finite_number_is_refused_in_one_line(value, shown):
    with pytest.raises(ValueError) as e:
        check_number(value, "sigma", 0.0, low_open=True, unit="m")
    assert str(e.value) == f"sigma must be a finite number > 0 m, got {shown}"


@pytest.mark.parametrize(
    ("value", "kwargs", "ok"),
    [
        (0.0, {"low": 0.0}, True),
        (0.0, {"low": 0.0, "low_open": True}, False),
        (1.0, {"high": 1.0}, True),
        (1.0, {"high": 1.0, "high_open": True}, False),
        (-1e-300, {"low": 0.0}, False),
        (1.0 + 2**-52, {"low": 0.0, "high": 1.0}, False),
        (5e-324, {"low": 0.0, "low_open": True}, True),
        (1e308, {}, True),
    ],
)
def test_the_ends_are_included_or_not_as_asked(value, kwargs, ok):
    if ok:
        assert check_number(value, "v", **kwargs) == value
    else:
        with pytest.raises(ValueError, match="^v must be a finite number"):
            check_number(value, "v", **kwargs)


def test_the_callers_error_kind_is_raised():
    class ConfigError(ValueError):
        pass

    with pytest.raises(ConfigError, match=r"^dt must be a finite number > 0 s, got -1$"):
        check_number(-1, "dt", 0.0, low_open=True, unit="s", error=ConfigError)


@pytest.mark.parametrize(
    ("value", "kwargs"),
    [
        (np.float32(0.6), {"low": 0.02, "high": 0.6}),  # 0.6000000238 as a double
        (np.float32(math.pi), {"low": 0.0, "high": math.pi}),  # 3.1415927 as a double
        (np.float32(0.02), {"low": 0.02, "high": 0.6}),  # 0.0199999996 as a double
    ],
)
def test_a_numpy_float_at_a_bound_is_in_as_numpy_compares_it(value, kwargs):
    """A float32 written at a bound is past it as a double; it meets the bound in its own
    precision (numpy's comparison, which the checks before this one used) and is taken, as
    the double it is."""
    assert not kwargs["low"] <= float(value) <= kwargs["high"]
    assert check_number(value, "step", **kwargs) == float(value)


def test_a_numpy_float_past_a_bound_in_its_own_precision_is_refused():
    with pytest.raises(
        ValueError, match=r"^step must be a finite number in \[0\.02, 0\.6\] m, got"
    ):
        check_number(np.float32(0.6001), "step", 0.02, 0.6, unit="m")
