# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The check of one real number (a length, a speed, a noise SD, a gain, a time step): finite,
in its interval, a Python or a numpy number alike (a 0-d array too), never a bool (True is
not 1 m) and never text ("1.5" is parsed where a file is read, not here). It returns the value
as a Python float (held by configs, written to JSON and YAML as numbers), -0.0 as 0.0 (numpy's
samplers refuse a scale whose sign bit is set).

The wording is one rule for the whole library, as :func:`kiseki._support.counts.integer_rule`
is for counts: ``sigma must be a finite number > 0 m, got nan``;
``alpha must be a finite number in [0, 1], got 1.5``."""

from __future__ import annotations

import math
import numbers
from typing import Any

import numpy as np

__all__ = ["check_number", "number_rule"]


def number_rule(
    low: float = -math.inf,
    high: float = math.inf,
    *,
    low_open: bool = False,
    high_open: bool = False,
    unit: str = "",
) -> str:
    """``a finite number in [LOW, HIGH] UNIT`` (parentheses for an open end), or ``> LOW``,
    ``>= LOW``, ``< HIGH``, ``<= HIGH`` where only one end is finite; with neither,
    ``a finite number (UNIT)``."""
    if math.isinf(low) and math.isinf(high):
        span = ""
    elif math.isinf(high):
        span = f" {'>' if low_open else '>='} {low:,g}"
    elif math.isinf(low):
        span = f" {'<' if high_open else '<='} {high:,g}"
    else:
        left, right = "(" if low_open else "[", ")" if high_open else "]"
        span = f" in {left}{low:,g}, {high:,g}{right}"
    if not span:  # no bound: "a finite number (m)" reads as the unit, "a finite number m" not
        return "a finite number" + (f" ({unit})" if unit else "")
    return "a finite number" + span + (f" {unit}" if unit else "")


def _real(value: Any) -> float | None:
    """The value as a float, or None when it is no real number."""
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value[()]
    if isinstance(value, bool | np.bool_) or not isinstance(value, numbers.Real):
        return None
    try:
        return float(value)
    except OverflowError:  # an integer past the double's range
        return None


def check_number(
    value: Any,
    name: str,
    low: float = -math.inf,
    high: float = math.inf,
    *,
    low_open: bool = False,
    high_open: bool = False,
    unit: str = "",
    error: type[Exception] = ValueError,
) -> float:
    """``value`` as a float when it is a finite real number in the interval from ``low`` to
    ``high`` (each end included unless ``low_open`` / ``high_open``); otherwise ``error`` (a
    ValueError unless the caller's own kind) ``"NAME must be RULE, got VALUE"``."""
    number = _real(value)
    ok = number is not None and math.isfinite(number)
    if ok:
        ok = (number > low if low_open else number >= low) and (
            number < high if high_open else number <= high
        )
    if not ok:
        rule = number_rule(low, high, low_open=low_open, high_open=high_open, unit=unit)
        raise error(f"{name} must be {rule}, got {value!r}")
    return number + 0.0
