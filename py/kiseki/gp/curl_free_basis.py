# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The reduced-rank curl-free GP (Solin et al., IEEE T-RO 2018, sec. IV; the Hilbert-space
method of Solin and Sarkka, Statistics and Computing 2020).

The potential's SE kernel is approximated by the Dirichlet Laplacian's eigenfunctions on a box
[c - L, c + L] (eqs. of sec. IV-A):

    phi_j(x) = prod_k L_k^-1/2 sin(pi j_k (x_k - c_k + L_k) / (2 L_k)),
    lambda_j = sum_k (pi j_k / (2 L_k))^2,
    k_SE(x, x') ~ sum_j S(sqrt(lambda_j)) phi_j(x) phi_j(x'),

with S(w) = sigma_f^2 (2 pi l^2)^(d/2) exp(-w^2 l^2 / 2) the SE kernel's spectral density in d
dimensions. The field's basis functions are -grad phi_j (analytic), so the design matrix is
(3n x m) and the weights' posterior an m x m system: fit O(n m^2), prediction O(m^2) per point.
The constant Earth field adds three basis functions (the unit vectors) with prior variance
sigma_lin^2.

2-D positions (the potential read at z = 0): the x and y components are -grad of a 2-D basis
with the 2-D spectral density; the z component, independent of them with the SE kernel of
variance sigma_f^2 / l^2 (the block of :mod:`kiseki.gp.curl_free` at r_z = 0), gets its own
weights on the same basis with density S_2(w) / l^2.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import scipy.linalg

from kiseki._support.counts import check_count
from kiseki._support.real_numbers import check_number
from kiseki.gp._data import inputs_array
from kiseki.gp.curl_free import CurlFreeKernel, field_targets

__all__ = ["MAX_BASIS", "ReducedRankCurlFreeGP", "laplacian_basis"]

MAX_BASIS = 10_000  # eigenfunctions of a reduced-rank curl-free GP


def laplacian_basis(half_widths: Any, count: int) -> np.ndarray:
    """(count, d) integer indices j (each >= 1) of the `count` eigenfunctions of the box with
    these half-widths L (d,) that have the smallest eigenvalues (ties: lexicographic)."""
    half = np.asarray(half_widths, dtype=float).reshape(-1)
    if half.size not in (2, 3) or not (np.isfinite(half).all() and (half > 0).all()):
        raise ValueError(f"half_widths: 2 or 3 finite lengths > 0, got {half_widths!r}")
    # the fit keeps a (count + 3)^2 factor: 10,000 functions are 800 MB
    count = check_count(count, "count", 1, MAX_BASIS)
    d = half.size
    # enough candidates per axis that the `count` smallest eigenvalues are among them
    per_axis = np.ceil(2.0 * count ** (1.0 / d) * half / half.min()) + 1
    if np.prod(per_axis) > 5e7:
        raise ValueError(
            f"half_widths {half.tolist()}: sides too unequal to pick {count} functions from "
            "(more than 50,000,000 candidates)"
        )
    per_axis = per_axis.astype(int)
    grids = np.meshgrid(*[np.arange(1, n + 1) for n in per_axis], indexing="ij")
    j = np.column_stack([g.ravel() for g in grids])
    lam = (((math.pi / 2) * j / half) ** 2).sum(axis=1)
    order = np.lexsort((*j.T[::-1], lam))
    return j[order[:count]]


class ReducedRankCurlFreeGP:
    """The reduced-rank curl-free GP (module text). Build with :meth:`fit`; the weights' mean
    and the Cholesky factor of their precision are kept, so prediction needs no refit."""

    def __init__(self, kernel, centre, half, indices, mean, chol) -> None:
        self.kernel = kernel
        self.centre = centre
        self.half_widths = half
        self.indices = indices
        self.weights = mean  # the posterior mean of the weights (potential, [z,] linear)
        self._chol = chol

    @classmethod
    def fit(
        cls,
        x: Any,
        y: Any,
        kernel: CurlFreeKernel,
        *,
        basis: int = 512,
        domain: tuple[Any, Any] | None = None,
        margin: float = 3.0,
        block: int = 2000,
    ) -> ReducedRankCurlFreeGP:
        """Fits to readings y (n, 3) at positions x (n, 2|3): `basis` eigenfunctions of the
        box `domain` = (lower, upper), by default the data's bounding box grown by `margin`
        length scales on every side (the approximation falls to the prior at the faces);
        `block` readings at a time."""
        if not isinstance(kernel, CurlFreeKernel):
            raise ValueError(f"kernel must be a CurlFreeKernel, got {type(kernel).__name__}")
        x = inputs_array(x)
        if x.shape[1] not in (2, 3) or not np.isfinite(x).all():
            raise ValueError(f"X: finite positions with 2 or 3 coordinates, got shape {x.shape}")
        y = field_targets(y, len(x))
        check_number(margin, "margin", 0.0)
        block = check_count(block, "block", 1)
        if domain is None:
            grow = margin * kernel.length_scale
            lower, upper = x.min(axis=0) - grow, x.max(axis=0) + grow
        else:
            lower, upper = (np.asarray(v, dtype=float).reshape(-1) for v in domain)
            if lower.shape != (x.shape[1],) or upper.shape != (x.shape[1],):
                raise ValueError(f"domain: lower and upper need {x.shape[1]} coordinates each")
            if not (upper > lower).all() or ((x < lower) | (x > upper)).any():
                raise ValueError("domain: upper must exceed lower and hold every position")
        centre, half = (lower + upper) / 2, np.maximum((upper - lower) / 2, 1e-9)
        indices = laplacian_basis(half, basis)
        model = cls(kernel, centre, half, indices, None, None)
        prior = model.prior_variances()
        size = len(prior)
        gram, projected = np.zeros((size, size)), np.zeros(size)
        columns = model.columns()
        for start in range(0, len(x), block):
            phi = model.design(x[start : start + block]).reshape(-1, 3, size)
            part = y[start : start + block]
            for c, cols in enumerate(columns):  # only the columns a component touches
                d = phi[:, c, cols]
                gram[np.ix_(cols, cols)] += d.T @ d
                projected[cols] += d.T @ part[:, c]
        # weights' precision / sigma_n^-2: Phi^T Phi + sigma_n^2 Lambda^-1 (sec. IV, eq. 25)
        gram[np.diag_indices(size)] += kernel.sigma_n**2 / prior
        model._chol = scipy.linalg.cho_factor(gram, lower=True, check_finite=False)
        model.weights = scipy.linalg.cho_solve(model._chol, projected, check_finite=False)
        return model

    def state(self) -> dict[str, np.ndarray]:
        """What :meth:`from_state` needs besides the kernel: the box (centre, half widths), the
        eigenfunctions' indices, the weights' mean and the lower Cholesky factor of their
        precision / sigma_n^-2."""
        return {
            "centre": self.centre.copy(),
            "half_widths": self.half_widths.copy(),
            "indices": self.indices.copy(),
            "weights": self.weights.copy(),
            "factor": np.tril(self._chol[0]),
        }

    @classmethod
    def from_state(
        cls, x, y, kernel: CurlFreeKernel, centre, half_widths, indices, weights, factor
    ) -> ReducedRankCurlFreeGP:
        """The GP :meth:`fit` made from readings y at positions x, from its :meth:`state`
        (no Phi^T Phi). A ValueError when the arrays' shapes do not fit each other or, on rows
        spread over the weights (the three constant ones among them), the stored precision does
        not turn the weights into Phi^T y (eq. 25's normal equations, to 1e-6 of the size of
        their terms)."""
        if not isinstance(kernel, CurlFreeKernel):
            raise ValueError(f"kernel must be a CurlFreeKernel, got {type(kernel).__name__}")
        arrays = [np.asarray(a, dtype=np.float64) for a in (centre, half_widths, weights, factor)]
        centre, half, mean, chol = arrays
        index = np.asarray(indices)
        d = centre.shape[0] if centre.ndim == 1 else 0
        if d not in (2, 3) or half.shape != (d,) or index.ndim != 2 or index.shape[1] != d:
            raise ValueError(
                f"centre {centre.shape}, half_widths {half.shape} and indices {index.shape} "
                "must describe one 2-D or 3-D box"
            )
        if not all(np.isfinite(a).all() for a in arrays) or not (half > 0).all():
            raise ValueError("the state must be finite, with half widths > 0")
        if index.dtype.kind not in "iu" or (index < 1).any():
            raise ValueError("indices must be integers >= 1 (the eigenfunctions' numbers)")
        model = cls(kernel, centre, half, index.astype(np.int64), mean, None)
        size = len(model.prior_variances())
        if mean.shape != (size,) or chol.shape != (size, size):
            raise ValueError(
                f"weights {mean.shape} and factor {chol.shape} do not fit {len(index)} "
                f"eigenfunctions (({size},) and ({size}, {size}))"
            )
        if not (np.diag(chol) > 0).all():
            raise ValueError("factor is not a Cholesky factor (a diagonal entry is <= 0)")
        chol = np.tril(chol)
        model._chol = (chol, True)
        x = inputs_array(x)
        y = field_targets(y, len(x))
        if x.shape[1] != d:
            raise ValueError(f"X has {x.shape[1]} coordinates, the state's box {d}")
        rows = np.unique(np.append(np.linspace(0, size - 4, min(size - 3, 21)).astype(int),
                                   np.arange(size - 3, size)))  # fmt: skip
        projected = np.zeros(len(rows))  # (Phi^T y)[rows], 2,000 readings at a time
        for start in range(0, len(x), 2000):
            phi = model.design(x[start : start + 2000])[:, rows]
            projected += phi.T @ y[start : start + 2000].reshape(-1)
        precision = chol[rows] @ chol.T
        size_of_terms = np.abs(precision) @ np.abs(mean) + np.abs(projected)
        if (np.abs(precision @ mean - projected) > 1e-6 * size_of_terms).any():
            raise ValueError("factor and weights do not fit these readings (eq. 25)")
        return model

    def constant_field(self) -> tuple[np.ndarray, np.ndarray]:
        """(mean (3,), variance (3,)) of the constant (Earth) field's posterior: the last three
        weights, their variance sigma_n^2 diag(P^-1) with P = L L^T the stored precision."""
        size = len(self.weights)
        e = np.zeros((size, 3))
        e[size - 3 :, :] = np.eye(3)
        v = scipy.linalg.solve_triangular(self._chol[0], e, lower=True, check_finite=False)
        return self.weights[-3:].copy(), self.kernel.sigma_n**2 * np.einsum("ij,ij->j", v, v)

    @property
    def dimension(self) -> int:
        return len(self.centre)

    @property
    def basis_size(self) -> int:
        """The number of eigenfunctions of the potential."""
        return len(self.indices)

    def prior_variances(self) -> np.ndarray:
        """The weights' prior variances: S(sqrt(lambda_j)) of the potential, (2-D) S / l^2 of
        the z component, sigma_lin^2 of the three linear terms."""
        k = self.kernel
        d = self.dimension
        root = np.sqrt((((math.pi / 2) * self.indices / self.half_widths) ** 2).sum(axis=1))
        l2 = k.length_scale**2
        density = k.sigma_f**2 * (2 * math.pi * l2) ** (d / 2) * np.exp(-0.5 * root**2 * l2)
        parts = [density] + ([density / l2] if d == 2 else []) + [np.full(3, k.sigma_lin**2)]
        return np.maximum(np.concatenate(parts), 1e-300)

    def columns(self) -> list[np.ndarray]:
        """Per field component, the design matrix's columns that can be non-zero in its rows:
        the potential's (x, y, 3-D z) or the z weights (2-D z), and its linear term."""
        m, d = self.basis_size, self.dimension
        size = len(self.prior_variances())
        potential = np.arange(m)
        out = []
        for c in range(3):
            own = np.arange(m, 2 * m) if (d == 2 and c == 2) else potential
            out.append(np.append(own, size - 3 + c))
        return out

    def design(self, points: Any) -> np.ndarray:
        """(3 m, P) design matrix at points (m, d): rows (point, component), columns the
        weights of :meth:`prior_variances`."""
        p = inputs_array(points, "points")
        if p.shape[1] != self.dimension:
            raise ValueError(
                f"points have {p.shape[1]} coordinates, the GP was fitted on {self.dimension}"
            )
        freq = (math.pi / 2) * self.indices / self.half_widths  # (M, d)
        angle = (p - self.centre + self.half_widths)[:, None, :] * freq[None]  # (m, M, d)
        sines, cosines = np.sin(angle), np.cos(angle)
        scale = 1.0 / math.sqrt(float(np.prod(self.half_widths)))
        m, count, d = angle.shape
        out = np.zeros((m, 3, len(self.prior_variances())))
        for k in range(d):
            # d phi_j / dx_k = freq_k cos(angle_k) prod_{other axes} sin(angle)
            others = np.prod(np.delete(sines, k, axis=2), axis=2)
            out[:, k, :count] = -scale * freq[None, :, k] * cosines[:, :, k] * others
        if d == 2:
            out[:, 2, count : 2 * count] = scale * np.prod(sines, axis=2)
        out[:, 0, -3], out[:, 1, -2], out[:, 2, -1] = 1.0, 1.0, 1.0
        return out.reshape(3 * m, -1)

    def predict(
        self, points: Any, *, variance: bool = True, block: int = 2000
    ) -> tuple[np.ndarray, np.ndarray | None]:
        """(mean (m, 3), variance of the noise-free field (m, 3) or None) at points (m, d);
        inside the box only (beyond it the eigenfunctions continue as sines: not the GP)."""
        block = check_count(block, "block", 1)
        p = inputs_array(points, "points")
        means, variances = [], []
        for start in range(0, len(p), block):
            phi = self.design(p[start : start + block])
            means.append((phi @ self.weights).reshape(-1, 3))
            if variance:
                v = scipy.linalg.solve_triangular(
                    self._chol[0], phi.T, lower=True, check_finite=False
                )
                var = self.kernel.sigma_n**2 * np.einsum("ij,ij->j", v, v)
                variances.append(var.reshape(-1, 3))
        mean = np.vstack(means) if means else np.zeros((0, 3))
        if not variance:
            return mean, None
        return mean, (np.vstack(variances) if variances else np.zeros((0, 3)))
