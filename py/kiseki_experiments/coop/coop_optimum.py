# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Where the error at the goal is smallest: the paper's own algebra (sec. 3.1, from eq. 4) and
the simulation's sweeps, the latter with a bootstrap interval over the runs of every setting
(the runs of each setting resampled, the argmin taken again; B. Efron, Ann. Statist. 7, 1979),
and the three-way verdict of such an interval against a range."""

from __future__ import annotations

import math

import numpy as np

from kiseki.coop import paper_error

__all__ = ["analytic_optimum", "argmin_interval", "range_verdict"]

RESAMPLES = 2000


def analytic_optimum(distance: float = 10.0, d: float = 1.0, dtheta: float = 1e-3):
    """The paper's sec. 3.1, from its eq. 4 (kiseki.coop.paper_error): each of n measurements
    places the moving robot on the centre line, d tan(theta) ahead of a baseline of half-width
    d, with theta1 = theta2 = theta and equal errors dtheta1 = dtheta2 (the along-track worst
    case); the along-track errors add up over the n steps, and n d tan(theta) = distance.
    Returns (n, theta in deg, the error) minimising that error over n = 1..200."""
    best = None
    for n in range(1, 201):
        theta = math.atan(distance / (n * d))
        error = n * abs(paper_error(d, theta, theta, dtheta, dtheta)[1])
        if best is None or error < best[2]:
            best = (n, math.degrees(theta), error)
    return best


def _statistic(runs: np.ndarray, kind: str) -> np.ndarray:
    """Per setting (rows of ``runs``): the mean of the errors or the RMS of signed errors."""
    return np.sqrt(np.mean(runs**2, axis=-1)) if kind == "rms" else np.mean(runs, axis=-1)


def argmin_interval(
    xs, runs, kind: str = "mean", resamples: int = RESAMPLES, seed: int = 0
) -> tuple[float, float, float]:
    """(x at the smallest statistic, 95 % low, high): ``xs`` the settings (moves or angles),
    ``runs`` a list of per-run errors per setting (equal counts), ``kind`` ``mean`` (of
    distances) or ``rms`` (of signed errors); the interval is the 2.5 and 97.5 % quantiles of
    the argmin over bootstrap resamples of every setting's runs."""
    x = np.asarray(xs, dtype=float)
    r = np.asarray([np.asarray(v, dtype=float) for v in runs])
    if r.ndim != 2 or len(x) != len(r) or len(x) == 0:
        raise ValueError("argmin_interval: one row of equally many runs per setting")
    best = float(x[int(np.argmin(_statistic(r, kind)))])
    rng = np.random.default_rng(seed)
    picks = np.empty(resamples)
    for b in range(resamples):
        pick = rng.integers(0, r.shape[1], r.shape)
        picks[b] = x[int(np.argmin(_statistic(np.take_along_axis(r, pick, axis=1), kind)))]
    return best, float(np.quantile(picks, 0.025)), float(np.quantile(picks, 0.975))


def range_verdict(low: float, high: float, lo: float, hi: float) -> str:
    """``holds`` when [low, high] lies within [lo, hi], ``fails`` when the two do not meet,
    else ``inconclusive``."""
    if lo <= low and high <= hi:
        return "holds"
    if high < lo or low > hi:
        return "fails"
    return "inconclusive"
