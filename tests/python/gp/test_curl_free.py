# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The curl-free field GP (kiseki.gp.curl_free, curl_free_basis) against references that do not
use its code: finite differences of the potential's kernel, scipy's Gaussian density, fields
made as finite-difference gradients of potentials drawn from the prior, and the exact GP as the
brute force behind the reduced-rank one."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.stats

from kiseki.gp import (
    CurlFreeGP,
    CurlFreeKernel,
    ExactGP,
    ReducedRankCurlFreeGP,
    SquaredExponential,
)
from kiseki.gp.curl_free import (
    curl_free_log_marginal_likelihood,
    field_inputs,
    fit_curl_free_hyperparameters,
)
from kiseki.gp.curl_free_basis import laplacian_basis

KERNEL = CurlFreeKernel(sigma_f=1.3, length_scale=0.7, sigma_lin=2.0, sigma_n=0.1)


def potential_kernel(a: np.ndarray, b: np.ndarray, k: CurlFreeKernel) -> np.ndarray:
    """The potential's covariance sigma_f^2 exp(-|a-b|^2 / (2 l^2)) + sigma_lin^2 a^T b."""
    d2 = ((a[:, None, :] - b[None, :, :]) ** 2).sum(axis=2)
    return k.sigma_f**2 * np.exp(-0.5 * d2 / k.length_scale**2) + k.sigma_lin**2 * a @ b.T


@pytest.mark.parametrize("dimension", [2, 3])
def test_kernel_is_the_mixed_second_derivative_of_the_potentials_kernel(dimension) -> None:
    rng = np.random.default_rng(1)
    a = rng.uniform(-1, 1, (4, dimension))
    b = rng.uniform(-1, 1, (5, dimension))
    analytic = KERNEL.covariance(a, b)
    a3, b3 = field_inputs(a), field_inputs(b)  # the potential read at z = 0 when 2-D
    h = 1e-3 * KERNEL.length_scale
    numeric = np.zeros_like(analytic)
    for i in range(3):
        for j in range(3):
            ei, ej = h * np.eye(3)[i], h * np.eye(3)[j]
            # d^2 k / dx_i dx'_j by central differences (cov of -d/dx_i phi and -d/dx'_j phi)
            mixed = (
                potential_kernel(a3 + ei, b3 + ej, KERNEL)
                - potential_kernel(a3 + ei, b3 - ej, KERNEL)
                - potential_kernel(a3 - ei, b3 + ej, KERNEL)
                + potential_kernel(a3 - ei, b3 - ej, KERNEL)
            ) / (4 * h * h)
            numeric[i::3, j::3] = mixed
    # truncation O(h^2 sigma_f^2 / l^4) ~ 3e-6, round-off eps * 10 / h^2 ~ 4e-9
    np.testing.assert_allclose(analytic, numeric, atol=2e-5)
    if dimension == 2:  # r_z = 0: z independent of x and y, variance sigma_f^2 / l^2
        assert np.all(analytic[2::3, 0::3] == 0) and np.all(analytic[0::3, 2::3] == 0)


def test_log_marginal_likelihood_is_scipys_density_and_its_gradient_the_derivative() -> None:
    rng = np.random.default_rng(2)
    x = rng.uniform(-1, 1, (12, 3))
    y = rng.normal(0, 1, (12, 3))
    value, gradient = curl_free_log_marginal_likelihood(x, y, KERNEL)
    cov = KERNEL.covariance(x, x) + KERNEL.sigma_n**2 * np.eye(36)
    assert value == pytest.approx(
        scipy.stats.multivariate_normal(np.zeros(36), cov).logpdf(y.reshape(-1)), rel=1e-10
    )
    theta = np.log([KERNEL.sigma_f, KERNEL.length_scale, KERNEL.sigma_lin, KERNEL.sigma_n])
    for p in range(4):
        step = np.eye(4)[p] * 1e-5
        up, _ = curl_free_log_marginal_likelihood(x, y, CurlFreeKernel(*np.exp(theta + step)))
        down, _ = curl_free_log_marginal_likelihood(x, y, CurlFreeKernel(*np.exp(theta - step)))
        assert gradient[p] == pytest.approx((up - down) / 2e-5, rel=1e-5, abs=1e-6)


def sampled_field(rng, centres: np.ndarray, k: CurlFreeKernel, h: float) -> np.ndarray:
    """A field made as the finite-difference gradient of a potential drawn from the SE prior
    (no linear term) at the 7-point stencil around each centre, plus a constant Earth field
    drawn from N(0, sigma_lin^2 I)."""
    offsets = np.vstack([np.zeros(3), h * np.eye(3), -h * np.eye(3)])
    stencil = (centres[:, None, :] + offsets[None]).reshape(-1, 3)
    se = CurlFreeKernel(k.sigma_f, k.length_scale, 1e-300, k.sigma_n)
    cov = potential_kernel(stencil, stencil, se)
    w, v = np.linalg.eigh(cov)
    phi = (v * np.sqrt(np.clip(w, 0, None))) @ rng.standard_normal(len(w))
    phi = phi.reshape(len(centres), 7)
    gradient = (phi[:, 1:4] - phi[:, 4:7]) / (2 * h)  # O(h^2 sigma_f / l^3) off
    return -gradient + rng.normal(0, k.sigma_lin, 3)


def test_exact_gp_reconstructs_a_sampled_potentials_gradient_within_its_variance() -> None:
    rng = np.random.default_rng(3)
    k = CurlFreeKernel(sigma_f=0.5, length_scale=0.5, sigma_lin=3.0, sigma_n=0.05)
    centres = np.column_stack([rng.uniform(-1, 1, (260, 2)), rng.uniform(-0.2, 0.2, 260)])
    field = sampled_field(rng, centres, k, h=1e-3 * k.length_scale)
    train, test = slice(0, 200), slice(200, 260)
    noisy = field[train] + rng.normal(0, k.sigma_n, (200, 3))
    gp = CurlFreeGP.fit(centres[train], noisy, k)
    mean, var = gp.predict(centres[test])
    z = (field[test] - mean) / np.sqrt(var)
    # the posterior is the truth's distribution: E z^2 = 1; 180 correlated values, and any
    # single |z| > 4.5 has probability ~180 * 7e-6 (the finite differences are 1e-6 off)
    assert 0.4 < float(np.mean(z**2)) < 1.8
    assert np.abs(z).max() < 4.5
    # and it is a map: far better than the anomaly's prior SD sigma_f / l = 1
    assert np.sqrt(np.mean((field[test] - mean) ** 2)) < 0.25 * k.anomaly_sd


def curl_and_scale(predict, p: np.ndarray, h: float = 1e-4) -> tuple[float, float]:
    """(largest |curl| of the mean by central differences, largest |d f_i / d x_j|)."""
    jac = np.zeros((len(p), 3, 3))  # jac[:, i, j] = d f_i / d x_j
    for j in range(3):
        e = h * np.eye(3)[j]
        jac[:, :, j] = (predict(p + e) - predict(p - e)) / (2 * h)
    curl = np.stack(
        [jac[:, 2, 1] - jac[:, 1, 2], jac[:, 0, 2] - jac[:, 2, 0], jac[:, 1, 0] - jac[:, 0, 1]],
        axis=1,
    )
    return float(np.abs(curl).max()), float(np.abs(jac).max())


@pytest.mark.parametrize("reduced", [False, True])
def test_the_predicted_mean_has_no_curl(reduced) -> None:
    rng = np.random.default_rng(4)
    x = rng.uniform(-1, 1, (80, 3))
    y = rng.normal(0, 1, (80, 3))  # any readings: the mean is a gradient field whatever y is
    gp = (
        ReducedRankCurlFreeGP.fit(x, y, KERNEL, basis=200)
        if reduced
        else CurlFreeGP.fit(x, y, KERNEL)
    )
    p = rng.uniform(-0.5, 0.5, (20, 3))
    curl, scale = curl_and_scale(lambda q: gp.predict(q, variance=False)[0], p)
    assert scale > 0.1  # the field does vary
    # central differences at h = 1e-4: O(h^2 |f| / l^2) ~ 1e-7 relative, round-off ~ 1e-11
    assert curl < 1e-5 * scale
    # the check can fail: independent GPs per component on the same readings have curl
    independent = ExactGP.fit(x, y, SquaredExponential(KERNEL.anomaly_sd, 0.7, 0.1))
    curl, scale = curl_and_scale(lambda q: independent.predict(q)[0], p)
    assert curl > 0.1 * scale


@pytest.mark.parametrize("dimension", [2, 3])
def test_reduced_rank_approaches_the_exact_gp_as_the_basis_grows(dimension) -> None:
    rng = np.random.default_rng(5)
    k = CurlFreeKernel(sigma_f=0.6, length_scale=0.6, sigma_lin=3.0, sigma_n=0.1)
    n = 150 if dimension == 2 else 120
    x = rng.uniform(-1, 1, (n, dimension))
    y = rng.normal(0, 1, (n, 3)) + [2.0, -1.0, 0.5]
    exact_mean, exact_var = CurlFreeGP.fit(x, y, k).predict(x[:40] * 0.9)
    domain = (np.full(dimension, -2.5), np.full(dimension, 2.5))  # 2.5 l beyond the data
    errors = []
    counts = [16, 64, 256] if dimension == 2 else [64, 343, 2000]
    for count in counts:
        gp = ReducedRankCurlFreeGP.fit(x, y, k, basis=count, domain=domain)
        mean, var = gp.predict(x[:40] * 0.9)
        errors.append(np.abs(mean - exact_mean).max())
    assert errors[0] > errors[1] > errors[2]
    assert errors[-1] < 2e-3 * np.std(exact_mean)
    np.testing.assert_allclose(var, exact_var, atol=1e-3 * k.anomaly_sd**2)
    # the brute force behind it: Phi Lambda Phi^T against the exact covariance
    phi = gp.design(x[:30])
    approx = (phi * gp.prior_variances()) @ phi.T
    np.testing.assert_allclose(approx, k.covariance(x[:30], x[:30]), atol=1e-3 * k.anomaly_sd**2)


def test_laplacian_basis_takes_the_smallest_eigenvalues() -> None:
    half = np.array([2.0, 1.0])
    j = laplacian_basis(half, 10)
    lam = (((math.pi / 2) * j / half) ** 2).sum(axis=1)
    brute = sorted(
        ((math.pi / 2) * a / 2) ** 2 + ((math.pi / 2) * b) ** 2
        for a in range(1, 40)
        for b in range(1, 40)
    )
    np.testing.assert_allclose(lam, brute[:10])


def test_laplacian_basis_bounds_what_it_is_asked_for() -> None:
    """basis=10**7 ran for minutes building its candidates (and a factor of 800 TB)."""
    with pytest.raises(ValueError, match="count must be an integer in 1..10,000, got 10000000"):
        laplacian_basis([2.0, 1.0], 10**7)
    with pytest.raises(ValueError, match="sides too unequal"):
        laplacian_basis([1e9, 1e-9], 100)
    assert len(laplacian_basis([2.0, 1.0], 10_000)) == 10_000


def test_hyperparameters_reach_at_least_the_truths_likelihood() -> None:
    rng = np.random.default_rng(6)
    k = CurlFreeKernel(sigma_f=0.4, length_scale=0.4, sigma_lin=5.0, sigma_n=0.1)
    x = np.column_stack([rng.uniform(-1.5, 1.5, (150, 2)), np.zeros(150)])
    y = sampled_field(rng, x, k, h=1e-3 * k.length_scale) + rng.normal(0, k.sigma_n, (150, 3))
    fit = fit_curl_free_hyperparameters(x[:, :2], y)
    truth, _ = curl_free_log_marginal_likelihood(x[:, :2], y, k, gradient=False)
    assert fit.log_marginal_likelihood >= truth - 1e-6
    assert 0.5 < fit.kernel.length_scale / k.length_scale < 2.0
    assert 0.5 < fit.kernel.sigma_n / k.sigma_n < 2.0


@pytest.mark.parametrize(
    ("call", "needle"),
    [
        (lambda: CurlFreeKernel(1.0, 0.0, 1.0, 1.0), "length_scale"),
        (lambda: CurlFreeKernel(1.0, 1.0, math.nan, 1.0), "sigma_lin"),
        (lambda: CurlFreeKernel.from_dict({"sigma_f": 1.0}), "exactly"),
        (lambda: CurlFreeGP.fit(np.zeros((3, 4)), np.zeros((3, 3)), KERNEL), "2 or 3"),
        (lambda: CurlFreeGP.fit(np.zeros((3, 2)), np.zeros((3, 2)), KERNEL), "3 components"),
        (lambda: CurlFreeGP.fit(np.zeros((3, 2)), np.zeros((4, 3)), KERNEL), "3 points"),
        (lambda: CurlFreeGP.fit([[0, math.inf]], [[1, 2, 3]], KERNEL), "NaN or infinite"),
        (lambda: CurlFreeGP.fit(np.zeros((3, 2)), np.zeros((3, 3)), "k"), "CurlFreeKernel"),
        (
            lambda: fit_curl_free_hyperparameters(np.zeros((3, 2)), np.zeros((3, 3)), max_points=1),
            "max_points",
        ),
        (
            lambda: ReducedRankCurlFreeGP.fit(np.zeros((3, 2)), np.zeros((3, 3)), KERNEL, basis=0),
            "count",
        ),
        (
            lambda: ReducedRankCurlFreeGP.fit(
                np.ones((3, 2)), np.zeros((3, 3)), KERNEL, domain=([0, 0], [0.5, 0.5])
            ),
            "hold every",
        ),
        (  # True was a margin of one length scale
            lambda: ReducedRankCurlFreeGP.fit(
                np.zeros((3, 2)), np.zeros((3, 3)), KERNEL, margin=True
            ),
            r"^margin must be a finite number >= 0, got True$",
        ),
        (
            lambda: ReducedRankCurlFreeGP.fit(
                np.zeros((3, 2)), np.zeros((3, 3)), KERNEL, margin=-1
            ),
            r"^margin must be a finite number >= 0, got -1$",
        ),
        (
            lambda: CurlFreeGP.fit(np.zeros((3, 2)), np.zeros((3, 3)), KERNEL).predict(
                np.zeros((2, 2)), block=0
            ),
            "block",
        ),
        (
            lambda: CurlFreeGP.fit(np.zeros((3, 2)), np.zeros((3, 3)), KERNEL).predict(
                np.zeros((2, 3))
            ),
            "2 coordinates",
        ),
    ],
)
def test_bad_inputs_are_named(call, needle) -> None:
    with pytest.raises(ValueError, match=needle):
        call()
