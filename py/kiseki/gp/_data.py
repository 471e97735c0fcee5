# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Checks of training and prediction arrays, shared by the GP classes."""

from __future__ import annotations

from typing import Any

import numpy as np

from kiseki._support.counts import check_count
from kiseki._support.real_arrays import real_array

MEANS = ("constant", "zero")


def inputs_array(x: Any, name: str = "X") -> np.ndarray:
    """(n, d) float64, C-contiguous; a 1-D array is n points of one coordinate."""
    a = np.asarray(real_array(x, name), dtype=np.float64)  # complex lost its imaginary part
    if a.ndim == 1:
        a = a[:, None]
    if a.ndim != 2 or a.shape[1] < 1:
        raise ValueError(f"{name}: expected an array of shape (n, d), got shape {a.shape}")
    return np.ascontiguousarray(a)


def targets_array(y: Any, n: int, name: str = "Y") -> tuple[np.ndarray, bool]:
    """(n, k) float64 and whether the caller gave a 1-D array (one field component)."""
    a = np.asarray(real_array(y, name), dtype=np.float64)
    flat = a.ndim == 1
    if flat:
        a = a[:, None]
    if a.ndim != 2 or a.shape[1] < 1:
        raise ValueError(f"{name}: expected an array of shape (n,) or (n, k), got shape {a.shape}")
    if a.shape[0] != n:
        raise ValueError(f"X has {n} points but {name} has {a.shape[0]} rows")
    return np.ascontiguousarray(a), flat


def check_mean(mean: str) -> bool:
    """True for a constant mean function, False for none."""
    if mean not in MEANS:
        raise ValueError(f"mean must be one of {MEANS}, got {mean!r}")
    return mean == "constant"


def remove_mean(y: np.ndarray, constant: bool) -> np.ndarray:
    return y - y.mean(axis=0) if constant else y


def check_iterations(max_iterations: Any) -> int:
    """A hyperparameter search's iteration limit: an integer >= 1."""
    return check_count(max_iterations, "max_iterations", 1)
