# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The maximum range of a log that does not state one: the largest reading that two scans
report. One corrupt reading of 500 m in an 80 m laser's log became the maximum range, and every
real no return (81.83 m) was then read as a wall 81.83 m away."""

from __future__ import annotations

import numpy as np
import pytest

from kiseki.scans import largest_reading


def brute_force(ranges: np.ndarray) -> float | None:
    """The definition, scan by scan with Python sets (for a log without +inf readings)."""
    rows = np.atleast_2d(np.asarray(ranges, dtype=np.float32))
    held: dict[float, int] = {}
    for row in rows:
        for v in {float(v) for v in row if np.isfinite(v) and v > 0}:
            held[v] = held.get(v, 0) + 1
    if not held:
        return None
    shared = [v for v, n in held.items() if n >= 2]
    return max(shared) if shared else max(held)


def test_one_corrupt_reading_does_not_become_the_maximum_range():
    rng = np.random.default_rng(7)
    ranges = np.round(rng.uniform(0.5, 30.0, (50, 180)), 2)
    ranges[rng.uniform(size=ranges.shape) < 0.1] = 81.83  # the logger's no returns
    ranges[17, 40] = 500.0
    assert largest_reading(ranges) == pytest.approx(81.83, abs=1e-5)
    ranges[23, 90] = 500.0  # a second scan reports it: the logger's value after all
    assert largest_reading(ranges) == 500.0


@pytest.mark.parametrize("seed", range(5))
def test_largest_reading_is_its_definition(seed):
    rng = np.random.default_rng(seed)
    ranges = np.round(rng.uniform(-1.0, 20.0, (30, 12)), 1).astype(np.float32)
    ranges[rng.uniform(size=ranges.shape) < 0.05] = np.nan
    ranges[3, :4] = 99.5  # repeated within one scan only: not two scans
    assert largest_reading(ranges) == brute_force(ranges)
    assert largest_reading(ranges) < 99.5


def test_one_scan_or_no_repeat_takes_the_largest_and_nothing_valid_is_none():
    assert largest_reading(np.array([[1.0, 5.0, 3.0]])) == 5.0
    assert largest_reading(np.array([1.0, 5.0, 3.0])) == 5.0
    assert largest_reading(np.array([[1.0, 2.0], [3.0, 4.0]])) == 4.0
    assert largest_reading(np.array([[np.nan, -1.0], [0.0, np.inf]])) is None
    # no returns written as +inf: the finite readings are all returns, the largest kept
    assert largest_reading(np.array([[1.0, 9.0], [1.0, np.inf]])) == 9.0
