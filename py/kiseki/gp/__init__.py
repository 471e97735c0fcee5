# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Gaussian-process regression of vector fields (the magnetic-navigation thesis, chapter 6).

* :class:`SquaredExponential`: the kernel sigma_f^2 exp(-|p - q|^2 / (2 l^2)) and noise sigma_n;
* :func:`fit_hyperparameters`: maximum of the log marginal likelihood (eqs. 6.11-6.15), BFGS;
  :func:`refine_hyperparameters` carries a subsample's maximum to every reading;
* :class:`ExactGP`: exact regression (eqs. 6.7-6.9), one factorisation for all field components;
* :class:`HilbertGP`: the reduced-rank approximation for maps of tens of thousands of readings;
* :class:`TiledGP`: a grid of overlapping exact or reduced-rank GPs, for a whole floor;
* :class:`CurlFreeGP`, :class:`ReducedRankCurlFreeGP`: the field as the gradient of a scalar
  potential plus a constant (Solin et al., IEEE T-RO 2018), exact and reduced-rank, in numpy;
  :func:`fit_curl_free_hyperparameters` their :class:`CurlFreeKernel`'s hyperparameters.

The C++ core (``cpp/include/kiseki/gp``) does the work with LAPACK; these classes check inputs
and shape the results.
"""

from kiseki.gp.curl_free import (
    CurlFreeFit,
    CurlFreeGP,
    CurlFreeKernel,
    fit_curl_free_hyperparameters,
)
from kiseki.gp.curl_free_basis import ReducedRankCurlFreeGP
from kiseki.gp.exact import ExactGP
from kiseki.gp.hilbert import HilbertGP, hilbert_basis_size, spectral_tolerance
from kiseki.gp.kernel import (
    HyperparameterFit,
    SquaredExponential,
    fit_hyperparameters,
    refine_hyperparameters,
)
from kiseki.gp.tiled import TiledGP

__all__ = [
    "CurlFreeFit",
    "CurlFreeGP",
    "CurlFreeKernel",
    "ExactGP",
    "HilbertGP",
    "HyperparameterFit",
    "ReducedRankCurlFreeGP",
    "SquaredExponential",
    "TiledGP",
    "fit_curl_free_hyperparameters",
    "fit_hyperparameters",
    "hilbert_basis_size",
    "refine_hyperparameters",
    "spectral_tolerance",
]
