# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The intervals of the rubble experiments' tables, computed as the claims' own are
(kiseki_experiments.harness.verdict.estimate): a percentile bootstrap of the median error over
seeds (none below the harness' MIN_TRIALS values) and the Wilson interval of a share."""

from __future__ import annotations

import numpy as np

from kiseki_experiments.harness.verdict import Evidence, estimate

__all__ = ["median_interval", "share_interval"]


def median_interval(values, seed: int = 0) -> tuple[float, float]:
    """The 95 % percentile-bootstrap interval of the median of ``values`` (NaN ends when there
    are too few values for one)."""
    v = np.asarray(values, dtype=float)
    if v.ndim != 1 or len(v) == 0 or not np.isfinite(v).all():
        raise ValueError("interval: expected a non-empty 1-D array of finite values")
    est = estimate(Evidence.of("median", v, "median"), seed)
    return est.low, est.high


def share_interval(flags) -> tuple[float, float, float]:
    """(share, Wilson 95 % low, high) of the true values in ``flags``."""
    f = np.asarray(flags, dtype=bool)
    est = estimate(Evidence.share("share", int(f.sum()), int(f.size)), 0)
    return est.value, est.low, est.high
