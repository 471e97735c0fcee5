# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Averaging readings per cell (kiseki.magnetic.binning) against a brute-force loop."""

from __future__ import annotations

import numpy as np
import pytest

from kiseki.magnetic.binning import bin_readings


def test_means_and_counts_equal_a_loop_over_cells():
    rng = np.random.default_rng(0)
    x = rng.uniform(-1.0, 2.0, (500, 2))
    y = rng.normal(size=(500, 3))
    px, py, counts = bin_readings(x, y, 0.4)
    cells: dict[tuple, list[int]] = {}
    for i, p in enumerate(x):
        cells.setdefault(tuple(np.floor(p / 0.4).astype(int)), []).append(i)
    assert len(px) == len(cells) and counts.sum() == 500
    for (k, members), pos, val, c in zip(
        cells.items(), px, py, counts, strict=True
    ):  # first-reached order
        assert np.array_equal(np.floor(x[members[0]] / 0.4).astype(int), np.array(k))
        np.testing.assert_allclose(pos, x[members].mean(axis=0), atol=1e-12)
        np.testing.assert_allclose(val, y[members].mean(axis=0), atol=1e-12)
        assert c == len(members)


def test_bad_input_is_refused():
    with pytest.raises(ValueError, match=r"^the bin size must be a finite number > 0 m, got 0.0$"):
        bin_readings(np.zeros((3, 2)), np.zeros((3, 3)), 0.0)
    with pytest.raises(ValueError, match=r"^the bin size must be a finite number > 0 m, got True$"):
        bin_readings(np.zeros((3, 2)), np.zeros((3, 3)), True)  # was taken as 1 m
    with pytest.raises(ValueError, match="same n"):
        bin_readings(np.zeros((3, 2)), np.zeros((2, 3)), 0.1)
    with pytest.raises(ValueError, match="finite"):
        bin_readings(np.array([[np.nan, 0.0]]), np.zeros((1, 3)), 0.1)
