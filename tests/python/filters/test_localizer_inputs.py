# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What the localizer is given, checked before the engine runs: a map or a config of another
kind was an AttributeError from inside ('NoneType' object has no attribute 'to_core',
'str' object has no attribute 'ranges') or a pybind11 list of signatures."""

from __future__ import annotations

import numpy as np
import pytest

from _helpers.room_log import room, room_scans
from kiseki.filters import LocalizeConfig, MclConfig, MonteCarloLocalizer
from kiseki.filters.tracking import localize
from kiseki.scans import LaserScans


def _scans(n: int = 4) -> LaserScans:
    return room_scans(n, length=0.3)


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        ({"config": None}, "config must be an MclConfig, got NoneType"),
        ({"config": LocalizeConfig()}, "config must be an MclConfig, got LocalizeConfig"),
        ({"free_space": "room.yaml"}, "free_space must be a kiseki OccupancyGrid or None, got str"),
        (
            {"free_space": np.zeros((4, 4))},
            "free_space must be a kiseki OccupancyGrid or None, got ndarray",
        ),
    ],
)
def test_the_localizer_refuses_a_config_or_map_of_another_kind(args, needle):
    call = {"config": MclConfig(particles=10), "seed": 1, "free_space": room()} | args
    with pytest.raises(TypeError) as caught:
        MonteCarloLocalizer(**call)
    assert str(caught.value) == needle


@pytest.mark.parametrize("seed", [None, 1.5, -1, True, 2**64])
def test_the_localizer_refuses_a_seed_that_is_not_one(seed):
    with pytest.raises(ValueError, match=r"seed must be an integer in \[0, 2\*\*64\), got "):
        MonteCarloLocalizer(MclConfig(particles=10), seed)
    # numpy integers are seeds: the same particles as Python's
    a, b = (MonteCarloLocalizer(MclConfig(particles=10), s) for s in (np.uint64(7), 7))
    for loc in (a, b):
        loc.initialize((1.0, -1.0, 0.0), (0.1, 0.1, 0.1))
    np.testing.assert_array_equal(a.poses, b.poses)


@pytest.mark.parametrize(
    ("which", "bad", "needle"),
    [
        ("scans", None, "localize: scans must be a LaserScans (a log's scans), got NoneType"),
        ("grid", None, "localize: grid must be a kiseki OccupancyGrid, got NoneType"),
        ("grid", "room.yaml", "localize: grid must be a kiseki OccupancyGrid, got str"),
        ("config", None, "localize: config must be a LocalizeConfig, got NoneType"),
        ("config", MclConfig(), "localize: config must be a LocalizeConfig, got MclConfig"),
    ],
)
def test_localize_refuses_a_log_map_or_config_of_another_kind(which, bad, needle):
    call = {"scans": _scans(), "grid": room(), "config": LocalizeConfig(particles=50)}
    with pytest.raises(TypeError) as caught:
        localize(**(call | {which: bad}))
    assert str(caught.value) == needle
