# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""kiseki.gp against scikit-learn's GaussianProcessRegressor (the reference) and closed forms."""

from __future__ import annotations

import numpy as np
import pytest
from sklearn.gaussian_process import GaussianProcessRegressor
from sklearn.gaussian_process.kernels import RBF, WhiteKernel
from sklearn.gaussian_process.kernels import ConstantKernel as Constant

from kiseki.gp import (
    CurlFreeKernel,
    ExactGP,
    HilbertGP,
    SquaredExponential,
    fit_hyperparameters,
    spectral_tolerance,
)
from kiseki.gp.kernel import log_marginal_likelihood


def field(x: np.ndarray, noise: float, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    y = np.c_[
        np.sin(1.3 * x[:, 0]) * np.cos(0.7 * x[:, 1]),
        0.3 * x[:, 0] - np.cos(x[:, 1]),
        x[:, 1] ** 2 / 9,
    ]
    return y + rng.normal(0.0, noise, y.shape)


@pytest.fixture(scope="module")
def data():
    rng = np.random.default_rng(0)
    x = rng.uniform(0.0, 3.0, (250, 2))
    return x, field(x, 0.05, 1), rng.uniform(-0.5, 3.5, (120, 2))


def sklearn_fixed(kernel: SquaredExponential, x, y):
    k = Constant(kernel.sigma_f**2, "fixed") * RBF(kernel.length_scale, "fixed")
    return GaussianProcessRegressor(k, alpha=kernel.sigma_n**2, optimizer=None).fit(x, y)


def test_prediction_equals_scikit_learn(data):
    x, y, q = data
    kernel = SquaredExponential(1.1, 0.6, 0.07)
    gp = ExactGP.fit(x, y, kernel, mean="zero")
    mean, var = gp.predict(q)
    ref_mean, ref_std = sklearn_fixed(kernel, x, y).predict(q, return_std=True)
    np.testing.assert_allclose(mean, ref_mean, atol=1e-10)
    np.testing.assert_allclose(var, ref_std**2, atol=1e-10)
    assert var.shape == (len(q), 3)


def test_a_truncation_that_is_not_a_number_is_refused_by_name(data):
    """'a' was pybind11's "incompatible function arguments" with the signature list; a number
    out of range reads as one that is no number."""
    x, y, q = data
    gp = ExactGP.fit(x, y, SquaredExponential(1.1, 0.6, 0.07), mean="zero")
    for bad, shown in (("a", "'a'"), (True, "True"), (None, "None"), (1.5, "1.5"), (np.nan, "nan")):
        rule = r"^predict: truncation must be a finite number in \[0, 1\), got "
        with pytest.raises(ValueError, match=rule + shown + "$"):
            gp.predict(q, truncation=bad)
    np.testing.assert_array_equal(gp.predict(q, truncation=0)[0], gp.predict(q, truncation=0.0)[0])


def test_log_marginal_likelihood_and_gradient_equal_scikit_learn(data):
    x, y, _ = data
    kernel = SquaredExponential(0.9, 0.5, 0.1)
    value, gradient = log_marginal_likelihood(x, y[:, 0], kernel, mean="zero")
    sk = Constant(1.0) * RBF(1.0) + WhiteKernel(1.0)
    reg = GaussianProcessRegressor(sk, alpha=0.0, optimizer=None).fit(x, y[:, 0])
    # scikit-learn's theta: (log sigma_f^2, log l, log sigma_n^2).
    theta = np.log([kernel.sigma_f**2, kernel.length_scale, kernel.sigma_n**2])
    ref_value, ref_gradient = reg.log_marginal_likelihood(theta, eval_gradient=True)
    assert value == pytest.approx(ref_value, rel=1e-10)
    np.testing.assert_allclose(gradient, ref_gradient * [2.0, 1.0, 2.0], rtol=1e-7)


def test_hyperparameters_reach_scikit_learns_optimum(data):
    x, y, _ = data
    fit = fit_hyperparameters(x, y[:, 1], mean="zero", restarts=1, seed=0)
    sk = Constant(1.0) * RBF(1.0) + WhiteKernel(0.1)
    reg = GaussianProcessRegressor(sk, n_restarts_optimizer=1, random_state=0).fit(x, y[:, 1])
    assert fit.log_marginal_likelihood >= reg.log_marginal_likelihood_value_ - 1e-6
    params = reg.kernel_.get_params()
    assert fit.kernel.length_scale == pytest.approx(params["k1__k2__length_scale"], rel=1e-2)
    assert fit.kernel.sigma_n**2 == pytest.approx(params["k2__noise_level"], rel=2e-2)
    again = fit_hyperparameters(x, y[:, 1], mean="zero", restarts=1, seed=0)
    assert again.kernel == fit.kernel  # the same seed, the same answer


def test_shared_and_per_component_kernels(data):
    x, y, q = data
    shared = ExactGP.fit(x, y, restarts=1)
    per = ExactGP.fit(x, y, restarts=1, per_component=True)
    assert len(shared.kernels) == 1 and len(per.kernels) == 3
    for c in range(3):
        alone = ExactGP.fit(x, y[:, c], per.kernels[c])
        np.testing.assert_allclose(per.predict(q)[0][:, c], alone.predict(q)[0][:, 0], atol=1e-12)
    # Each component's own kernel explains it at least as well as the shared one.
    assert per.log_marginal_likelihood() >= shared.log_marginal_likelihood() - 1e-6


def test_constant_mean_is_the_prior_far_away(data):
    x, y, _ = data
    gp = ExactGP.fit(x, y, SquaredExponential(1.0, 0.5, 0.05))
    mean, var = gp.predict([[100.0, 100.0]])
    np.testing.assert_allclose(mean[0], y.mean(axis=0), atol=1e-12)
    np.testing.assert_allclose(var[0], 1.0, atol=1e-12)


def test_far_coordinates_lose_no_digits(data):
    # The same problem 5e6 m from the origin (UTM-like northings): the same predictions.
    x, y, q = data
    kernel = SquaredExponential(1.0, 0.5, 0.05)
    near = ExactGP.fit(x, y, kernel).predict(q)
    far = ExactGP.fit(x + 5e6, y, kernel).predict(q + 5e6)
    np.testing.assert_allclose(far[0], near[0], atol=1e-8)
    np.testing.assert_allclose(far[1], near[1], atol=1e-8)


def test_duplicate_inputs_are_fitted(data):
    # Two readings at each place, y and y + 0.01, with noise variance s^2 are one reading of
    # their mean, y + 0.005, with noise variance s^2 / 2 (the product of the two Gaussians):
    # the same posterior mean and variance everywhere.
    x, y, q = data
    xx, yy = np.vstack([x, x]), np.vstack([y, y + 0.01])
    twice = ExactGP.fit(xx, yy, SquaredExponential(1.0, 0.5, 0.05)).predict(q)
    once = ExactGP.fit(x, y + 0.005, SquaredExponential(1.0, 0.5, 0.05 / np.sqrt(2))).predict(q)
    np.testing.assert_allclose(twice[0], once[0], rtol=0, atol=1e-9)
    np.testing.assert_allclose(twice[1], once[1], rtol=0, atol=1e-9)
    # With almost no noise the doubled matrix is singular to rounding (K's own condition number
    # at this spacing is beyond 1e12, so no value is asserted): the fit must still factorise.
    tight = ExactGP.fit(xx, yy, SquaredExponential(1.0, 0.5, 1e-6))
    assert np.isfinite(tight.predict(q)[0]).all()


def test_hilbert_gp_approaches_the_exact_gp(data):
    x, y, q = data
    kernel = SquaredExponential(1.0, 0.6, 0.05)
    exact = ExactGP.fit(x, y, kernel)
    hilbert = HilbertGP.fit(x, y, kernel, tolerance=1e-8)
    inside = (q >= 0).all(axis=1) & (q <= 3).all(axis=1)
    e_mean, e_var = exact.predict(q[inside])
    h_mean, h_var = hilbert.predict(q[inside])
    assert np.abs(e_mean - h_mean).max() < 5e-3
    assert np.abs(e_var - h_var).max() < 5e-3
    # Fewer basis functions, a coarser approximation.
    coarse = HilbertGP.fit(x, y, kernel, tolerance=1e-2)
    assert coarse.basis_size < hilbert.basis_size
    assert np.abs(coarse.predict(q[inside])[0] - e_mean).max() > np.abs(h_mean - e_mean).max()


@pytest.mark.parametrize("ratio", [10.0, 60.0])
def test_hilbert_gp_s_default_cut_follows_the_exact_gp_however_far_the_field_stands_above_noise(
    ratio,
):
    """Criterion: with its default spectral tolerance the reduced-rank mean lies within 0.02
    sigma_n RMS and 0.1 sigma_n at worst of the exact GP's on the same 2,400 readings, at
    sigma_f / sigma_n = 10 and 60. Control: the fixed 1e-4 (the rule's value at a ratio of 1)
    misses the worst-case bound at 60 (1.4-2.1 sigma_n measured) and keeps fewer functions."""
    rng = np.random.default_rng(7)
    x = rng.uniform([0.0, 0.0], [12.0, 5.0], (2400, 2))
    kernel = SquaredExponential(1.0, 0.5, 1.0 / ratio)
    y = np.c_[np.sin(2.1 * x[:, 0]) * np.cos(1.7 * x[:, 1]), np.cos(1.3 * x[:, 0] + 2.3 * x[:, 1])]
    y = y + rng.normal(0.0, kernel.sigma_n, y.shape)
    g = np.stack(np.meshgrid(np.arange(0.05, 12, 0.1), np.arange(0.05, 5, 0.1)), -1)
    q = g.reshape(-1, 2)
    exact = ExactGP.fit(x, y, kernel).predict(q)[0]
    default = HilbertGP.fit(x, y, kernel)
    assert default.tolerance == pytest.approx(1e-4 / ratio**2)
    gap = (default.predict(q)[0] - exact) / kernel.sigma_n
    assert np.sqrt(np.mean(gap**2)) < 0.02 and np.abs(gap).max() < 0.1
    fixed = HilbertGP.fit(x, y, kernel, tolerance=1e-4)
    assert fixed.basis_size < default.basis_size
    if ratio == 60.0:
        assert np.abs(fixed.predict(q)[0] - exact).max() > 0.5 * kernel.sigma_n


def test_spectral_tolerance_is_1e_4_until_the_field_stands_above_its_noise():
    assert spectral_tolerance(SquaredExponential(1.0, 0.5, 2.0)) == 1e-4
    assert spectral_tolerance(SquaredExponential(1.0, 0.5, 1.0)) == 1e-4
    assert spectral_tolerance(SquaredExponential(3.0, 0.5, 1.0)) == pytest.approx(1e-4 / 9)


def test_two_stages_reach_the_one_stage_optimum(data):
    """ExactGP.fit's search in two stages (starts on 100 of the 250 points, each distinct
    optimum climbed on all 250) against the one stage on all of them (250 is under the default
    two-stage size, so the default is one stage): the same optimum of every point's likelihood."""
    x, y, _ = data
    one = ExactGP.fit(x, y, restarts=2, seed=1)
    assert one.hyperparameter_fit.refined_from is None and one.hyperparameter_fit.points_used == 250
    two = ExactGP.fit(x, y, restarts=2, seed=1, search_points=100)
    fit = two.hyperparameter_fit
    assert fit.points_used == 250 and fit.refined_from.points_used == 100
    assert len(fit.start_values) >= 1
    assert fit.log_marginal_likelihood == pytest.approx(two.log_marginal_likelihood(), rel=1e-9)
    assert two.log_marginal_likelihood() == pytest.approx(one.log_marginal_likelihood(), rel=1e-6)
    for name in ("sigma_f", "length_scale", "sigma_n"):
        assert getattr(two.kernel, name) == pytest.approx(getattr(one.kernel, name), rel=1e-3)


def test_restarts_stop_once_a_start_ends_at_an_earlier_optimum(data):
    """The stop at a repeated optimum against the full search with the same seed: the starts it
    makes are the full search's first ones, to the same values; the last of them repeats an
    earlier one's log marginal likelihood (to 1e-6) and none before it does; the optimum is the
    full search's, for fewer likelihood evaluations. Its control: starts cut to one L-BFGS
    iteration end at different points, so every restart is made."""
    x, y, _ = data
    full = fit_hyperparameters(x, y, restarts=6, seed=3, stop_at_repeat=False)
    stopped = fit_hyperparameters(x, y, restarts=6, seed=3)
    made = len(stopped.start_values)
    assert len(full.start_values) == 8  # the data's start, the scan's best, 6 random
    assert 2 <= made < 8
    np.testing.assert_allclose(stopped.start_values, full.start_values[:made], rtol=1e-12)

    def same(a, b):
        return abs(a - b) <= 1e-6 * max(abs(b), 1.0)

    values = stopped.start_values
    assert any(same(values[-1], v) for v in values[:-1])
    assert not any(same(values[i], v) for i in range(1, made - 1) for v in values[:i])
    assert stopped.log_marginal_likelihood == pytest.approx(full.log_marginal_likelihood, rel=1e-8)
    assert stopped.evaluations < full.evaluations
    short = fit_hyperparameters(x, y, restarts=6, seed=3, max_iterations=1)
    assert len(short.start_values) == 8


@pytest.mark.parametrize(
    ("x", "y", "message"),
    [
        (np.zeros((2, 3)) + [[0, 0, 0], [1, 1, 1]], np.zeros(2), "at least 4 are needed"),
        (np.ones((10, 2)), np.zeros(10), "identical"),
        (np.arange(20.0).reshape(10, 2), np.zeros(9), "10 points but Y has 9 rows"),
        (np.arange(20.0).reshape(10, 2), np.r_[np.zeros(9), np.nan], "target row 9 is NaN"),
        (np.r_[np.arange(18.0), np.nan, 1].reshape(10, 2), np.zeros(10), "input point 9 is NaN"),
        ([["a", "b"]], [1.0], "X: expected real numbers, got dtype <U1"),
    ],
)
def test_bad_input_is_refused(x, y, message):
    with pytest.raises(ValueError, match=message):
        ExactGP.fit(x, y, SquaredExponential(1.0, 0.5, 0.1))


def test_bad_kernels_and_options_are_refused(data):
    x, y, _ = data
    length = r"^SquaredExponential: length_scale must be a finite number in \(1e-50, 1e\+50\], got "
    with pytest.raises(ValueError, match=length + "0.0$"):
        SquaredExponential(1.0, 0.0, 0.1)
    # beyond, the algebra overflowed: NaN means and variances, or an OverflowError
    for bad, name in (((1e300, 0.5, 0.1), "sigma_f"), ((1.0, 0.5, 1e51), "sigma_n")):
        with pytest.raises(ValueError, match=rf"{name} must be a finite number in \(0, 1e\+50\]"):
            SquaredExponential(*bad)
    with pytest.raises(ValueError, match=length + "1e-300$"):
        SquaredExponential(1.0, 1e-300, 0.1)
    with pytest.raises(
        ValueError,
        match=r"^CurlFreeKernel: sigma_f must be a finite number in \(0, 1e\+50\], got 1e\+300$",
    ):
        CurlFreeKernel(1e300, 0.5, 40.0, 0.1)
    mean, var = ExactGP.fit(x, y, SquaredExponential(1e50, 0.5, 0.1)).predict(x)
    assert np.isfinite(mean).all() and np.isfinite(var).all()
    with pytest.raises(ValueError, match="mean must be one of"):
        ExactGP.fit(x, y, SquaredExponential(1.0, 0.5, 0.1), mean="linear")
    with pytest.raises(ValueError, match="points have 3 coordinates"):
        ExactGP.fit(x, y, SquaredExponential(1.0, 0.5, 0.1)).predict(np.zeros((2, 3)))
    with pytest.raises(
        ValueError, match=r"^tolerance must be a finite number in \(0, 1\), got 1\.0$"
    ):
        HilbertGP.fit(x, y, SquaredExponential(1.0, 0.5, 0.1), tolerance=1.0)
    with pytest.raises(ValueError, match="outside the domain"):
        HilbertGP.fit(x, y, SquaredExponential(1.0, 0.5, 0.1), domain=([0.5, 0.5], [2.0, 2.0]))
    with pytest.raises(ValueError, match="stop_at_repeat must be True or False"):
        fit_hyperparameters(x, y, stop_at_repeat=1)
    for bad in (1, 2.5, True):
        with pytest.raises(ValueError, match="search_points must be an integer >= 2"):
            fit_hyperparameters(x, y, search_points=bad)
    with pytest.raises(ValueError, match="more than 10 basis functions"):
        HilbertGP.fit(x, y, SquaredExponential(1.0, 0.1, 0.1), max_basis=10)
