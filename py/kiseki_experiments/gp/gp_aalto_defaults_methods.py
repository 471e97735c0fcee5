# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The map methods gp-aalto-defaults compares (:mod:`kiseki_experiments.gp.gp_aalto_defaults`),
each fitted on the training runs' readings and predicting positions of the held-out run:

* ``sklearn``: scikit-learn's GaussianProcessRegressor(ConstantKernel() * RBF() +
  WhiteKernel()), one per component, its default optimiser and normalize_y=False, on every
  ``baseline_step``-th reading; each component's training mean is subtracted before the fit
  and added back to the prediction (the kernel has no mean, and the field's is about 40 uT);
* ``exact-bin-shared`` / ``exact-bin-per-component``: kiseki's ExactGP on the readings averaged
  per ``bin_size`` square (kiseki.magnetic.binning), one kernel for the three components or one
  each;
* ``hilbert-<tolerance>``: kiseki's HilbertGP on every reading, per-component hyperparameters
  from fit_hyperparameters on the baseline's readings (every ``baseline_step``-th), the basis
  set by the spectral tolerance;
* ``curl-free-exact-bin``: the curl-free GP (kiseki.gp.CurlFreeGP) on the binned readings;
* ``curl-free-rr-<m>``: the reduced-rank curl-free GP on every reading with m eigenfunctions,
  its hyperparameters fitted on the baseline's readings.

Each method returns the predicted mean (n, 3) and its fit time (hyperparameters and
factorisation, s; prediction excluded).
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np

from kiseki.gp import (
    CurlFreeGP,
    CurlFreeKernel,
    ExactGP,
    HilbertGP,
    ReducedRankCurlFreeGP,
    fit_curl_free_hyperparameters,
    fit_hyperparameters,
)
from kiseki.magnetic.binning import bin_readings

__all__ = ["BASELINE", "Prediction", "method_names", "run_method", "sklearn_baseline"]

BASELINE = "sklearn"
Prediction = tuple[np.ndarray, float]


def sklearn_baseline(
    x: np.ndarray, y: np.ndarray, points: np.ndarray
) -> tuple[np.ndarray, list[dict[str, float]]]:
    """The baseline's prediction (module text) at points from the readings (x, y) given, and
    per component the hyperparameters its optimiser found (constant, length scale, noise
    variance)."""
    # imported here: scikit-learn takes about a second to import and only this method needs it
    from sklearn.gaussian_process import GaussianProcessRegressor
    from sklearn.gaussian_process.kernels import RBF, ConstantKernel, WhiteKernel

    out, found = np.empty((len(points), y.shape[1])), []
    for c in range(y.shape[1]):
        mean = y[:, c].mean()
        gpr = GaussianProcessRegressor(ConstantKernel() * RBF() + WhiteKernel(), normalize_y=False)
        gpr.fit(x, y[:, c] - mean)
        out[:, c] = gpr.predict(points) + mean
        k = gpr.kernel_
        found.append(
            {
                "constant": float(k.k1.k1.constant_value),
                "length_scale": float(k.k1.k2.length_scale),
                "noise_level": float(k.k2.noise_level),
            }
        )
    return out, found


def method_names(config) -> list[str]:
    """The methods of a config, the baseline first."""
    names = [BASELINE, "exact-bin-shared", "exact-bin-per-component"]
    names += [f"hilbert-{t:g}" for t in config.hilbert_tolerances]
    names += ["curl-free-exact-bin"] + [f"curl-free-rr-{m}" for m in config.curl_free_basis]
    return names


def _lagged(config, y: np.ndarray) -> np.ndarray:
    """The negative control's readings: each position paired with the reading taken
    ``lag_readings`` samples later along the recorded track (circularly), kiseki's methods only:
    a smooth, confident map of the field somewhere else."""
    return np.roll(y, -config.lag_readings, axis=0) if config.lag_readings else y


def _scaled(config, kernel: CurlFreeKernel) -> CurlFreeKernel:
    """The curl-free control: the fitted length scale times ``curl_free_length_factor`` (the
    anomaly's SD sigma_f / l kept)."""
    f = config.curl_free_length_factor
    if f == 1.0:
        return kernel
    return CurlFreeKernel(
        kernel.sigma_f * f, kernel.length_scale * f, kernel.sigma_lin, kernel.sigma_n
    )


def run_method(
    name: str, config, x: np.ndarray, y: np.ndarray, points: np.ndarray, cache: dict
) -> Prediction:
    """(mean at points, fit seconds) of method `name` trained on all readings (x, y) of the
    training runs, in the order recorded. Hyperparameters fitted for one method are kept in
    `cache` for the others of its family (the Hilbert GP's tolerances, the reduced-rank
    basis sizes); their fit time is added to each method's. The curl-free kernels used are
    left in `cache` as "kernel:<method>" (a dict each)."""
    start = time.perf_counter()
    step = config.baseline_step
    if name == BASELINE:
        mean, found = sklearn_baseline(x[::step], y[::step], points)
        cache[BASELINE] = found
        return mean, time.perf_counter() - start
    y = _lagged(config, y)
    predict, hyper_seconds = _method(name, config, x, y, step, cache)
    seconds = time.perf_counter() - start + hyper_seconds
    return predict(points), seconds


def _method(name: str, config, x, y, step, cache: dict) -> tuple[Callable, float]:
    """(the mean predictor of the fitted model, seconds of cached hyperparameter fits)."""
    hyper = {"max_points": config.max_points, "restarts": config.restarts, "seed": config.gp_seed}
    cf = {"max_points": config.curl_free_max_points, "seed": config.gp_seed}
    if name.startswith("exact-bin"):
        xb, yb, _ = bin_readings(x, y, config.bin_size)
        gp = ExactGP.fit(xb, yb, per_component=name.endswith("per-component"), **hyper)
        return (lambda p: gp.predict(p)[0]), 0.0
    if name.startswith("hilbert-"):
        tolerance = float(name.removeprefix("hilbert-"))
        kernels, seconds = _timed(
            cache,
            "hilbert",
            lambda: [
                fit_hyperparameters(x[::step], y[::step, [c]], **hyper).kernel for c in range(3)
            ],
        )
        gps = [HilbertGP.fit(x, y[:, [c]], k, tolerance=tolerance) for c, k in enumerate(kernels)]
        return (lambda p: np.hstack([g.predict(p)[0] for g in gps])), seconds
    if name == "curl-free-exact-bin":
        xb, yb, _ = bin_readings(x, y, config.bin_size)
        kernel = _scaled(config, fit_curl_free_hyperparameters(xb, yb, **cf).kernel)
        gp = CurlFreeGP.fit(xb, yb, kernel)
        cache[f"kernel:{name}"] = kernel.to_dict()
        return (lambda p: gp.predict(p, variance=False)[0]), 0.0
    if name.startswith("curl-free-rr-"):
        basis = int(name.removeprefix("curl-free-rr-"))
        fit, seconds = _timed(
            cache, "curl-free-rr", lambda: fit_curl_free_hyperparameters(x[::step], y[::step], **cf)
        )
        gp = ReducedRankCurlFreeGP.fit(x, y, _scaled(config, fit.kernel), basis=basis)
        cache["kernel:curl-free-rr"] = gp.kernel.to_dict()
        return (lambda p: gp.predict(p, variance=False)[0]), seconds
    raise ValueError(f"gp-aalto-defaults: unknown method {name!r}")


def _timed(cache: dict, key: str, compute: Callable) -> tuple[object, float]:
    """(cache[key], 0 s) the first time, computed now (the caller's clock counts it); later
    (the value, the seconds its computation took), for the caller to add."""
    if key in cache:
        return cache[key]
    start = time.perf_counter()
    value = compute()
    cache[key] = (value, time.perf_counter() - start)
    return value, 0.0
