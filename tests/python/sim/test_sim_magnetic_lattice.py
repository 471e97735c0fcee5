# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The seeded random dipole lattice (a slab's or a wall's rebar): its cells, the statistics of
its moments, its field as the sum of its dipoles, its scene key and its errors."""

from __future__ import annotations

import numpy as np
import pytest

from kiseki.sim.magnetic import Dipole, MagneticWorld
from kiseki.sim.magnetic_lattice import MAX_LATTICE_DIPOLES, DipoleLattice


def test_cells_fill_the_box_and_a_flat_side_is_one_layer():
    lat = DipoleLattice([0.0, 0.0, -0.2], [2.0, 1.0, -0.2], 0.25, [1.0, 1.0, 1.0], seed=1)
    assert lat.positions.shape == (8 * 4, 3)
    np.testing.assert_allclose(np.unique(lat.positions[:, 0]), 0.125 + 0.25 * np.arange(8))
    np.testing.assert_allclose(np.unique(lat.positions[:, 1]), 0.125 + 0.25 * np.arange(4))
    assert np.all(lat.positions[:, 2] == -0.2) and lat.radius == 0.125
    odd = DipoleLattice([0, 0, 0], [1.0, 0, 0], 0.3, [1, 1, 1])  # 1.0 / 0.3 -> 3 cells
    np.testing.assert_allclose(odd.positions[:, 0], [1 / 6, 0.5, 5 / 6])


def test_moments_have_the_stated_mean_and_sd_and_follow_the_seed():
    kw = {"lower": [0, 0, 0], "upper": [20, 20, 0], "spacing": 0.2, "moment_sd": [0.5, 1.0, 2.0]}
    lat = DipoleLattice(**kw, moment_mean=[0.0, 0.3, -1.0], seed=7)
    n = len(lat.moments)
    assert n == 10_000
    se = np.array([0.5, 1.0, 2.0]) / np.sqrt(n)
    assert np.all(np.abs(lat.moments.mean(axis=0) - [0.0, 0.3, -1.0]) < 4 * se)
    np.testing.assert_allclose(lat.moments.std(axis=0), [0.5, 1.0, 2.0], rtol=0.03)
    same = DipoleLattice(**kw, moment_mean=[0.0, 0.3, -1.0], seed=7)
    np.testing.assert_array_equal(same.moments, lat.moments)
    assert not np.allclose(DipoleLattice(**kw, seed=8).moments, DipoleLattice(**kw, seed=7).moments)


def test_field_is_the_sum_of_its_dipoles_and_the_scene_key_round_trips():
    lat = DipoleLattice([0, 0, -0.3], [1.0, 0.6, -0.3], 0.2, [0.4, 0.4, 0.4], seed=3)
    points = np.array([[0.5, 0.3, 0.15], [-0.2, 1.0, 0.5], [0.1, 0.1, 0.0]])
    reference = sum(
        Dipole(p, m, lat.radius).field_at(points)
        for p, m in zip(lat.positions, lat.moments, strict=True)
    )
    np.testing.assert_allclose(lat.field_at(points), reference, rtol=1e-12, atol=1e-15)
    world = MagneticWorld.from_dict({"lattices": [lat.to_dict()], "drift": {"amplitude": 0.0}})
    np.testing.assert_allclose(world.field_at(points) - world.earth_field, reference, rtol=1e-12)
    again = MagneticWorld.from_dict(world.to_dict())
    np.testing.assert_array_equal(again.field_at(points), world.field_at(points))


@pytest.mark.parametrize(
    ("lattice", "match"),
    [
        (
            {"lower": [0, 0], "upper": [1, 1, 1], "spacing": 1, "moment_sd": [1, 1, 1]},
            r"lattices\[0\]\.lower: must be a list of 3 numbers \[x, y, z\], got \[0, 0\]",
        ),
        (
            {"lower": [0, 0, 0], "upper": [1, -1, 1], "spacing": 1, "moment_sd": [1, 1, 1]},
            "upper: must be >= lower",
        ),
        (
            {"lower": [0, 0, 0], "upper": [1, 1, 1], "spacing": 0, "moment_sd": [1, 1, 1]},
            "spacing: must be greater than 0, got 0",
        ),
        (
            {"lower": [0, 0, 0], "upper": [1, 1, 1], "spacing": 1, "moment_sd": [1, -1, 1]},
            r"moment_sd\[1\]: must be greater than or equal to 0, got -1",
        ),
        ({"lower": [0, 0, 0], "upper": [1, 1, 1], "spacing": 1}, r"moment_sd: missing"),
        (
            {
                "lower": [0, 0, 0],
                "upper": [1, 1, 1],
                "spacing": 1,
                "moment_sd": [1, 1, 1],
                "seed": -1,
            },
            "seed: must be",
        ),
        (
            {
                "lower": [0, 0, 0],
                "upper": [1, 1, 1],
                "spacing": 1,
                "moment_sd": [1, 1, 1],
                "seed": True,
            },
            r"seed: must be an integer in \[0, 2\*\*64\), got True",
        ),
        (
            {"lower": [0, 0, 0], "upper": [1, 1, 1], "spacing": 1, "moment_sd": [1, 1, 1], "x": 1},
            r"lattices\[0\]\.x: unknown key",
        ),
        (
            {"lower": [0, 0, 0], "upper": [100, 100, 0], "spacing": 0.1, "moment_sd": [1, 1, 1]},
            rf"spacing: makes 1000000 dipoles"
            rf" .*more than the limit of {MAX_LATTICE_DIPOLES}, got 0\.1",
        ),
        (
            {
                "lower": [0, 0, float("nan")],
                "upper": [1, 1, 1],
                "spacing": 1,
                "moment_sd": [1, 1, 1],
            },
            "finite",
        ),
    ],
)
def test_bad_lattices_are_named(lattice, match):
    with pytest.raises(ValueError, match=match) as info:
        MagneticWorld.from_dict({"lattices": [lattice]}, "scene.yaml")
    assert str(info.value).startswith("scene.yaml: lattices[0].")
