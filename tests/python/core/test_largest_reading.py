# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The maximum range of a log that does not state one. One corrupt reading of 500 m in an 80 m
laser's log became the maximum range, and every real no return (81.83 m) was then read as a
wall 81.83 m away; now a few stray readings above a value the logger wrote many times are no
returns themselves, and every other log keeps its largest reading."""

from __future__ import annotations

import numpy as np
import pytest

from kiseki.scans import NO_RETURN_READINGS, NO_RETURN_SCANS, STRAY_SHARE, largest_reading


def brute_force(ranges: np.ndarray) -> float | None:
    """The definition, value by value with Python dicts and sets."""
    rows = np.atleast_2d(np.asarray(ranges, dtype=np.float32))
    counts: dict[float, int] = {}
    scans: dict[float, set[int]] = {}
    for i, row in enumerate(rows):
        for v in row:
            if np.isfinite(v) and v > 0:
                counts[float(v)] = counts.get(float(v), 0) + 1
                scans.setdefault(float(v), set()).add(i)
    if not counts:
        return None
    for value in sorted(counts, reverse=True):
        above = sum(n for v, n in counts.items() if v > value)
        if above > STRAY_SHARE * counts[value]:
            break
        if counts[value] >= NO_RETURN_READINGS and len(scans[value]) >= NO_RETURN_SCANS:
            return value
    return max(counts)


def log_with_no_returns(seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    ranges = np.round(rng.uniform(0.5, 30.0, (50, 180)), 2)
    ranges[rng.uniform(size=ranges.shape) < 0.1] = 81.83  # the logger's no returns, ~900
    return ranges


def test_one_corrupt_reading_does_not_become_the_maximum_range():
    ranges = log_with_no_returns(7)
    assert largest_reading(ranges) == pytest.approx(81.83, abs=1e-5)  # as before
    ranges[17, 40] = 500.0
    assert largest_reading(ranges) == pytest.approx(81.83, abs=1e-5)  # was 500
    ranges[18:38, 41] = 500.0  # 21 readings: more than 1 % of the ~900 no returns
    assert largest_reading(ranges) == 500.0


@pytest.mark.parametrize("seed", range(5))
def test_largest_reading_is_its_definition(seed):
    rng = np.random.default_rng(seed)
    ranges = log_with_no_returns(seed).astype(np.float32)
    ranges[rng.uniform(size=ranges.shape) < 0.02] = np.nan
    ranges[rng.uniform(size=ranges.shape) < 0.02] = np.inf  # no returns as +inf: not counted
    strays = int(rng.integers(0, 20))
    ranges.ravel()[rng.choice(ranges.size, strays, replace=False)] = rng.uniform(82, 900, strays)
    assert largest_reading(ranges) == brute_force(ranges)


def test_logs_without_a_frequent_value_keep_their_largest_reading():
    assert largest_reading(np.array([[1.0, 5.0, 3.0]])) == 5.0
    assert largest_reading(np.array([1.0, 5.0, 3.0])) == 5.0
    short = np.full((3, 30), 81.83)  # 90 no returns: fewer than NO_RETURN_READINGS
    short[0, 0] = 500.0
    assert largest_reading(short) == 500.0
    wall = np.full((2, 180), 1.5)  # a flat wall 2 m off in 179 beams of one scan
    wall[0, :179], wall[0, 179] = 2.0, 81.83
    assert largest_reading(wall) == pytest.approx(81.83, abs=1e-5)
    assert largest_reading(np.array([[np.nan, -1.0], [0.0, np.inf]])) is None
