# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The cells of a field map over a box, one count for the map and for the fit command's check
before fitting (the command counted them with floats of its own)."""

from __future__ import annotations

import numpy as np
import pytest

from kiseki.magnetic.map_cells import cell_span


def test_cells_cover_the_box_and_a_bound_on_an_edge_stays_on_its_side():
    first, last, counts = cell_span([0.0, -0.25], [1.0, 0.3], 0.1)
    np.testing.assert_array_equal(first, [0, -3])
    np.testing.assert_array_equal(last, [10, 3])  # 1.0 / 0.1 = 10.000000000000002: cell 10's edge
    np.testing.assert_array_equal(counts, [10, 6])
    rng = np.random.default_rng(1)
    for _ in range(100):  # against the cells whose centres' span reaches into the box
        lo = rng.uniform(-5, 5, 2)
        hi = lo + rng.uniform(0.01, 3, 2)
        res = rng.uniform(0.05, 0.5)
        first, last, counts = cell_span(lo, hi, res)
        assert np.all(first * res <= lo + 1e-9 * res) and np.all(last * res >= hi - 1e-9 * res)
        assert np.all((first + 1) * res > lo) and np.all((last - 1) * res < hi)
        np.testing.assert_array_equal(counts, np.maximum(last - first, 1))
    _, _, counts = cell_span([2.0, 2.0], [2.0, 2.0], 0.1)  # a point: one cell a side
    np.testing.assert_array_equal(counts, [1, 1])


def test_indices_past_int64_are_refused():
    with pytest.raises(ValueError, match="beyond any grid's cell indices"):
        cell_span([0.0, 0.0], [1.0, 1.0], 1e-300)
