# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The intervals of the rubble experiments' tables (the claims' own come from the harness,
kiseki_experiments.harness.verdict): a percentile bootstrap of the median error over seeds
(B. Efron, Ann. Statist. 7, 1979) and the Wilson interval of a share
(kiseki.metrics.wilson_interval)."""

from __future__ import annotations

import numpy as np

from kiseki.metrics import wilson_interval

__all__ = ["RESAMPLES", "median_interval", "share_interval"]

RESAMPLES = 4000
"""Bootstrap resamples: the 2.5 and 97.5 % quantiles move by well under a cell (2 cm) between
bootstrap seeds at this count."""


def _values(values) -> np.ndarray:
    v = np.asarray(values, dtype=float)
    if v.ndim != 1 or len(v) == 0 or not np.isfinite(v).all():
        raise ValueError("interval: expected a non-empty 1-D array of finite values")
    return v


def median_interval(values, resamples: int = RESAMPLES, seed: int = 0) -> tuple[float, float]:
    """The 95 % percentile-bootstrap interval of the median of ``values``."""
    v = _values(values)
    pick = np.random.default_rng(seed).integers(0, len(v), (resamples, len(v)))
    medians = np.median(v[pick], axis=1)
    return float(np.quantile(medians, 0.025)), float(np.quantile(medians, 0.975))


def share_interval(flags) -> tuple[float, float, float]:
    """(share, Wilson 95 % low, high) of the true values in ``flags``."""
    f = np.asarray(flags, dtype=bool)
    k, n = int(f.sum()), int(f.size)
    lo, hi = wilson_interval(k, n)
    return (k / n if n else float("nan")), lo, hi
