# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The check of one real number (a length, a speed, a noise SD, a gain, a time step): finite,
in its interval, a Python or a numpy integer or float alike; never a bool (True is not 1 m),
never text ("1.5" is parsed where a file is read, not here), and neither an array (a 0-d one
included: ``float(x)`` or ``x[()]`` gives its number) nor a Fraction or Decimal, which callers
that keep the value as given would hold and compute with. It returns the value as a Python
float (held by configs, written to JSON and YAML as numbers), -0.0 as 0.0 (numpy's samplers
refuse a scale whose sign bit is set). A numpy float is in its interval when it is so as a
double or in its own precision (numpy's comparison): ``np.float32(0.6)`` is 0.6000000238 as a
double and meets a bound of 0.6 as numpy compares it, as the checks before this one took it.

The wording is one rule for the whole library, as :func:`kiseki._support.counts.integer_rule`
is for counts: ``sigma must be a finite number > 0 m, got nan``;
``alpha must be a finite number in [0, 1], got 1.5``."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["check_number", "hold_number", "number_rule"]


# bounds written as the angle they are
_NAMED_BOUNDS = {math.pi: "pi", -math.pi: "-pi", 2 * math.pi: "2 pi", math.pi / 2: "pi/2",
                 math.pi / 4: "pi/4"}  # fmt: skip


def _bound(x: float) -> str:
    return _NAMED_BOUNDS.get(x, f"{x:,g}")


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
    ``a finite number (UNIT)``. pi, 2 pi, pi/2 and pi/4 are written so."""
    if math.isinf(low) and math.isinf(high):
        span = ""
    elif math.isinf(high):
        span = f" {'>' if low_open else '>='} {_bound(low)}"
    elif math.isinf(low):
        span = f" {'<' if high_open else '<='} {_bound(high)}"
    else:
        left, right = "(" if low_open else "[", ")" if high_open else "]"
        span = f" in {left}{_bound(low)}, {_bound(high)}{right}"
    if not span:  # no bound: "a finite number (m)" reads as the unit, "a finite number m" not
        return "a finite number" + (f" ({unit})" if unit else "")
    return "a finite number" + span + (f" {unit}" if unit else "")


def _real(value: Any) -> float | None:
    """The value as a float, or None when it is no Python or numpy integer or float."""
    if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating):
        return None
    try:
        return float(value)
    except OverflowError:  # an integer past the double's range
        return None


def _within(x: Any, low: float, high: float, low_open: bool, high_open: bool) -> bool:
    return bool((x > low if low_open else x >= low) and (x < high if high_open else x <= high))


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
        ends = (low, high, low_open, high_open)
        ok = _within(number, *ends) or (isinstance(value, np.floating) and _within(value, *ends))
    if not ok:
        rule = number_rule(low, high, low_open=low_open, high_open=high_open, unit=unit)
        raise error(f"{name} must be {rule}, got {value!r}")
    return number + 0.0


def hold_number(obj: Any, field: str, name: str, *bounds: float, **rule: Any) -> None:
    """Checks ``obj.field`` by :func:`check_number` (``name`` in its message, ``bounds`` and
    ``rule`` its own) and holds the float it returns there, also in a frozen dataclass: -0.0 as
    0.0 (numpy's normal refuses a scale of -0.0), a numpy number as a Python float."""
    object.__setattr__(obj, field, check_number(getattr(obj, field), name, *bounds, **rule))
