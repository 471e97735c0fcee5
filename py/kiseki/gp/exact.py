# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Exact Gaussian-process regression (thesis chapter 6, eqs. 6.7-6.9)."""

from __future__ import annotations

from typing import Any

import numpy as np

from kiseki import _core
from kiseki._support.real_numbers import check_number
from kiseki.gp._data import check_mean, inputs_array, targets_array
from kiseki.gp.kernel import (
    HyperparameterFit,
    SquaredExponential,
    fit_hyperparameters,
    refine_hyperparameters,
)

__all__ = ["ExactGP"]


class ExactGP:
    """A fitted exact GP: every column of the targets (mx, my, mz) a GP with one shared kernel,
    so one Cholesky factorisation of K + sigma_n^2 I serves all of them.

    Build with :meth:`fit`. ``predict`` gives the mean (eq. 6.8) and the variance of the
    noise-free field (eq. 6.9); add ``kernel.sigma_n ** 2`` for the variance of a new reading.
    Prediction uses, for each block of nearby points, only the training points whose kernel
    value exceeds 1e-13 sigma_f^2 (exactly all of them up to 2,000 training points)."""

    def __init__(
        self, cores: list[Any], kernels: list[SquaredExponential], mean: str, fits: list
    ) -> None:
        self._cores = cores
        self.kernels = tuple(kernels)  # one shared by every column, or one per column
        self.kernel = kernels[0]
        self.mean = mean
        self.hyperparameter_fits: tuple[HyperparameterFit | None, ...] = tuple(fits)

    @classmethod
    def fit(
        cls,
        x: Any,
        y: Any,
        kernel: SquaredExponential | None = None,
        *,
        mean: str = "constant",
        restarts: int = 3,
        seed: int = 0,
        max_points: int = 2000,
        per_component: bool = False,
        refine: bool = False,
        search_points: int | None = None,
    ) -> ExactGP:
        """Fits to readings y (n,) or (n, k) at positions x (n, d). Without a kernel the
        hyperparameters are chosen by :func:`fit_hyperparameters` (restarts, seed, max_points,
        search_points as there). mean: "constant" (the training mean of each column) or "zero" (as
        scikit-learn's GaussianProcessRegressor with normalize_y=False). per_component: one
        kernel per column, as the thesis fits mx, my and mz (three factorisations). refine: with
        more readings than max_points, the subsample's hyperparameters are then refined on every
        reading (:func:`refine_hyperparameters`), so that they maximise eq. 6.11 on all of them."""
        x = inputs_array(x)
        y, _ = targets_array(y, x.shape[0])
        constant = check_mean(mean)
        if kernel is not None and not isinstance(kernel, SquaredExponential):
            raise ValueError(f"kernel must be a SquaredExponential, got {type(kernel).__name__}")
        columns = [y[:, [c]] for c in range(y.shape[1])] if per_component else [y]
        cores, kernels, fits = [], [], []
        for part in columns:
            hyper = None
            k = kernel
            if k is None:
                hyper = fit_hyperparameters(
                    x,
                    part,
                    restarts=restarts,
                    seed=seed,
                    max_points=max_points,
                    mean=mean,
                    search_points=search_points,
                )
                if refine and hyper.points_used < len(x):
                    hyper = refine_hyperparameters(x, part, hyper, mean=mean)
                k = hyper.kernel
            cores.append(
                _core.ExactGaussianProcess(x, part, k.sigma_f, k.length_scale, k.sigma_n, constant)
            )
            kernels.append(k)
            fits.append(hyper)
        return cls(cores, kernels, mean, fits)

    @property
    def hyperparameter_fit(self) -> HyperparameterFit | None:
        return self.hyperparameter_fits[0]

    def predict(self, points: Any, *, truncation: float = 1e-13) -> tuple[np.ndarray, np.ndarray]:
        """(mean (m, k), variance (m, k)) at points (m, d); the variance is the same for every
        column (one kernel) and is that of the noise-free field."""
        p = inputs_array(points, "points")
        if p.shape[1] != self.dimension:
            raise ValueError(
                f"points have {p.shape[1]} coordinates, the GP was fitted on {self.dimension}"
            )
        # "a" was pybind11's signature list
        truncation = check_number(truncation, "predict: truncation", 0.0, 1.0, high_open=True)
        means, variances = [], []
        for core in self._cores:
            m, v = core.predict(p, truncation)
            means.append(m)
            variances.append(np.repeat(v[:, None], m.shape[1], axis=1))
        return np.hstack(means), np.hstack(variances)

    def log_marginal_likelihood(self) -> float:
        """Eq. 6.11 summed over the target columns, on every training point."""
        return float(sum(core.log_marginal_likelihood for core in self._cores))

    @property
    def dimension(self) -> int:
        return int(self._cores[0].dimension)

    @property
    def outputs(self) -> int:
        return int(sum(core.outputs for core in self._cores))

    @property
    def size(self) -> int:
        return int(self._cores[0].size)

    @property
    def prior_mean(self) -> np.ndarray:
        return np.concatenate([np.asarray(core.prior_mean) for core in self._cores])

    @property
    def prior_variance(self) -> np.ndarray:
        """sigma_f^2 per column."""
        per_core = [
            np.full(core.outputs, k.sigma_f**2)
            for core, k in zip(self._cores, self.kernels, strict=True)
        ]
        return np.concatenate(per_core)
