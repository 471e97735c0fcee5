# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What the map builders take as a scan: real numbers, at least one beam, finite beam angles.
Before, a local map of NaN angles came back empty as if the scan had seen nothing, complex
readings lost their imaginary part, scans of no beam built a map of unknown cells only, a dict
for build_map's config was "no attribute 'margin'" and check_map_size(1e300, 1, 1e-300) an
OverflowError."""

from __future__ import annotations

import numpy as np
import pytest

from kiseki.mapping import MapBuildConfig, build_map, check_map_size, scan_local_map

ANGLES = np.linspace(-1.0, 1.0, 9)
RANGES = np.full(9, 3.0)
POSES = np.zeros((2, 3))


def test_a_local_map_needs_finite_angles_and_one_scan_of_real_readings():
    known = scan_local_map(ANGLES, RANGES, 10.0).cells != -1
    assert known.sum() > 9  # the reference: the same scan with good angles sees cells
    # None in a list is no reading (NaN), as before: the beam adds nothing
    gap = scan_local_map(ANGLES, [3.0] * 8 + [None], 10.0).cells
    np.testing.assert_array_equal(gap, scan_local_map(ANGLES, [3.0] * 8 + [np.nan], 10.0).cells)
    for angles, ranges, message in [
        (np.full(9, np.nan), RANGES, "local map: angles: contains NaN or infinite values"),
        (np.r_[ANGLES[:8], np.inf], RANGES, "local map: angles: contains NaN or infinite"),
        (ANGLES, RANGES + 0j, "local map: ranges: expected real numbers, got dtype complex128"),
        (ANGLES.astype(str), RANGES, "local map: angles: expected real numbers, got dtype <U"),
        (ANGLES[:0], RANGES[:0], "local map: the scan has no beams"),
        (ANGLES, RANGES > 0, "local map: ranges: expected real numbers, got dtype bool"),
    ]:
        with pytest.raises(ValueError) as caught:
            scan_local_map(angles, ranges, 10.0)
        assert message in str(caught.value)


def test_build_map_needs_a_config_real_readings_and_a_beam():
    grid = build_map(POSES, np.tile(RANGES, (2, 1)), ANGLES, 10.0)
    assert (grid.cells == 100).any()  # the reference: the walls are in it
    with pytest.raises(ValueError, match=r"^ranges: expected real numbers, got dtype complex128"):
        build_map(POSES, np.tile(RANGES, (2, 1)) + 1j, ANGLES, 10.0)
    with pytest.raises(ValueError, match=r"^angles: expected real numbers, got dtype object"):
        build_map(
            POSES, np.tile(RANGES, (2, 1)), np.array([*ANGLES[:8], "1_0"], dtype=object), 10.0
        )
    with pytest.raises(ValueError, match=r"beams >= 1, got shape \(2, 0\)"):
        build_map(POSES, np.zeros((2, 0)), np.zeros(0), 10.0)
    with pytest.raises(TypeError, match="config must be a MapBuildConfig, got dict"):
        build_map(POSES, np.tile(RANGES, (2, 1)), ANGLES, 10.0, {"resolution": 0.1})
    same = build_map(POSES, np.tile(RANGES, (2, 1)), ANGLES, 10.0, MapBuildConfig())
    np.testing.assert_array_equal(same.cells, grid.cells)
    for margin in (-1.0, np.nan, True):  # True was taken as a margin of 1 m
        with pytest.raises(ValueError, match="^margin must be a finite number >= 0 m, got "):
            build_map(POSES, np.tile(RANGES, (2, 1)), ANGLES, 10.0, MapBuildConfig(margin=margin))


def test_a_map_too_large_for_a_float_is_over_the_limit_not_an_overflow():
    with pytest.raises(ValueError, match=r"makes a map of inf x 1e\+300 cells .* more than the"):
        check_map_size(1e300, 1.0, 1e-300)
    assert check_map_size(2.0, 1.0, 0.1) == (20, 10)  # the closed form, ceil(side / cell)
