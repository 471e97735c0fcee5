# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Scan registration baselines for the rubble paper's search, on the same scan pairs: PCL's
ICP (point to point) and GICP (plane to plane), through kiseki's core
(``kiseki/terrain/pcl_registration.hpp``)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from kiseki import _core
from kiseki._support.counts import check_count

__all__ = ["Registration", "register_pcl"]


@dataclass(frozen=True)
class Registration:
    """The transform (4x4) that maps the source points onto the target, whether PCL reports
    convergence, and its fitness (mean squared distance of matched pairs, m^2)."""

    transform: np.ndarray
    converged: bool
    fitness: float


def register_pcl(
    source: Any,
    target: Any,
    initial: Any = None,
    method: Literal["icp", "gicp"] = "gicp",
    max_correspondence: float = 0.5,
    max_iterations: int = 50,
) -> Registration:
    """Aligns source (n, 3) to target (m, 3) from ``initial`` (4x4 rigid motion; None:
    identity). Raises ValueError for NaN points, points beyond +-1e6 m, fewer than 10 points, a
    guess that is not a rigid motion or bad parameters."""
    max_iterations = check_count(max_iterations, "max_iterations", 1, 100_000)
    guess = np.eye(4) if initial is None else np.asarray(initial, dtype=float)
    if (
        guess.shape == (4, 4)
        and np.isfinite(guess).all()
        and not np.array_equal(guess[3], [0, 0, 0, 1])
    ):
        raise ValueError(f"initial: a rigid motion's last row is 0 0 0 1, got {guess[3].tolist()}")
    m, ok, fit = _core.register_pcl(
        source, target, guess, method, float(max_correspondence), int(max_iterations)
    )
    return Registration(np.asarray(m), bool(ok), float(fit))
