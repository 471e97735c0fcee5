# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""scikit-learn's GaussianProcessRegressor set up as kiseki's exact GP, the reference of
bench_gp.py: the kernel sigma_f^2 exp(-r^2 / 2 l^2) + sigma_n^2 as ConstantKernel * RBF +
WhiteKernel, kiseki's data-derived start and its bounds, sklearn's own L-BFGS-B counting the
likelihood evaluations, the training mean removed by hand (normalize_y stays False), and the
noise-free predictive SD (sklearn's includes the WhiteKernel's noise)."""

from __future__ import annotations

import multiprocessing
import time

import numpy as np
import scipy.optimize
from sklearn.gaussian_process import GaussianProcessRegressor
from sklearn.gaussian_process.kernels import RBF, WhiteKernel
from sklearn.gaussian_process.kernels import ConstantKernel as Constant

from kiseki import _core
from kiseki.gp import SquaredExponential


def start_kernel(x: np.ndarray, y: np.ndarray) -> SquaredExponential:
    """kiseki's own start (sigma_f the RMS of the centred targets, l a tenth of the extent,
    sigma_n a tenth of sigma_f): the start of both libraries."""
    return SquaredExponential(*_core.gp_initial_kernel(x, y - y.mean(axis=0)))


def sklearn_kernel(k0: SquaredExponential):
    """ConstantKernel * RBF + WhiteKernel at k0, within kiseki's bounds (sigma_f and sigma_n
    1e-6..1e3 times the RMS, l 1e-3..1e2 times the extent)."""
    s2, extent = k0.sigma_f**2, 10.0 * k0.length_scale
    return Constant(s2, (1e-12 * s2, 1e6 * s2)) * RBF(
        k0.length_scale, (1e-3 * extent, 1e2 * extent)
    ) + WhiteKernel(k0.sigma_n**2, (1e-12 * s2, 1e6 * s2))


class CountingLBFGSB:
    """sklearn's own "fmin_l_bfgs_b" (scipy's L-BFGS-B with the analytic gradient), counting
    the likelihood evaluations."""

    def __init__(self) -> None:
        self.evaluations = 0

    def __call__(self, objective, theta, bounds):
        r = scipy.optimize.minimize(objective, theta, method="L-BFGS-B", jac=True, bounds=bounds)
        self.evaluations += int(r.nfev)
        return r.x, r.fun


def run_sklearn(x, y, xs, restarts: int, per_component: bool) -> dict:
    """Fit at y (n, k) (one GP per column when per_component) and predict at xs: times, mean,
    noise-free SD, log marginal likelihood on every point, evaluations, kernels."""
    columns = [[c] for c in range(y.shape[1])] if per_component else [list(range(y.shape[1]))]
    start = time.perf_counter()
    models, counter = [], CountingLBFGSB()
    for cols in columns:
        part = y[:, cols]
        reg = GaussianProcessRegressor(
            sklearn_kernel(start_kernel(x, part)),
            optimizer=counter,
            n_restarts_optimizer=restarts,
            normalize_y=False,
            random_state=0,
        )
        models.append((reg.fit(x, part - part.mean(axis=0)), part.mean(axis=0)))
    fit_s = time.perf_counter() - start
    start = time.perf_counter()
    means, stds = [], []
    for reg, mu in models:
        m, s = reg.predict(xs, return_std=True)
        means.append(m.reshape(len(xs), -1) + mu)
        # sklearn's std includes the WhiteKernel's noise: remove it to compare with kiseki's
        # noise-free variance (eq. 6.9).
        s2 = s.reshape(len(xs), -1)[:, 0] ** 2 - reg.kernel_.k2.noise_level
        stds.append(np.sqrt(np.maximum(s2, 0.0)))
    return {
        "fit": fit_s,
        "predict": time.perf_counter() - start,
        "mean": np.hstack(means),
        "std": np.column_stack(stds),
        "lml": sum(reg.log_marginal_likelihood_value_ for reg, _ in models),
        "evaluations": counter.evaluations,
        "kernels": [str(reg.kernel_) for reg, _ in models],
    }


def _sklearn_child(conn, *args) -> None:
    conn.send(run_sklearn(*args))
    conn.close()


def run_sklearn_limited(x, y, xs, restarts, per_component, timeout: float) -> dict | None:
    """run_sklearn in a forked process, stopped after `timeout` s (None then)."""
    ctx = multiprocessing.get_context("fork")
    parent, child = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_sklearn_child, args=(child, x, y, xs, restarts, per_component))
    proc.start()
    child.close()
    out = parent.recv() if parent.poll(timeout) else None
    if out is None:
        proc.kill()
    proc.join()
    return out
