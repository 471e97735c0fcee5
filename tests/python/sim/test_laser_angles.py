# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""A simulated laser's beam angles: computed once for its parameters (every scan computed its
up to 10,000 angles anew), bit for bit the evenly spaced angles of its field of view, and a
seeded laser's scans those of the same angles and noise draws."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from _helpers.room_log import room
from kiseki.core import Random
from kiseki.sim.sensors import LASER_PRESETS, Laser2D, LaserParams, Mount


def formula(params: LaserParams) -> np.ndarray:
    """-fov/2 + k fov/(n - 1), k = 0..n-1: the angles a scan used before they were kept."""
    fov = math.radians(params.field_of_view_deg)
    return -fov / 2 + np.arange(params.beams) * (fov / (params.beams - 1))


@pytest.mark.parametrize("name", sorted(LASER_PRESETS))
def test_the_beam_angles_are_computed_once_bit_for_bit_and_read_only(name):
    params = LASER_PRESETS[name]
    angles = params.angles
    assert np.array_equal(angles, formula(params))  # equal, not within a tolerance
    assert params.angles is angles  # kept, not computed again for the next scan
    assert not angles.flags.writeable  # shared by every scan, so nobody may change them
    with pytest.raises(ValueError, match="read-only"):
        angles[0] = 0.0
    for array in (angles, params.angles):  # nor unlock them (their base is bytes)
        with pytest.raises(ValueError, match="WRITEABLE"):
            array.setflags(write=True)
    assert isinstance(angles.base, bytes)
    wider = dataclasses.replace(params, field_of_view_deg=params.field_of_view_deg / 2)
    assert np.array_equal(wider.angles, formula(wider))  # other parameters, their own angles
    assert "angles" not in vars(params)  # a copy built from the fields alone still works
    assert LaserParams(**vars(params)) == params


def test_a_seeded_lasers_scans_use_those_angles_and_its_noise_draws():
    grid = room()
    params = dataclasses.replace(
        LASER_PRESETS["speed_lrf"], noise_fraction=0.02, dropout_probability=0.05
    )
    mount = Mount(x=0.1, y=-0.05, yaw_deg=10.0)
    laser, rng = Laser2D(params, mount, seed=11), Random(11)
    angles, top, n = formula(params), params.max_range, params.beams
    for pose in [(0.0, 0.0, 0.0), (1.5, -1.0, 2.0), (3.0, 1.0, -1.0)]:
        sensor, ranges = laser.scan(grid, pose)
        np.testing.assert_array_equal(sensor, mount.planar(pose))
        truth = grid.cast_scans(sensor[None], angles, max_range=top)[0]
        sd = np.maximum(params.noise_sd, params.noise_fraction * truth)
        noisy = np.clip(truth + sd * rng.normal(0.0, 1.0, n), 0.0, top)
        expected = np.where(truth < top, noisy, top)
        expected[rng.uniform(0.0, 1.0, n) < params.dropout_probability] = top
        assert (truth < top).any() and (expected == top).any()
        np.testing.assert_array_equal(ranges, expected.astype(np.float32))
