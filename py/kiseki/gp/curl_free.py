# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The curl-free magnetic field GP (Solin, Kok, Wahlstrom, Schon and Sarkka, "Modeling and
interpolation of the ambient magnetic field by Gaussian processes", IEEE T-RO 34(4), 2018).

In a source-free region the field is the gradient of a scalar potential, f = -grad(phi). With
phi ~ GP(0, k_SE + k_lin), k_SE(x, x') = sigma_f^2 exp(-|r|^2 / (2 l^2)), r = x - x', and the
linear kernel k_lin(x, x') = sigma_lin^2 x^T x' (the constant Earth field, a 3-vector with
prior N(0, sigma_lin^2 I)), the field's 3 x 3 covariance block is the mixed second derivative
d^2 k / dx dx'^T (Solin et al., sec. III-B):

    K(x, x') = sigma_f^2 (I / l^2 - r r^T / l^4) exp(-|r|^2 / (2 l^2)) + sigma_lin^2 I,

and every reading adds sigma_n^2 I. Positions of a robot moving in a plane are 2-D: the
potential is taken as a function of (x, y, z) and read at z = 0, so r_z = 0 in the block (the
z component is then independent of x and y, with variance sigma_f^2 / l^2).

This module holds the kernel, its hyperparameters by maximum marginal likelihood and the exact
GP (one Cholesky factorisation of the 3n x 3n matrix); :mod:`kiseki.gp.curl_free_basis` holds
the reduced-rank version.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
import scipy.linalg
import scipy.linalg.lapack
import scipy.optimize

from kiseki._support.counts import check_count
from kiseki.gp._data import check_iterations, inputs_array, targets_array
from kiseki.gp.kernel import check_hyperparameters, subsample

__all__ = [
    "CurlFreeFit",
    "CurlFreeGP",
    "CurlFreeKernel",
    "curl_free_log_marginal_likelihood",
    "field_inputs",
    "field_targets",
    "fit_curl_free_hyperparameters",
]

_NAMES = ("sigma_f", "length_scale", "sigma_lin", "sigma_n")


@dataclass(frozen=True)
class CurlFreeKernel:
    """The hyperparameters of the curl-free model (module text). Units: sigma_f that of the
    potential (field x metres), so that sigma_f / l is the SD of each component of the
    anomaly; sigma_lin and sigma_n those of the field; l metres."""

    sigma_f: float
    length_scale: float
    sigma_lin: float
    sigma_n: float

    def __post_init__(self) -> None:
        check_hyperparameters(self, _NAMES)

    def to_dict(self) -> dict[str, float]:
        return asdict(self)

    @classmethod
    def from_dict(cls, d: Any) -> CurlFreeKernel:
        if not isinstance(d, dict) or set(d) != set(_NAMES):
            raise ValueError(f"a curl-free kernel needs exactly {', '.join(_NAMES)}, got {d!r}")
        return cls(**d)

    @property
    def anomaly_sd(self) -> float:
        """sigma_f / l: the prior SD of each field component's anomaly (the diagonal of K)."""
        return self.sigma_f / self.length_scale

    def covariance(self, a: Any, b: Any) -> np.ndarray:
        """The (3 n_a, 3 n_b) covariance of the field at positions a (n_a, d) and b (n_b, d),
        d = 2 or 3, rows ordered (point, component); no noise term."""
        a, b = field_inputs(a, "a"), field_inputs(b, "b")
        return _blocks(a, b, self)[0]


def field_inputs(x: Any, name: str = "X") -> np.ndarray:
    """(n, 3) positions: 3-D as given, 2-D at z = 0 (the potential read on the plane)."""
    a = inputs_array(x, name)
    if a.shape[1] not in (2, 3):
        raise ValueError(f"{name}: positions must have 2 or 3 coordinates, got {a.shape[1]}")
    if not np.isfinite(a).all():
        raise ValueError(f"{name}: contains NaN or infinite values")
    if a.shape[1] == 2:
        a = np.column_stack([a, np.zeros(len(a))])
    return a


def field_targets(y: Any, n: int, name: str = "Y") -> np.ndarray:
    """(n, 3) field readings, finite."""
    a, _ = targets_array(y, n, name)
    if a.shape[1] != 3:
        raise ValueError(f"{name}: the field has 3 components per reading, got {a.shape[1]}")
    if not np.isfinite(a).all():
        raise ValueError(f"{name}: contains NaN or infinite values")
    return a


def _blocks(
    a: np.ndarray, b: np.ndarray, k: CurlFreeKernel, gradient: bool = False, linear: bool = True
):
    """(K (3 n_a, 3 n_b), dK / dlog l or None) of the field, without noise (module text), with
    the linear term sigma_lin^2 I in every block unless ``linear`` is False; built one
    component pair at a time (memory: the result and a few n_a x n_b arrays)."""
    r = [a[:, None, c] - b[None, :, c] for c in range(3)]  # r_c (n_a, n_b)
    s = r[0] ** 2 + r[1] ** 2 + r[2] ** 2
    l2 = k.length_scale**2
    e = k.sigma_f**2 * np.exp(-0.5 * s / l2)  # sigma_f^2 exp(-|r|^2 / (2 l^2))
    lin = k.sigma_lin**2 if linear else 0.0
    kmat = np.empty((len(a), 3, len(b), 3))
    d = np.empty_like(kmat) if gradient else None
    for i in range(3):
        for j in range(i, 3):
            rr = r[i] * r[j] / l2**2  # (r r^T)_ij / l^4
            inner = (1.0 / l2 if i == j else 0.0) - rr  # (I / l^2 - r r^T / l^4)_ij
            kmat[:, i, :, j] = e * inner + (lin if i == j else 0.0)
            kmat[:, j, :, i] = kmat[:, i, :, j]
            if d is not None:
                # d/dlog l of e (I/l^2 - r r^T/l^4) = e [(s/l^2) inner - 2 I/l^2 + 4 r r^T/l^4]
                d[:, i, :, j] = e * ((s / l2) * inner - (2.0 / l2 if i == j else 0.0) + 4.0 * rr)
                d[:, j, :, i] = d[:, i, :, j]
    shape = (3 * len(a), 3 * len(b))
    return kmat.reshape(shape), (None if d is None else d.reshape(shape))


def curl_free_log_marginal_likelihood(
    x: Any, y: Any, kernel: CurlFreeKernel, *, gradient: bool = True
) -> tuple[float, np.ndarray | None]:
    """(log p(y | x) of the stacked readings (Rasmussen and Williams eq. 2.30 with the 3n x 3n
    matrix), its gradient in log(sigma_f, l, sigma_lin, sigma_n) (their eq. 5.9) or None)."""
    if not isinstance(kernel, CurlFreeKernel):
        raise ValueError(f"kernel must be a CurlFreeKernel, got {type(kernel).__name__}")
    x = field_inputs(x)
    y = field_targets(y, len(x)).reshape(-1)
    return _lml(x, y, kernel, gradient)


def _lml(x: np.ndarray, y: np.ndarray, k: CurlFreeKernel, gradient: bool):
    se, dl = _blocks(x, x, k, gradient, linear=False)  # the squared-exponential part
    kmat = se.copy()
    for c in range(3):  # + sigma_lin^2 between the same components of any two readings
        kmat[c::3, c::3] += k.sigma_lin**2
    kmat[np.diag_indices_from(kmat)] += k.sigma_n**2
    try:
        chol = scipy.linalg.cho_factor(kmat, lower=True, check_finite=False, overwrite_a=True)
    except np.linalg.LinAlgError:
        return -math.inf, None
    alpha = scipy.linalg.cho_solve(chol, y, check_finite=False)
    logdet = 2.0 * np.log(np.diag(chol[0])).sum()
    value = -0.5 * (y @ alpha) - 0.5 * logdet - 0.5 * len(y) * math.log(2 * math.pi)
    if not gradient:
        return float(value), None
    # dL/dtheta = 1/2 tr((alpha alpha^T - K^-1) dK/dtheta) = 1/2 (alpha^T D alpha - <K^-1, D>)
    # for each symmetric D = dK/dtheta, without forming alpha alpha^T or the whole K^-1
    inverse, info = scipy.linalg.lapack.dpotri(chol[0], lower=1, overwrite_c=1)
    if info != 0:
        return -math.inf, None
    lower = np.tril(inverse)  # K^-1's lower half (dpotri leaves the upper half as it was)
    diagonal = np.diag(lower).copy()

    def with_inverse(d: np.ndarray) -> float:  # <K^-1, D> = sum_ij (K^-1)_ij D_ij
        return 2.0 * np.vdot(lower, d) - diagonal @ np.diag(d)

    sums = np.array([alpha[c::3].sum() for c in range(3)])
    lin_inverse = sum(2.0 * lower[c::3, c::3].sum() - diagonal[c::3].sum() for c in range(3))
    grads = [
        alpha @ (se @ alpha) - with_inverse(se),  # dK/dlog sigma_f = 2 K_SE, halved by the 1/2
        0.5 * (alpha @ (dl @ alpha) - with_inverse(dl)),
        k.sigma_lin**2 * (sums @ sums - lin_inverse),  # dK/dlog sigma_lin = 2 sigma_lin^2 L
        k.sigma_n**2 * (alpha @ alpha - diagonal.sum()),  # dK/dlog sigma_n = 2 sigma_n^2 I
    ]
    return float(value), np.array(grads)


@dataclass(frozen=True)
class CurlFreeFit:
    """The outcome of :func:`fit_curl_free_hyperparameters`."""

    kernel: CurlFreeKernel
    log_marginal_likelihood: float  # at the optimum, on the points used
    evaluations: int
    start_values: tuple[float, ...]  # the best likelihood reached from each start
    points_used: int


def initial_kernel(x: np.ndarray, y: np.ndarray, length_scale: float) -> CurlFreeKernel:
    """A start from the data's spread: the anomaly's SD from the readings' SD per component,
    sigma_lin from the mean field's size, sigma_n a tenth of the anomaly."""
    sd = float(np.sqrt(np.mean(np.var(y, axis=0)))) or 1.0
    size = float(np.linalg.norm(y.mean(axis=0)))
    return CurlFreeKernel(sd * length_scale, length_scale, max(size, sd), 0.1 * sd)


def fit_curl_free_hyperparameters(
    x: Any,
    y: Any,
    *,
    initial: CurlFreeKernel | None = None,
    max_points: int = 500,
    seed: int = 0,
    max_iterations: int = 100,
) -> CurlFreeFit:
    """Hyperparameters maximising the log marginal likelihood, by L-BFGS-B in the log
    parameters with the analytic gradient, from `initial` or else from three starts (the data's
    spread with l a 30th, a 10th and a 3rd of the positions' extent), the best kept. Above
    `max_points` readings the likelihood is that of a seeded random subsample of that size
    (each evaluation factorises a 3 max_points square matrix)."""
    x = field_inputs(x)
    y = field_targets(y, len(x))
    check_iterations(max_iterations)
    if initial is not None and not isinstance(initial, CurlFreeKernel):
        raise ValueError(f"initial must be a CurlFreeKernel, got {type(initial).__name__}")
    keep = subsample(len(x), max_points, seed)
    if keep is not None:
        x, y = x[keep], y[keep]
    flat = y.reshape(-1)
    if initial is None:
        extent = float(np.max(np.ptp(x, axis=0))) or 1.0
        starts = [initial_kernel(x, y, extent / f) for f in (30.0, 10.0, 3.0)]
    else:
        starts = [initial]
    counter = [0]

    def objective(theta: np.ndarray):
        counter[0] += 1
        v, g = _lml(x, flat, CurlFreeKernel(*np.exp(theta)), True)
        if not math.isfinite(v):
            return 1e300, np.zeros(4)
        return -v, -g

    best, values = None, []
    for start in starts:
        theta0 = np.log([getattr(start, n) for n in _NAMES])
        bounds = [(t - 12.0, t + 12.0) for t in theta0]
        res = scipy.optimize.minimize(
            objective,
            theta0,
            jac=True,
            method="L-BFGS-B",
            bounds=bounds,
            options={"maxiter": max_iterations},
        )
        values.append(float(-res.fun))
        if best is None or res.fun < best.fun:
            best = res
    kernel = CurlFreeKernel(*np.exp(best.x))
    return CurlFreeFit(kernel, float(-best.fun), counter[0], tuple(values), len(x))


class CurlFreeGP:
    """The exact curl-free GP: f(x*) | y ~ N(K*^T (K + sigma_n^2 I)^-1 y, K** - K*^T (...)^-1
    K*) with the 3 x 3 blocks above (zero prior mean: the constant field is the linear term).
    Build with :meth:`fit`; memory 8 (3n)^2 bytes, time (3n)^3 / 3 flops."""

    def __init__(self, x: np.ndarray, dimension: int, kernel: CurlFreeKernel, chol, alpha, fit):
        self._x = x
        self.dimension = dimension  # of the positions given (2: the potential read at z = 0)
        self.kernel = kernel
        self._chol = chol
        self._alpha = alpha
        self.hyperparameter_fit: CurlFreeFit | None = fit

    @classmethod
    def fit(
        cls,
        x: Any,
        y: Any,
        kernel: CurlFreeKernel | None = None,
        *,
        max_points: int = 500,
        seed: int = 0,
    ) -> CurlFreeGP:
        """Fits to readings y (n, 3) at positions x (n, 2) or (n, 3); without a kernel the
        hyperparameters come from :func:`fit_curl_free_hyperparameters` (max_points, seed)."""
        dimension = inputs_array(x).shape[1]
        x = field_inputs(x)
        y = field_targets(y, len(x))
        fit = None
        if kernel is None:
            fit = fit_curl_free_hyperparameters(x, y, max_points=max_points, seed=seed)
            kernel = fit.kernel
        if not isinstance(kernel, CurlFreeKernel):
            raise ValueError(f"kernel must be a CurlFreeKernel, got {type(kernel).__name__}")
        kmat, _ = _blocks(x, x, kernel)
        kmat[np.diag_indices_from(kmat)] += kernel.sigma_n**2
        chol = scipy.linalg.cho_factor(kmat, lower=True, overwrite_a=True, check_finite=False)
        alpha = scipy.linalg.cho_solve(chol, y.reshape(-1), check_finite=False)
        return cls(x, dimension, kernel, chol, alpha, fit)

    def state(self) -> dict[str, np.ndarray]:
        """What :meth:`from_state` needs besides the readings and the kernel: the lower
        Cholesky factor of K + sigma_n^2 I (3n, 3n)."""
        return {"factor": np.tril(self._chol[0])}

    @classmethod
    def from_state(cls, x: Any, y: Any, kernel: CurlFreeKernel, factor: Any) -> CurlFreeGP:
        """The GP :meth:`fit` made from readings y at positions x with `kernel`, from its
        :meth:`state`: no factorisation, the weights by two triangular solves. Rows spread over
        the factor (the last one, which touches every column, among them) are checked against
        the kernel: L L^T = K + sigma_n^2 I to 1e-8 of |L| |L^T| entry by entry; a ValueError
        when they disagree."""
        if not isinstance(kernel, CurlFreeKernel):
            raise ValueError(f"kernel must be a CurlFreeKernel, got {type(kernel).__name__}")
        dimension = inputs_array(x).shape[1]
        x = field_inputs(x)
        y = field_targets(y, len(x)).reshape(-1)
        size = 3 * len(x)
        chol = np.asarray(factor, dtype=np.float64)
        if chol.shape != (size, size):
            raise ValueError(f"factor {chol.shape} does not fit {len(x)} readings ({size} square)")
        if not np.isfinite(chol).all() or not (np.diag(chol) > 0).all():
            raise ValueError("factor is not a Cholesky factor (not finite, or a diagonal <= 0)")
        rows = np.unique(np.linspace(0, size - 1, min(size, 24)).astype(int))
        kmat, _ = _blocks(x[rows // 3], x, kernel)
        kmat = kmat[np.arange(len(rows)) * 3 + rows % 3]
        kmat[np.arange(len(rows)), rows] += kernel.sigma_n**2
        lower = np.tril(chol)
        # Cholesky's backward error is a few rounding errors of |L| |L^T|, entry by entry
        size_of_terms = np.abs(lower[rows]) @ np.abs(lower).T
        if (np.abs(lower[rows] @ lower.T - kmat) > 1e-8 * size_of_terms + 1e-300).any():
            raise ValueError("factor is not the Cholesky factor of these readings' kernel matrix")
        chol = (lower, True)
        alpha = scipy.linalg.cho_solve(chol, y, check_finite=False)
        return cls(x, dimension, kernel, chol, alpha, None)

    def constant_field(self) -> tuple[np.ndarray, np.ndarray]:
        """(mean (3,), variance (3,)) of the constant (Earth) field's posterior: with
        E = [I I ... I] (3, 3n), mean sigma_lin^2 E weights and variance sigma_lin^2 -
        sigma_lin^4 diag(E (K + sigma_n^2 I)^-1 E^T); the field far from every reading."""
        s2 = self.kernel.sigma_lin**2
        e = np.tile(np.eye(3), (self.size, 1))  # E^T
        v = scipy.linalg.solve_triangular(self._chol[0], e, lower=True, check_finite=False)
        return s2 * (e.T @ self._alpha), s2 - s2**2 * np.einsum("ij,ij->j", v, v)

    @property
    def size(self) -> int:
        return len(self._x)

    @property
    def weights(self) -> np.ndarray:
        """(K + sigma_n^2 I)^-1 y, (n, 3): the mean at x* is sum_i K(x*, x_i) weights_i."""
        return self._alpha.reshape(-1, 3)

    def predict(
        self, points: Any, *, variance: bool = True, block: int = 500
    ) -> tuple[np.ndarray, np.ndarray | None]:
        """(mean (m, 3), variance of the noise-free field (m, 3) or None) at points (m, 2|3);
        `block` points at a time (memory 8 * 9 n block bytes)."""
        if inputs_array(points, "points").shape[1] != self.dimension:
            raise ValueError(f"points must have {self.dimension} coordinates, as the GP's inputs")
        p = field_inputs(points, "points")
        block = check_count(block, "block", 1)
        means, variances = [], []
        prior = self.kernel.anomaly_sd**2 + self.kernel.sigma_lin**2
        for start in range(0, len(p), block):
            ks, _ = _blocks(self._x, p[start : start + block], self.kernel)  # (3n, 3b)
            means.append((ks.T @ self._alpha).reshape(-1, 3))
            if variance:
                v = scipy.linalg.solve_triangular(self._chol[0], ks, lower=True, check_finite=False)
                variances.append((prior - np.einsum("ij,ij->j", v, v)).reshape(-1, 3))
        mean = np.vstack(means) if means else np.zeros((0, 3))
        if not variance:
            return mean, None
        return mean, (np.vstack(variances) if variances else np.zeros((0, 3)))
