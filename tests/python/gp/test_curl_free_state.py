# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The curl-free GPs' stored state (what a map folder keeps so that it predicts without a refit)
and the constant field's posterior (what a map returns outside its cells)."""

from __future__ import annotations

import numpy as np
import pytest

from kiseki.gp import CurlFreeGP, CurlFreeKernel, ReducedRankCurlFreeGP

KERNEL = CurlFreeKernel(2.0, 0.8, 30.0, 0.3)


def readings(d: int, n: int = 120, seed: int = 1):
    rng = np.random.default_rng(seed)
    x = rng.uniform(0, 4, (n, d))
    y = rng.normal(size=(n, 3)) + [20.0, -5.0, 40.0]
    return x, y, rng.uniform(0, 4, (25, d))


@pytest.mark.parametrize("d", [2, 3])
def test_the_exact_gp_from_its_state_predicts_as_the_fitted_one(d):
    x, y, at = readings(d)
    gp = CurlFreeGP.fit(x, y, KERNEL)
    again = CurlFreeGP.from_state(x, y, KERNEL, **gp.state())
    for a, b in zip(gp.predict(at), again.predict(at), strict=True):
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-10)


def test_a_factor_or_readings_that_do_not_belong_together_are_refused():
    x, y, _ = readings(2)
    factor = CurlFreeGP.fit(x, y, KERNEL).state()["factor"]
    damaged = factor.copy()
    damaged[300, 17] += 1e-3  # an entry of a checked row (rows spread over the 360)
    with pytest.raises(ValueError, match="not the Cholesky factor"):
        CurlFreeGP.from_state(x, y, KERNEL, damaged)
    with pytest.raises(ValueError, match="not the Cholesky factor"):  # other positions
        CurlFreeGP.from_state(x * 1.05, y, KERNEL, factor)  # (a shift: the same K)
    with pytest.raises(ValueError, match="does not fit 119 readings"):
        CurlFreeGP.from_state(x[1:], y[1:], KERNEL, factor)


@pytest.mark.parametrize("d", [2, 3])
def test_the_reduced_rank_gp_from_its_state_predicts_as_the_fitted_one(d):
    x, y, at = readings(d)
    gp = ReducedRankCurlFreeGP.fit(x, y, KERNEL, basis=128)
    again = ReducedRankCurlFreeGP.from_state(x, y, KERNEL, **gp.state())
    for a, b in zip(gp.predict(at), again.predict(at), strict=True):
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-10)
    state = gp.state()
    state["factor"] = state["factor"] * 1.01
    with pytest.raises(ValueError, match="do not fit these readings"):
        ReducedRankCurlFreeGP.from_state(x, y, KERNEL, **state)
    with pytest.raises(ValueError, match="do not fit these readings"):
        ReducedRankCurlFreeGP.from_state(x, y + 1.0, KERNEL, **gp.state())


def test_the_constant_field_is_the_exact_gps_prediction_far_from_every_reading():
    """Reference: the GP's own mean and variance 10^4 length scales away, where only the linear
    kernel's sigma_lin^2 couples the point to the readings (the anomaly's prior added)."""
    x, y, _ = readings(2)
    gp = CurlFreeGP.fit(x, y, KERNEL)
    mean, variance = gp.constant_field()
    far_mean, far_variance = gp.predict(np.array([[1e4, 1e4]]))
    np.testing.assert_allclose(mean, far_mean[0], rtol=1e-10)
    np.testing.assert_allclose(variance + KERNEL.anomaly_sd**2, far_variance[0], rtol=1e-9)


def test_the_reduced_rank_constant_field_approaches_the_exact_one():
    x, y, _ = readings(2)
    exact = CurlFreeGP.fit(x, y, KERNEL).constant_field()
    reduced = ReducedRankCurlFreeGP.fit(x, y, KERNEL, basis=1024).constant_field()
    np.testing.assert_allclose(reduced[0], exact[0], atol=0.05)
    np.testing.assert_allclose(reduced[1], exact[1], rtol=0.2)
