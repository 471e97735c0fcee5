# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The squared-exponential kernel and its hyperparameters by maximum marginal likelihood."""

from __future__ import annotations

from dataclasses import asdict, dataclass, replace
from typing import Any

import numpy as np

from kiseki import _core
from kiseki._support.counts import check_count
from kiseki._support.real_numbers import check_number
from kiseki.core import check_seed
from kiseki.gp._data import (
    check_iterations,
    check_mean,
    inputs_array,
    remove_mean,
    targets_array,
)

# Hyperparameters beyond these overflow in the GP's algebra (sigma_f = 1e300 squared is inf, and
# a length scale of 1e-300 divides to inf: the predictions NaN); no field, length or noise is
# within 50 orders of magnitude of them. Tiny amplitudes (sigma_lin = 1e-300: no constant term)
# stay allowed.
KERNEL_LOW, KERNEL_HIGH = 1e-50, 1e50

__all__ = [
    "HyperparameterFit",
    "SquaredExponential",
    "fit_hyperparameters",
    "refine_hyperparameters",
]


def check_hyperparameters(kernel, names: tuple[str, ...]) -> None:
    """Each of the frozen dataclass ``kernel``'s hyperparameters ``names`` as a float in (0,
    KERNEL_HIGH] (a length scale above KERNEL_LOW), refused naming the kernel and the field.
    Compared as a Python float: a float32 would take the bounds as float32 (1e50: inf)."""
    for name in names:
        low = KERNEL_LOW if name == "length_scale" else 0.0
        label = f"{type(kernel).__name__}: {name}"
        value = check_number(getattr(kernel, name), label, low, KERNEL_HIGH, low_open=True)
        object.__setattr__(kernel, name, value)


@dataclass(frozen=True)
class SquaredExponential:
    """k(p, q) = sigma_f^2 exp(-|p - q|^2 / (2 l^2)) (thesis eq. 6.2), plus independent noise
    sigma_n^2 on every reading (eq. 6.3). Units: sigma_f and sigma_n those of the field, l those
    of the positions (m). The thesis' Table 6.1 found sigma_f 1.738, l 0.475 m, sigma_n 0.420."""

    sigma_f: float
    length_scale: float
    sigma_n: float

    def __post_init__(self) -> None:
        check_hyperparameters(self, ("sigma_f", "length_scale", "sigma_n"))

    def to_dict(self) -> dict[str, float]:
        return asdict(self)

    @classmethod
    def from_dict(cls, d: Any) -> SquaredExponential:
        if not isinstance(d, dict) or set(d) != {"sigma_f", "length_scale", "sigma_n"}:
            raise ValueError(f"a kernel needs exactly sigma_f, length_scale and sigma_n, got {d!r}")
        return cls(**d)


@dataclass(frozen=True)
class HyperparameterFit:
    """The outcome of :func:`fit_hyperparameters`."""

    kernel: SquaredExponential
    log_marginal_likelihood: float  # at the optimum, on the points used
    evaluations: int  # likelihood values (one Cholesky factorisation each)
    gradients: int  # of which also with the gradient (two more n^3 / 3 each)
    start_values: tuple[float, ...]  # the best likelihood reached from each start made
    points_used: int
    # a refinement's (refine_hyperparameters) or a two-stage fit's: the subsample's fit it
    # started from
    refined_from: HyperparameterFit | None = None


def subsample(n: int, max_points: int, seed: int) -> np.ndarray | None:
    """Indices of a seeded random subsample of max_points of n (None: use them all)."""
    max_points = check_count(max_points, "max_points", 2)
    if n <= max_points:
        return None
    rng = np.random.default_rng(check_seed(seed))
    return np.sort(rng.choice(n, size=max_points, replace=False))


# The starts are searched on a subsample of a quarter of the points used, at least this many:
# an evaluation costs n^3 / 3, so each of the search's costs 1/64 of one on every point, and
# the climbs on every point decide between the optima it found. Up to this many points the
# search is made on all of them (one stage); from 257 to 1,023 points it is made on 256.
SEARCH_POINTS_MIN = 256


def search_points_for(points: int) -> int:
    """The default subsample size of the start search for ``points`` readings used."""
    return max(points // 4, SEARCH_POINTS_MIN)


def fit_hyperparameters(
    x: Any,
    y: Any,
    *,
    initial: SquaredExponential | None = None,
    restarts: int = 3,
    seed: int = 0,
    max_points: int = 2000,
    max_iterations: int = 100,
    mean: str = "constant",
    stop_at_repeat: bool = True,
    search_points: int | None = None,
) -> HyperparameterFit:
    """Hyperparameters that maximise the log marginal likelihood (eq. 6.11) summed over Y's
    columns (one kernel shared by the field's components), by projected L-BFGS in
    log-parameters with the analytic gradient (eqs. 6.12-6.15), from `initial` (default: from
    the data's spread), from the best of a coarse scan of l and sigma_n, and from up to
    `restarts` seeded random starts: with `stop_at_repeat` they stop once a start ends at an
    optimum an earlier start reached (the same log marginal likelihood to 1e-6 of its size and
    every hyperparameter within 1 %). Above `max_points` readings the likelihood is that of a
    seeded random subsample of that size (its cost grows as n^3).

    Two stages when the points used outnumber `search_points` (default
    :func:`search_points_for`: a quarter of them, at least 256): the starts above are searched
    on a seeded subsample of that size (``refined_from``), then each distinct optimum it found
    is climbed by the same L-BFGS on every point used, and the best climb wins; its
    ``start_values`` are the climbs'. With `search_points` at least the points used, one stage
    (the search on all of them)."""
    x = inputs_array(x)
    y, _ = targets_array(y, x.shape[0])
    constant = check_mean(mean)
    restarts = check_count(restarts, "restarts", 0, 100)
    if not isinstance(stop_at_repeat, bool):
        raise ValueError(f"stop_at_repeat must be True or False, got {stop_at_repeat!r}")
    check_iterations(max_iterations)
    if search_points is not None:
        search_points = check_count(search_points, "search_points", 2)
    chosen = subsample(x.shape[0], max_points, seed)
    if chosen is not None:
        x, y = x[chosen], y[chosen]
    y = remove_mean(y, constant)
    if search_points is None:
        search_points = search_points_for(len(x))
    searched = subsample(len(x), search_points, seed)
    xs, ys = (x, y) if searched is None else (x[searched], y[searched])
    if initial is None:
        initial = SquaredExponential(*_core.gp_initial_kernel(xs, ys))
    *found, optima = _core.gp_fit_hyperparameters(
        xs,
        ys,
        initial.sigma_f,
        initial.length_scale,
        initial.sigma_n,
        restarts,
        check_seed(seed),
        max_iterations,
        stop_at_repeat=stop_at_repeat,
    )
    search = _fit_of(found, len(xs))
    if searched is None:
        return search
    # Each distinct optimum of the subsample climbed on every point used, best first.
    climbs = [
        _climb(x, y, SquaredExponential(sf, ls, sn), max_iterations)
        for sf, ls, sn, _ in sorted(optima, key=lambda o: -o[3])
    ]
    best = max(climbs, key=lambda c: c.log_marginal_likelihood)
    return HyperparameterFit(
        best.kernel,
        best.log_marginal_likelihood,
        sum(c.evaluations for c in climbs),
        sum(c.gradients for c in climbs),
        tuple(c.log_marginal_likelihood for c in climbs),
        len(x),
        search,
    )


def _climb(x: np.ndarray, y: np.ndarray, k: SquaredExponential, max_iterations: int):
    """The L-BFGS from kernel k alone (no scan, no restarts) on the checked, centred x, y."""
    found = _core.gp_fit_hyperparameters(
        x, y, k.sigma_f, k.length_scale, k.sigma_n, 0, 0, max_iterations, scan=False
    )
    return _fit_of(found, len(x))


def _fit_of(found: Any, points: int) -> HyperparameterFit:
    """A HyperparameterFit from gp_fit_hyperparameters' values (the optima left out)."""
    sf, ls, sn, lml, evaluations, gradients, starts = found[:7]
    return HyperparameterFit(
        SquaredExponential(sf, ls, sn),
        float(lml),
        int(evaluations),
        int(gradients),
        tuple(starts),
        points,
    )


def refine_hyperparameters(
    x: Any,
    y: Any,
    start: HyperparameterFit,
    *,
    max_iterations: int = 100,
    mean: str = "constant",
) -> HyperparameterFit:
    """The hyperparameters that maximise eq. 6.11 on every reading, by the same L-BFGS from the
    optimum ``start`` found on a subsample (:func:`fit_hyperparameters` with ``max_points``):
    no scan and no random restarts, which on every reading would cost the most. It climbs to the
    optimum of all readings nearest the subsample's (on the thesis' 3-D floor, 9 evaluations
    from a 1,000-point subsample's, where a full fit on 2,000 points takes 195)."""
    if not isinstance(start, HyperparameterFit):  # None was "no attribute 'kernel'"
        raise TypeError(
            f"start must be a HyperparameterFit (fit_hyperparameters'), got {type(start).__name__}"
        )
    x = inputs_array(x)
    y, _ = targets_array(y, x.shape[0])
    y = remove_mean(y, check_mean(mean))
    check_iterations(max_iterations)
    return replace(_climb(x, y, start.kernel, max_iterations), refined_from=start)


def log_marginal_likelihood(x: Any, y: Any, kernel: SquaredExponential, *, mean: str = "constant"):
    """(eq. 6.11 summed over Y's columns, its gradient in (log sigma_f, log l, log sigma_n))."""
    x = inputs_array(x)
    y, _ = targets_array(y, x.shape[0])
    y = remove_mean(y, check_mean(mean))
    value, gradient = _core.gp_log_marginal_likelihood(
        x, y, kernel.sigma_f, kernel.length_scale, kernel.sigma_n
    )
    return float(value), np.asarray(gradient)
