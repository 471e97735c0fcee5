# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""TiledGP against one exact GP on every reading (the reference it approximates), its cost
rule's tile counts against a brute-force count, and its checks of what it is given."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from kiseki import _core
from kiseki.gp import (
    ExactGP,
    HilbertGP,
    SquaredExponential,
    TiledGP,
    hilbert_basis_size,
    spectral_tolerance,
)
from kiseki.gp.tiled import _cheaper, _tile_counts

KERNEL = SquaredExponential(1.0, 0.5, 0.1)


def smooth_field(x: np.ndarray) -> np.ndarray:
    """Two components varying on the kernel's length scale (0.5 m) over the whole area."""
    return np.c_[
        np.sin(2.1 * x[:, 0]) * np.cos(1.7 * x[:, 1]),
        np.cos(1.3 * x[:, 0] + 2.3 * x[:, 1]),
    ]


@pytest.fixture(scope="module")
def strip():
    """2,400 noisy readings over a 12 x 5 m strip; query points on a grid over it."""
    rng = np.random.default_rng(7)
    x = rng.uniform([0.0, 0.0], [12.0, 5.0], (2400, 2))
    y = smooth_field(x) + rng.normal(0.0, KERNEL.sigma_n, (len(x), 2))
    g = np.stack(np.meshgrid(np.arange(0.05, 12, 0.1), np.arange(0.05, 5, 0.1)), -1)
    q = g.reshape(-1, 2)
    return x, y, q, ExactGP.fit(x, y, KERNEL).predict(q)


@pytest.mark.parametrize("solver", ["exact", "hilbert"])
def test_tiles_predict_what_one_exact_gp_on_every_reading_predicts(strip, solver):
    """Criterion: the tiled means within 0.1 sigma_n RMS (0.5 sigma_n at worst) of one exact GP
    on all 2,400 readings, the variances within 0.01 sigma_f^2 (signal-to-noise ratio 10).
    Control: the same tiles without overlap (each fitted on its core's readings alone) miss the
    bound at the seams."""
    x, y, q, (e_mean, e_var) = strip
    tiled = TiledGP.fit(x, y, KERNEL, solver=solver, tiles_per_axis=[4, 2])
    mean, var = tiled.predict(q)
    assert tiled.tiles == 8 and set(tiled.solvers) == {solver}
    sn = KERNEL.sigma_n
    assert np.sqrt(np.mean((mean - e_mean) ** 2)) < 0.1 * sn
    assert np.abs(mean - e_mean).max() < 0.5 * sn
    assert np.abs(var - e_var).max() < 0.01
    cut = TiledGP.fit(x, y, KERNEL, solver=solver, tiles_per_axis=[4, 2], overlap=0.0)
    assert np.abs(cut.predict(q)[0] - e_mean).max() > 0.5 * sn


def test_the_cost_rule_picks_tiles_and_solvers_that_match_the_exact_gp(strip):
    """The default grid and per-tile solver: more than one tile on the strip, and the same
    bounds against the exact GP as above."""
    x, y, q, (e_mean, e_var) = strip
    tiled = TiledGP.fit(x, y, KERNEL)
    mean, var = tiled.predict(q)
    assert tiled.tiles > 1
    assert np.sqrt(np.mean((mean - e_mean) ** 2)) < 0.1 * KERNEL.sigma_n
    assert np.abs(var - e_var).max() < 0.01


def test_far_points_get_the_prior_and_one_tile_is_the_exact_gp(strip):
    x, y, q, _ = strip
    tiled = TiledGP.fit(x, y, KERNEL, tiles_per_axis=[1, 1], solver="exact")
    mean, var = tiled.predict(np.array([[100.0, 100.0], [-50.0, 2.0]]))
    np.testing.assert_allclose(mean, np.repeat(y.mean(axis=0)[None], 2, axis=0), rtol=1e-12)
    np.testing.assert_allclose(var, KERNEL.sigma_f**2, rtol=1e-12)
    one = ExactGP.fit(x, y, KERNEL).predict(q[:500])
    mine = tiled.predict(q[:500])
    np.testing.assert_allclose(mine[0], one[0], atol=1e-9)
    np.testing.assert_allclose(mine[1], one[1], atol=1e-9)
    again = TiledGP.fit(x, y, KERNEL, tiles_per_axis=[1, 1], solver="exact").predict(q[:500])
    assert np.array_equal(again[0], mine[0])


def test_tile_counts_equal_a_brute_force_count():
    rng = np.random.default_rng(3)
    x = rng.uniform([0, 0, 0], [9.0, 4.0, 2.0], (3000, 3))
    lower, extent = x.min(axis=0), np.ptp(x, axis=0)
    for counts, overlap in [((3, 2, 1), 1.0), ((7, 3, 2), 0.4), ((1, 1, 1), 0.0)]:
        counts = np.array(counts)
        width = extent / counts
        brute = []
        for index in itertools.product(*(range(k) for k in counts)):
            lo = lower + width * np.array(index) - overlap
            brute.append(int(np.all((x >= lo) & (x <= lo + width + 2 * overlap), axis=1).sum()))
        assert _tile_counts(x, lower, counts, width, overlap).tolist() == brute


@pytest.mark.parametrize(
    "sides, length_scale", [([7.0], 0.3), ([4.0, 6.5], 0.5), ([5.0, 3.0, 2.2], 0.6)]
)
def test_basis_size_rule_equals_hilbert_gps(sides, length_scale):
    d = len(sides)
    x = 0.5 + 0.1 * np.r_[np.zeros((1, d)), np.eye(d)]
    kernel = SquaredExponential(1.0, length_scale, 0.1)
    gp = HilbertGP.fit(x, np.arange(d + 1.0), kernel, domain=(np.zeros(d), sides))
    assert hilbert_basis_size(sides, length_scale, spectral_tolerance(kernel)) == gp.basis_size


@pytest.mark.parametrize(
    "sides, length_scale", [([30.0, 12.0], 0.05), ([10.0, 7.0, 3.0], 0.08), ([400.0, 300.0], 0.2)]
)
def test_basis_size_counted_by_search_equals_every_combination(monkeypatch, sides, length_scale):
    """Above 20 M combinations the count is taken by a search per value of the first sides (a
    dense grid of every combination asked for 20 GiB at sides [1e9, 3]); here both ways."""
    import kiseki.gp.hilbert as hilbert

    dense = hilbert_basis_size(sides, length_scale, 1e-4)
    monkeypatch.setattr(hilbert, "_DENSE_COUNT", 0)
    assert hilbert_basis_size(sides, length_scale, 1e-4) == dense > 200_000


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (([1e9, 3.0], 0.5, 1e-4), "a side of 1e\\+09 at length scale 0.5 holds 2.73e\\+09"),
        (([3.0, 3.0], 0.0, 1e-4), r"length_scale must be a finite number > 0, got 0\.0$"),
        (([3.0, 3.0], 0.5, 0.0), r"tolerance must be a finite number in \(0, 1\), got 0\.0$"),
        (([3.0, 3.0], 0.5, True), r"tolerance must be a finite number in \(0, 1\), got True$"),
        (([-1.0, 3.0], 0.5, 1e-4), "sides must be 1-3 lengths > 0"),
    ],
)
def test_basis_size_refuses_what_it_cannot_count(args, message):
    with pytest.raises(ValueError, match=message):
        hilbert_basis_size(*args)


def test_a_length_scale_far_below_the_box_is_refused_in_one_line(strip):
    """A micrometre length scale over a 10 m strip asked for 176 TiB."""
    x, y, _, _ = strip
    with pytest.raises(ValueError, match="eigenfunctions, more than 10,000,000"):
        TiledGP.fit(x, y, SquaredExponential(1.0, 1e-6, 0.1))


def test_what_it_is_given_is_checked(strip):
    x, y, _, _ = strip
    with pytest.raises(ValueError, match="solver must be one of"):
        TiledGP.fit(x, y, KERNEL, solver="fast")
    with pytest.raises(ValueError, match=r"^overlap must be a finite number >= 0 m, got -1\.0$"):
        TiledGP.fit(x, y, KERNEL, overlap=-1.0)
    with pytest.raises(ValueError, match=r"^margin must be a finite number >= 0 m, got inf$"):
        TiledGP.fit(x, y, KERNEL, margin=np.inf)
    with pytest.raises(
        ValueError, match=r"^tolerance must be a finite number in \(0, 1\), got nan$"
    ):
        TiledGP.fit(x, y, KERNEL, tolerance=np.nan)
    with pytest.raises(ValueError, match="tiles_per_axis must be 2 integers"):
        TiledGP.fit(x, y, KERNEL, tiles_per_axis=[2])
    with pytest.raises(ValueError, match="1-3 coordinates"):
        TiledGP.fit(np.zeros((3, 4)), np.zeros(3), KERNEL)
    with pytest.raises(ValueError, match="NaN or infinite"):
        TiledGP.fit(np.where(x == x[0], np.nan, x), y, KERNEL)
    with pytest.raises(ValueError, match="kernel must be a SquaredExponential"):
        TiledGP.fit(x, y, (1.0, 0.5, 0.1))
    with pytest.raises(ValueError, match="needs at least 3 readings"):
        TiledGP.fit(x[:1], y[:1], KERNEL)
    with pytest.raises(ValueError, match="points have 3 coordinates"):
        TiledGP.fit(x, y, KERNEL, tiles_per_axis=[2, 1]).predict(np.zeros((2, 3)))


def test_a_tile_reaching_one_reading_takes_the_next_nearest_too():
    """Two clusters far apart and one lone reading in a tile of its own: every reading is used
    (the lone one's tile takes the nearest others too, d + 1 in all) and the prediction at the
    lone reading moves towards it, as the exact GP's does."""
    rng = np.random.default_rng(1)
    x = np.r_[rng.uniform(0, 1, (40, 2)), rng.uniform(9, 10, (40, 2)), [[5.0, 0.5]]]
    y = np.r_[np.zeros((80, 1)), [[3.0]]]
    tiled = TiledGP.fit(x, y, KERNEL, tiles_per_axis=[5, 1], overlap=0.5)
    assert "none" in tiled.solvers and tiled.solvers[2] == "exact"
    exact = ExactGP.fit(x, y, KERNEL).predict([[5.0, 0.5]])[0]
    assert tiled.predict([[5.0, 0.5]])[0][0, 0] == pytest.approx(exact[0, 0], abs=0.05)


def test_a_core_without_truncated_prediction_predicts_as_the_dense_path():
    """Above 2,000 readings the exact core keeps the inverse for truncated prediction; a tile's
    core is built without it and predicts with every reading through the factor: the same
    means and variances as the full core's dense path (truncation 0), to rounding."""
    rng = np.random.default_rng(5)
    x = rng.uniform(0.0, [4.0, 3.0, 2.0], (2100, 3))
    y = rng.normal(size=(2100, 2))
    q = rng.uniform(0.0, [4.0, 3.0, 2.0], (300, 3))
    args = (x, y, 1.0, 0.5, 0.1, False)
    dense = _core.ExactGaussianProcess(*args).predict(q, 0.0)
    tile = _core.ExactGaussianProcess(*args, truncated_prediction=False).predict(q, 1e-3)
    np.testing.assert_allclose(tile[0], dense[0], rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(tile[1], dense[1], rtol=1e-10, atol=1e-12)
    truncated = _core.ExactGaussianProcess(*args).predict(q, 1e-3)
    assert np.abs(truncated[0] - dense[0]).max() > 1e-9  # the truncation the tile does not do


def test_a_tile_s_solver_is_the_one_of_fewer_operations_within_the_reduced_rank_cap():
    """By the operation counts: 20,000 readings, 3,000 basis functions: 2 n m^2 + m^3 / 3 =
    3.7e11 against 4 n^3 / 3 = 1.1e13, the reduced rank; 500 readings: 1.7e8 exact against
    1.8e10; beyond HilbertGP's 20,000 functions the exact GP, however costly."""
    assert _cheaper(20_000, 3_000) == "hilbert"
    assert _cheaper(500, 3_000) == "exact"
    assert _cheaper(20_000, 20_001) == "exact"


def test_unbuilt_tiles_are_factorised_on_first_use_to_the_same_predictions(strip):
    """build=False: no tile factorised at first; points in one core factorise that tile alone,
    with the same means and variances, bit for bit, as the tiles built at once."""
    x, y, q, _ = strip
    eager = TiledGP.fit(x, y, KERNEL, tiles_per_axis=[4, 2])
    lazy = TiledGP.fit(x, y, KERNEL, tiles_per_axis=[4, 2], build=False)
    assert eager.built == 8 and lazy.built == 0
    corner = q[(q[:, 0] < 2.9) & (q[:, 1] < 2.4)]  # inside the first core (3 x 2.5 m)
    mine = lazy.predict(corner)
    assert lazy.built == 1
    assert all(np.array_equal(a, b) for a, b in zip(mine, eager.predict(corner), strict=True))
    whole = lazy.predict(q)
    assert lazy.built == 8
    assert all(np.array_equal(a, b) for a, b in zip(whole, eager.predict(q), strict=True))


def test_released_tiles_predict_the_same_and_leave_none_factorised(strip):
    """predict(release=True), as a map's cells are computed: every tile factorised for its
    points and freed after them, the same means and variances bit for bit as tiles kept; a
    later call factorises them again, to the same values."""
    x, y, q, _ = strip
    kept = TiledGP.fit(x, y, KERNEL, tiles_per_axis=[4, 2])
    released = TiledGP.fit(x, y, KERNEL, tiles_per_axis=[4, 2], build=False)
    for _ in range(2):
        once = released.predict(q, release=True)
        assert released.built == 0
        assert all(np.array_equal(a, b) for a, b in zip(once, kept.predict(q), strict=True))
    assert kept.built == 8
