# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""refine_hyperparameters carries a subsample's optimum to the optimum of eq. 6.11 on every
reading: the one scikit-learn's L-BFGS-B (scipy) reaches from the same start, in a handful of
evaluations and without the scan."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.optimize

from kiseki.gp import ExactGP, SquaredExponential, fit_hyperparameters, refine_hyperparameters
from kiseki.gp.kernel import log_marginal_likelihood


@pytest.fixture(scope="module")
def survey():
    """600 readings of a smooth 2-D field with 0.05 noise."""
    rng = np.random.default_rng(3)
    x = rng.uniform(0.0, 4.0, (600, 2))
    y = np.c_[np.sin(1.7 * x[:, 0]) * np.cos(0.9 * x[:, 1]), np.cos(1.2 * x[:, 0] + x[:, 1])]
    return x, y + rng.normal(0.0, 0.05, y.shape)


def test_refinement_reaches_scipys_optimum_on_every_reading(survey):
    x, y = survey
    start = fit_hyperparameters(x, y, max_points=120, seed=0)
    assert start.points_used == 120
    refined = refine_hyperparameters(x, y, start)
    assert refined.points_used == 600 and refined.refined_from is start
    assert refined.evaluations < 40 and len(refined.start_values) == 1  # no scan, no restarts

    def negative(p):  # scipy's L-BFGS-B on eq. 6.11 of every reading, from the same start
        value, gradient = log_marginal_likelihood(x, y, SquaredExponential(*np.exp(p)))
        return -value, -gradient

    k = start.kernel
    ref = scipy.optimize.minimize(
        negative, np.log([k.sigma_f, k.length_scale, k.sigma_n]), jac=True, method="L-BFGS-B"
    )
    assert refined.log_marginal_likelihood == pytest.approx(-ref.fun, rel=1e-7)
    np.testing.assert_allclose(
        [refined.kernel.sigma_f, refined.kernel.length_scale, refined.kernel.sigma_n],
        np.exp(ref.x),
        rtol=2e-3,
    )
    # and it is an improvement on every reading over the subsample's optimum
    at_start, _ = log_marginal_likelihood(x, y, k)
    assert refined.log_marginal_likelihood > at_start + 0.1


def test_exact_gp_refines_only_when_asked_and_only_beyond_max_points(survey):
    x, y = survey
    plain = ExactGP.fit(x, y, max_points=120)
    refined = ExactGP.fit(x, y, max_points=120, refine=True)
    assert plain.hyperparameter_fit.refined_from is None
    fit = refined.hyperparameter_fit
    assert fit.refined_from.kernel == plain.kernel  # from the subsample's optimum
    assert refined.kernel == refine_hyperparameters(x, y, plain.hyperparameter_fit).kernel
    assert refined.log_marginal_likelihood() == pytest.approx(fit.log_marginal_likelihood)
    small = ExactGP.fit(x[:100], y[:100], max_points=120, refine=True)
    assert small.hyperparameter_fit.refined_from is None  # every reading was fitted already
