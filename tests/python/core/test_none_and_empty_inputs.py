# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""An empty series and a missing object (None) given to the library's helpers: answered in kind
or refused naming the argument, never an error from inside numpy or an attribute lookup."""

from __future__ import annotations

import numpy as np
import pytest

from kiseki.gp.hilbert import spectral_tolerance
from kiseki.gp.kernel import refine_hyperparameters
from kiseki.grid import grid_summary
from kiseki.magnetic.rahok_navigation import moving_average


def test_an_empty_series_or_a_missing_object_is_refused_or_answered_in_kind():
    """moving_average([]) was numpy's "cannot reshape array of size 0"; None for a kernel, a
    fit to refine or a grid was an AttributeError from inside."""
    assert moving_average([], 3).shape == (0,)  # nothing to average: nothing
    with pytest.raises(TypeError, match="kernel must be a SquaredExponential, got NoneType"):
        spectral_tolerance(None)
    with pytest.raises(TypeError, match="start must be a HyperparameterFit .* got NoneType"):
        refine_hyperparameters(np.zeros((3, 1)), np.zeros(3), None)
    with pytest.raises(TypeError, match="grid must be a kiseki OccupancyGrid, got NoneType"):
        grid_summary(None)
