# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Both map builders bound the poses they build from (kiseki.mapping.check_map_poses): poses
past +-1e9 m made a map that no map file could hold (only `kiseki map from-log` said so), and
the teaching map's extent was not held to kiseki's map limit (poses 2 km apart built a map of
4e8 cells, four times the limit; 1e6 m apart were refused only by the C++ grid's own 1e9)."""

from __future__ import annotations

import re

import numpy as np
import pytest

from kiseki.mapping import MAX_MAP_CELLS, build_map, check_map_poses
from kiseki.teach.environment_map import build_teaching_map

ANGLES = np.linspace(-1.0, 1.0, 5)
RANGES = np.full((2, 5), 1.0, np.float32)


def _poses(x: float) -> np.ndarray:
    return np.array([[0.0, 0.0, 0.0], [x, 0.5, 0.1]])


@pytest.mark.parametrize("build", [build_map, build_teaching_map])
@pytest.mark.parametrize("x", [1e11, -2e9])
def test_poses_past_a_billion_metres_are_refused(build, x):
    needle = re.escape(f"the poses reach {abs(x):.10g} m, beyond +-1e+09")
    with pytest.raises(ValueError, match=needle):
        build(_poses(x), RANGES, ANGLES, 5.0)


@pytest.mark.parametrize("apart", [2e3, 1e6])
def test_the_teaching_map_states_its_cell_limit(apart):
    with pytest.raises(ValueError, match=re.escape(f"more than the limit of {MAX_MAP_CELLS:.0e}")):
        build_teaching_map(np.array([[0, 0, 0], [apart, apart, 0.0]]), RANGES, ANGLES, 5.0)


@pytest.mark.parametrize("bad", [np.array([[0.0, np.nan, 0.0]]), np.zeros((0, 3)), np.zeros(3)])
def test_the_teaching_map_names_poses_that_are_no_poses(bad):
    with pytest.raises(ValueError, match="poses: expected"):
        build_teaching_map(bad, RANGES[: max(len(np.atleast_2d(bad)), 1)], ANGLES, 5.0)


@pytest.mark.parametrize(
    ("name", "value"),
    [("resolution", np.nan), ("resolution", np.inf), ("resolution", 0.0), ("resolution", True),
     ("local_size", np.nan), ("local_size", -8.0)],
)  # fmt: skip
def test_the_teaching_map_names_a_resolution_or_size_that_is_no_length(name, value):
    """A NaN resolution said 'check_map_size: width must be a finite number', naming neither."""
    with pytest.raises(ValueError, match=f"teaching map: {name} must be a finite number > 0 m"):
        build_teaching_map(_poses(1.0), RANGES, ANGLES, 5.0, **{name: value})


def test_the_bound_itself_is_taken_and_a_metre_past_it_is_not():
    poses = check_map_poses(_poses(1e9))
    assert poses.flags.c_contiguous and poses.dtype == np.float64 and poses[1, 0] == 1e9
    with pytest.raises(ValueError, match=re.escape("reach 1000000001 m, beyond")):
        check_map_poses(_poses(-(1e9 + 1.0)))


def test_both_maps_span_the_poses():
    for grid in (
        build_map(_poses(20.0), RANGES, ANGLES, 5.0),
        build_teaching_map(_poses(20.0), RANGES, ANGLES, 5.0),
    ):
        # the map spans the poses' extent (both poses inside it)
        lo = np.array([grid.origin.x, grid.origin.y])
        hi = lo + grid.resolution * np.array([grid.width, grid.height])
        assert (lo < [0.0, 0.0]).all() and (hi > [20.0, 0.5]).all()
