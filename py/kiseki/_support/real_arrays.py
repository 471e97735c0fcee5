# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Arrays of real numbers as the library takes them: integers or floats (Python's None, in a
list, is a NaN: no value). Complex numbers lost their imaginary part in a float cast (numpy
only warns), booleans read as 0 and 1, and strings were parsed ("1_0" as 10): each is refused
in one line naming the argument, as is a ragged list."""

from __future__ import annotations

import numbers
from typing import Any

import numpy as np

__all__ = ["real_array"]


def real_array(values: Any, name: str) -> np.ndarray:
    """``values`` as a numpy array of integers or floats (not copied when it is one), or a
    ValueError ``"NAME: expected real numbers, got ..."``."""
    try:
        array = np.asarray(values)
    except (TypeError, ValueError):  # ragged: "setting an array element with a sequence"
        raise ValueError(f"{name}: expected real numbers in an array of one shape") from None
    if array.dtype.kind == "O" and all(
        v is None or (isinstance(v, numbers.Real) and not isinstance(v, bool | np.bool_))
        for v in array.flat
    ):
        array = array.astype(np.float64)  # None -> NaN
    if array.dtype.kind not in "iuf":
        raise ValueError(f"{name}: expected real numbers, got dtype {array.dtype}")
    return array
