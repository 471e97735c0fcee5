# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The check of a count (particles, beams, threads, moves, a window's length): an integer
in a range, a Python or a numpy integer alike, never a bool (True is not one particle) and
never a float (1000.7 is not a particle count). A count with no upper bound of its own stops
at what the C++ type it reaches can hold (``kiseki._support.schema.INT32_MAX`` for a C++
``int``: pybind11 refuses a larger one with a TypeError listing the call's overloads) or at a
stated compute limit; a count only Python uses may leave ``high`` out.

The wording is the command line's (:class:`kiseki._support.options.Count` words its rule with
:func:`integer_rule`), so the same mistake reads the same in the API and the CLI:
``particles must be an integer in 1..10,000,000, got 0``."""

from __future__ import annotations

import numbers
from typing import Any

import numpy as np

__all__ = ["check_count", "integer_rule"]


def integer_rule(low: int, high: int | None = None, note: str = "") -> str:
    """``an integer in LOW..HIGH (NOTE)``, or ``an integer >= LOW (NOTE)`` without ``high``;
    thousands separated by commas."""
    span = f"in {low:,}..{high:,}" if high is not None else f">= {low:,}"
    return f"an integer {span}" + (f" ({note})" if note else "")


def check_count(
    value: Any,
    name: str,
    low: int,
    high: int | None = None,
    note: str = "",
    error: type[Exception] = ValueError,
) -> int:
    """``value`` as an int when it is an integer (``numbers.Integral``: numpy's too) in
    ``low..high`` (both included; no upper bound when ``high`` is None); otherwise ``error``
    (a ValueError unless the caller's own kind) ``"NAME must be RULE, got VALUE"``."""
    if (
        isinstance(value, bool | np.bool_)
        or not isinstance(value, numbers.Integral)
        or value < low
        or (high is not None and value > high)
    ):
        raise error(f"{name} must be {integer_rule(low, high, note)}, got {value!r}")
    return int(value)
