# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Reduced-rank GP regression for large maps (Solin & Sarkka, Statistics and Computing 2020)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from kiseki import _core
from kiseki._support.real_numbers import check_number
from kiseki.gp._data import check_mean, inputs_array, targets_array
from kiseki.gp.kernel import SquaredExponential

__all__ = ["HilbertGP", "hilbert_basis_size", "spectral_tolerance"]

# hilbert_basis_size's counting: every combination of the sides' eigenfunctions at once up to
# _DENSE_COUNT (as always), above that by a search per value of the first sides, up to
# _SEARCHED_COUNT such values; no side beyond _MAX_PER_SIDE functions
_DENSE_COUNT = 20_000_000
_SEARCHED_COUNT = 20_000_000
_MAX_PER_SIDE = 10_000_000


class HilbertGP:
    """The GP approximated by the Laplacian's eigenfunctions on a box around the data (see
    ``cpp/include/kiseki/gp/hilbert_gp.hpp``): fit O(n m^2), prediction O(m^2) per point,
    m the basis size, which depends on the box and the length scale but not on n.

    Use it beyond ~10,000 readings, with hyperparameters from :func:`fit_hyperparameters` on
    a subsample. The default box is the data's bounding box grown by 4 length scales on every
    side (the approximation falls to the prior at the box's faces); ``tolerance`` is the share
    of the kernel's spectral density below which frequencies are dropped (default
    :func:`spectral_tolerance`: 1e-4, smaller for a field that stands far above its noise)."""

    def __init__(
        self, core: Any, kernel: SquaredExponential, mean: str, lower, upper, tolerance: float
    ) -> None:
        self._core = core
        self.kernel = kernel
        self.mean = mean
        self.lower = np.asarray(lower, dtype=float)
        self.upper = np.asarray(upper, dtype=float)
        self.tolerance = tolerance

    @classmethod
    def fit(
        cls,
        x: Any,
        y: Any,
        kernel: SquaredExponential,
        *,
        domain: tuple[Any, Any] | None = None,
        tolerance: float | None = None,
        max_basis: int = 20000,
        mean: str = "constant",
    ) -> HilbertGP:
        x = inputs_array(x)
        y, _ = targets_array(y, x.shape[0])
        constant = check_mean(mean)
        if not isinstance(kernel, SquaredExponential):
            raise ValueError(f"kernel must be a SquaredExponential, got {type(kernel).__name__}")
        if x.shape[1] > 3:
            raise ValueError(f"HilbertGP takes 1-3 coordinates, got {x.shape[1]}")
        if not np.isfinite(x).all():
            raise ValueError("X: contains NaN or infinite values")
        if domain is None:
            margin = 4.0 * kernel.length_scale
            lower, upper = x.min(axis=0) - margin, x.max(axis=0) + margin
        else:
            lower, upper = (np.asarray(v, dtype=float).reshape(-1) for v in domain)
        if tolerance is None:
            tolerance = spectral_tolerance(kernel)
        tolerance = check_number(tolerance, "tolerance", 0.0, 1.0, low_open=True, high_open=True)
        core = _core.HilbertGaussianProcess(
            x,
            y,
            kernel.sigma_f,
            kernel.length_scale,
            kernel.sigma_n,
            lower,
            upper,
            tolerance,
            max_basis,
            constant,
        )
        return cls(core, kernel, mean, lower, upper, tolerance)

    def predict(self, points: Any) -> tuple[np.ndarray, np.ndarray]:
        """(mean (m, k), variance (m, k)) of the noise-free field; the prior outside the box."""
        p = inputs_array(points, "points")
        if p.shape[1] != self.dimension:
            raise ValueError(
                f"points have {p.shape[1]} coordinates, the GP was fitted on {self.dimension}"
            )
        mean, var = self._core.predict(p)
        return mean, np.repeat(var[:, None], mean.shape[1], axis=1)

    @property
    def basis_size(self) -> int:
        return int(self._core.basis_size)

    @property
    def dimension(self) -> int:
        return int(self._core.dimension)

    @property
    def outputs(self) -> int:
        return int(self._core.outputs)

    @property
    def size(self) -> int:
        return int(self._core.size)

    @property
    def prior_mean(self) -> np.ndarray:
        return np.asarray(self._core.prior_mean)

    @property
    def prior_variance(self) -> np.ndarray:
        """sigma_f^2 per column."""
        return np.full(self.outputs, self.kernel.sigma_f**2)


def spectral_tolerance(kernel: SquaredExponential) -> float:
    """The default spectral cut of a reduced-rank GP with this kernel: 1e-4 times sigma_n^2 /
    sigma_f^2 where that is smaller. The frequencies dropped hold of the order of tolerance x
    sigma_f^2 of the prior's variance, which the mean cannot follow; scaled so, that part
    stays near 1e-4 sigma_n^2 however far the field stands above the noise. On 2,400 readings
    over a 12 x 5 m strip at l = 0.5 m (two seeds) a fixed 1e-4 (810 functions) put the mean
    up to 0.14 sigma_n from the exact GP's at sigma_f / sigma_n = 10 and 2.1 sigma_n at 60;
    the rule's 1e-6 and 2.8e-8 (1,224 and 1,542 functions) 0.002-0.003 sigma_n."""
    if not isinstance(kernel, SquaredExponential):  # None was "no attribute 'sigma_n'"
        raise TypeError(f"kernel must be a SquaredExponential, got {type(kernel).__name__}")
    return 1e-4 * min(1.0, (kernel.sigma_n / kernel.sigma_f) ** 2)


def hilbert_basis_size(sides: Any, length_scale: float, tolerance: float) -> int:
    """The basis size m of :class:`HilbertGP` on a box with these side lengths at a spectral
    `tolerance` (its default for a kernel: :func:`spectral_tolerance`), by its rule: the
    Laplacian's eigenfunctions sin(pi j_d (x_d - lower_d) / side_d), j_d = 1, 2, ..., whose
    frequency sqrt(sum_d (pi j_d / side_d)^2) is at most w_max, S(w_max) = tolerance S(0) (at
    least one function)."""
    check_number(length_scale, "hilbert_basis_size: length_scale", 0.0, low_open=True)
    check_number(
        tolerance, "hilbert_basis_size: tolerance", 0.0, 1.0, low_open=True, high_open=True
    )
    box = np.atleast_1d(np.asarray(sides, dtype=float))
    if box.ndim != 1 or not 1 <= len(box) <= 3 or not (np.isfinite(box) & (box > 0)).all():
        raise ValueError(f"hilbert_basis_size: sides must be 1-3 lengths > 0, got {sides!r}")
    w_max = math.sqrt(-2.0 * math.log(tolerance)) / length_scale
    counts = [max(1, math.floor(min(w_max * side / math.pi, 1e18))) for side in box]
    if max(counts) > _MAX_PER_SIDE:
        raise ValueError(
            f"hilbert_basis_size: a side of {box[int(np.argmax(counts))]:g} at length scale "
            f"{length_scale:g} holds {max(counts):.3g} eigenfunctions, more than "
            f"{_MAX_PER_SIDE:,} (a length scale this short for so large a box)"
        )
    axes = [np.pi * np.arange(1, c + 1) / side for c, side in zip(counts, box, strict=True)]
    if math.prod(counts) <= _DENSE_COUNT:  # every combination at once, as always
        w2 = sum(a**2 for a in np.meshgrid(*axes, indexing="ij", sparse=True))
        return max(1, int((w2 <= w_max**2).sum()))
    # too many combinations to hold: for each value of the first axes, the last axis' count by
    # a search (the same count)
    if math.prod(counts[:-1]) > _SEARCHED_COUNT:
        raise ValueError(
            f"hilbert_basis_size: sides {box.tolist()} at length scale {length_scale:g} would "
            f"need about {math.prod(counts):.3g} eigenfunctions to count (a length scale this "
            "short for so large a box)"
        )
    squares = [a**2 for a in axes]
    rows = [squares[0]] if len(squares) == 2 else [a + squares[1] for a in squares[0]]
    inside = sum(int(np.searchsorted(squares[-1], w_max**2 - r, side="right").sum()) for r in rows)
    return max(1, inside)
