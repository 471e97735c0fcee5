# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""LaserScans' fields describe the same scans: a user's scans with a field of another length
were localized along the shorter one (2 estimates for 6 scans, without a word), or failed
deep inside with an IndexError."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from _helpers.room_log import room, room_scans
from kiseki.filters import LocalizeConfig, localize
from kiseki.scans import LaserScans


def _scans(n: int = 6) -> LaserScans:
    return room_scans(n)


def test_fields_of_other_lengths_are_refused_naming_the_field():
    scans = _scans()
    n, b = len(scans), len(scans.angles)
    assert len(localize(scans, room(), LocalizeConfig(particles=100)).estimates) == n
    for name, value, named in [
        ("times", scans.times[:2], "poses has shape (6, 3), expected (2, 3) (2 scans in times"),
        ("poses", scans.poses[:, :2], "poses has shape (6, 2), expected (6, 3)"),
        ("odometry", scans.odometry[:-1], "odometry has shape (5, 3), expected (6, 3)"),
        ("ranges", scans.ranges[:, :-1], f"ranges has shape (6, {b - 1}), expected (6, {b})"),
        ("angles", np.zeros((b, 1)), "angles has shape (91, 1), expected one value per beam"),
    ]:
        with pytest.raises(ValueError) as caught:
            dataclasses.replace(scans, **{name: value})
        assert str(caught.value).startswith(f"LaserScans: {named}"), str(caught.value)
        assert "\n" not in str(caught.value)
    for bad in (0.0, -1.0, math.nan, math.inf, True, "8"):
        with pytest.raises(ValueError, match="LaserScans: max_range must be"):
            dataclasses.replace(scans, max_range=bad)
