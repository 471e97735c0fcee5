# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The Gaussian process behind a magnetic field map (:mod:`kiseki.magnetic.field_map`): fitting
the field's components, evaluating the GP on the map's cells, and the predictor a map keeps so
that predictions at any point need no refit.

Two field models:

* ``independent``: mx, my and mz as GPs with squared-exponential kernels (thesis ch. 6, eqs.
  6.7-6.9), one kernel shared or one per component, exact (:class:`~kiseki.gp.ExactGP`),
  reduced-rank (:class:`~kiseki.gp.HilbertGP`) or a grid of either for a whole floor
  (:class:`~kiseki.gp.TiledGP`); a map keeps its readings and rebuilds the GP
  (no optimisation) the first time it predicts;
* ``curl-free``: the field as the gradient of a scalar potential plus a constant (Solin et al.,
  IEEE T-RO 2018; :class:`~kiseki.gp.CurlFreeGP`, :class:`~kiseki.gp.ReducedRankCurlFreeGP`);
  a map keeps its readings and the fitted GP's factor (:func:`predictor_state`), so predicting
  costs two triangular solves (exact) or nothing (reduced rank) before the first point.

Outside the map a curl-free map returns the constant field's posterior (the field far from every
reading), with the anomaly's prior variance added.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from tqdm import tqdm

from kiseki.gp import (
    CurlFreeGP,
    CurlFreeKernel,
    ExactGP,
    HilbertGP,
    ReducedRankCurlFreeGP,
    TiledGP,
)

__all__ = [
    "CURL_FREE_BASIS",
    "METHODS",
    "MODELS",
    "as_gp_list",
    "column_kernels",
    "evaluate_on_cells",
    "fit_component_gps",
    "hilbert_settings",
    "predict_all",
    "predictor_state",
    "rebuild",
]

MODELS = ("curl-free", "independent")
METHODS = ("exact", "hilbert", "tiled")  # "tiled": the independent model's only
CURL_FREE_BASIS = 1024
"""Eigenfunctions of the reduced-rank curl-free GP (the most that gp-aalto-defaults measured:
4.45 uT mean held-out RMSE against 3.68 for the exact GP on binned readings)."""
_CHUNK = 20_000  # at most this many cells per gp.predict call
_CHUNK_ENTRIES = 20_000_000  # and a (cells x training points) cross-covariance of <= 160 MB
_CURL_FREE = (CurlFreeGP, ReducedRankCurlFreeGP)


class _CurlFreeField:
    """A curl-free GP seen as a map's three outputs (the interface of ExactGP and HilbertGP
    that the map uses)."""

    outputs = 3

    def __init__(self, gp: CurlFreeGP | ReducedRankCurlFreeGP) -> None:
        self.gp = gp
        self.kernel = gp.kernel
        self.kernels = (gp.kernel,) * 3
        self.dimension = gp.dimension
        constant, variance = gp.constant_field()
        self.prior_mean = constant
        self.prior_variance = variance + gp.kernel.anomaly_sd**2
        self.size = getattr(gp, "size", 1)
        self.basis_size = getattr(gp, "basis_size", self.size)

    def predict(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return self.gp.predict(points)


def as_gp_list(gp) -> list:
    """The fitted GP(s) of a map's three components: one GP of three outputs, three of one, or
    a curl-free GP; a ValueError for anything else."""
    gps = list(gp) if isinstance(gp, (list, tuple)) else [gp]
    gps = [_CurlFreeField(g) if isinstance(g, _CURL_FREE) else g for g in gps]
    for g in gps:
        for name in ("predict", "dimension", "outputs", "kernel", "prior_mean"):
            if not hasattr(g, name):
                raise ValueError(f"not a fitted GP (no {name}): {g!r}")
    if sum(g.outputs for g in gps) != 3:
        raise ValueError(f"the GPs give {sum(g.outputs for g in gps)} outputs; a map needs 3")
    if len({g.dimension for g in gps}) != 1:
        raise ValueError("the GPs of the three components must share their input dimension")
    return gps


def column_kernels(gps: list) -> tuple:
    """The kernel of each of the three components (a GP holds one shared kernel, or with
    ``kernels`` one per output)."""
    out = []
    for g in gps:
        kernels = tuple(getattr(g, "kernels", (g.kernel,)))
        if len(kernels) not in (1, g.outputs):
            raise ValueError(f"a GP with {g.outputs} outputs has {len(kernels)} kernels")
        out += kernels * g.outputs if len(kernels) == 1 else kernels
    return tuple(out)


def predict_all(
    gps: list, points: np.ndarray, *, release: bool = False, progress: bool = False
) -> tuple[np.ndarray, np.ndarray]:
    """(mean (m, 3), variance (m, 3)) of the three components at points (m, d); release and
    progress: a tiled GP's (:meth:`~kiseki.gp.TiledGP.predict`)."""
    means, variances = [], []
    for g in gps:
        tiled = isinstance(g, TiledGP)
        m, v = g.predict(points, release=release, progress=progress) if tiled else g.predict(points)
        means.append(np.asarray(m, dtype=np.float64).reshape(len(points), -1))
        variances.append(np.asarray(v, dtype=np.float64).reshape(len(points), -1))
    # eq. 6.9 can fall a rounding error below zero where the data pin the field down
    return np.hstack(means), np.maximum(np.hstack(variances), 0.0)


def evaluate_on_cells(gps: list, centres, total: int, progress: bool):
    """(mean (total, 3), variance (total, 3)) at the cells whose centres ``centres(start,
    stop)`` gives, in chunks sized to the GP (a tqdm bar when `progress`)."""
    if all(isinstance(g, TiledGP) for g in gps):
        # every cell at once, tile by tile, each tile's factor freed once its cells are done:
        # one tile in memory, not all (3.7 GB for 40,000 readings of a floor at l = 0.5 m)
        return predict_all(gps, centres(0, total), release=True, progress=progress)
    mean = np.empty((total, 3))
    var = np.empty((total, 3))
    # the exact GP's cross-covariance has a column per training point, the reduced-rank
    # GP's one per basis function
    training = max(int(getattr(g, "basis_size", getattr(g, "size", 1))) for g in gps)
    chunk = max(1, min(_CHUNK, _CHUNK_ENTRIES // max(training, 1)))
    starts = range(0, total, chunk)
    bar = tqdm(starts, desc="map", unit="chunk", disable=not progress or total <= chunk)
    for start in bar:
        stop = min(start + chunk, total)
        mean[start:stop], var[start:stop] = predict_all(gps, centres(start, stop))
    return mean, var


def fit_component_gps(
    x,
    y,
    kernels,
    method: str,
    *,
    mean: str = "constant",
    domains=None,
    tolerances=None,
    build: bool = True,
) -> list:
    """GPs of the field's three columns: one GP of all three with one kernel, or one GP per
    column with three; exact, reduced-rank ("hilbert": one box (lower, upper) and one
    spectral tolerance a kernel, or each kernel's defaults) or "tiled" (its tiles factorised
    on first use without `build`). With a
    :class:`~kiseki.gp.CurlFreeKernel`, the curl-free GP (reduced-rank: 1,024 functions; not
    tiled)."""
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")
    if isinstance(kernels, CurlFreeKernel):
        if method == "tiled":
            raise ValueError("the curl-free model is not tiled: use exact or hilbert")
        if method == "exact":
            return [CurlFreeGP.fit(x, y, kernels)]
        domain = None if domains is None else domains[0]
        gp = ReducedRankCurlFreeGP.fit(x, y, kernels, basis=CURL_FREE_BASIS, domain=domain)
        return [gp]
    kernels = [kernels] if not isinstance(kernels, (list, tuple)) else list(kernels)
    columns = [slice(0, 3)] if len(kernels) == 1 else [slice(k, k + 1) for k in range(3)]
    pairs = zip(kernels, columns, strict=True)
    if method == "exact":
        return [ExactGP.fit(x, y[:, c], k, mean=mean) for k, c in pairs]
    if method == "tiled":
        return [TiledGP.fit(x, y[:, c], k, mean=mean, build=build) for k, c in pairs]
    domains = [None] * len(kernels) if domains is None else list(domains)
    tolerances = [None] * len(kernels) if tolerances is None else list(tolerances)
    if not len(domains) == len(tolerances) == len(kernels):
        raise ValueError(
            f"{len(domains)} boxes and {len(tolerances)} spectral tolerances for "
            f"{len(kernels)} kernels"
        )
    return [
        HilbertGP.fit(x, y[:, c], k, domain=d, tolerance=t, mean=mean)
        for (k, c), d, t in zip(pairs, domains, tolerances, strict=True)
    ]


def hilbert_settings(gps: list) -> dict | None:
    """What a map keeps of its reduced-rank GPs so that :func:`rebuild` makes the same ones:
    each GP's box and spectral tolerance (a GP per kernel, each on the box its own length
    scale set); None for other GPs."""
    if not all(isinstance(g, HilbertGP) for g in gps):
        return None
    return {
        "domains": [[np.asarray(g.lower).tolist(), np.asarray(g.upper).tolist()] for g in gps],
        "tolerance": [float(g.tolerance) for g in gps],
    }


def predictor_state(gp) -> dict[str, np.ndarray] | None:
    """The arrays a map keeps so that :func:`rebuild` needs no refit: a curl-free GP's
    ``state()``, its triangular factor packed row by row (``factor_lower``, half the bytes);
    None for the independent GPs (rebuilt from the readings)."""
    if isinstance(gp, _CurlFreeField):
        gp = gp.gp
    if not isinstance(gp, _CURL_FREE):
        return None
    state = gp.state()
    factor = state.pop("factor")
    state["factor_lower"] = factor[np.tril_indices(len(factor))]
    return state


def _unpacked(state: Mapping) -> dict[str, np.ndarray]:
    """:func:`predictor_state`'s arrays with the factor square again; a ValueError when the
    packed length is not that of a triangle."""
    out = {k: np.asarray(v) for k, v in state.items() if k != "factor_lower"}
    packed = np.asarray(state["factor_lower"], dtype=np.float64).reshape(-1)
    size = int(round((np.sqrt(8 * len(packed) + 1) - 1) / 2))
    if size * (size + 1) // 2 != len(packed):
        raise ValueError(f"factor_lower has {len(packed)} values: not a triangle's")
    factor = np.zeros((size, size))
    factor[np.tril_indices(size)] = packed
    out["factor"] = factor
    return out


def rebuild(training, kernel) -> list:
    """The GP(s) of a map's stored training data (``TrainingData``) with the stored
    hyperparameters: a curl-free GP from its stored state when the map keeps one, otherwise
    fitted again (no optimisation)."""
    x, y = training.inputs, training.outputs
    state: Mapping | None = training.predictor
    if isinstance(kernel, CurlFreeKernel) and state is not None:
        state = _unpacked(state)
        if training.method == "exact":
            return [_CurlFreeField(CurlFreeGP.from_state(x, y, kernel, state["factor"]))]
        return [_CurlFreeField(ReducedRankCurlFreeGP.from_state(x, y, kernel, **state))]
    hilbert = training.hilbert or {}
    count = len(kernel) if isinstance(kernel, (list, tuple)) else 1
    domains, tolerances = hilbert.get("domains"), hilbert.get("tolerance")
    if domains is None and "domain" in hilbert:  # one box for every GP, as older maps kept
        domains = [hilbert["domain"]] * count
    if training.method == "hilbert" and tolerances is None:
        # a map written before the default followed the kernel (spectral_tolerance): it was
        # fitted at 1e-4, HilbertGP's default then
        tolerances = [1e-4] * count
    # a tiled map factorises only the tiles its predictions reach
    gps = fit_component_gps(
        x,
        y,
        kernel,
        training.method,
        mean=training.mean,
        domains=domains,
        tolerances=tolerances,
        build=False,
    )
    return as_gp_list(gps)
