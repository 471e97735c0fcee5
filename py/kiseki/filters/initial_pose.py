# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The checks of a particle filter's start (:meth:`kiseki.filters.MonteCarloLocalizer.initialize`
and :meth:`~kiseki.filters.MonteCarloLocalizer.initialize_particles`): a pose, a spread or a
particle beyond ``POSE_LIMIT`` is refused naming it. Standard deviations of 1e300 m gave particles
1e299 m away without a word, and every model weighing them then overflowed (numpy warnings,
NaN agreements)."""

from __future__ import annotations

import numbers

import numpy as np

from kiseki._support.schema import MAGNITUDE_LIMIT

__all__ = ["POSE_LIMIT", "check_particles", "check_spread", "check_start"]

POSE_LIMIT = MAGNITUDE_LIMIT
"""The largest magnitude of a start's x, y (m) and theta (rad), of its standard deviations and
of a particle's coordinates: kiseki's bound for positions in files (1e9 m, beyond the Moon), so
that squares and products of them stay finite in the models that weigh the particles."""


def _numbers(value) -> np.ndarray | None:
    """``value`` as a float array when it holds real numbers only (no bool, no string), else
    None."""
    items = np.asarray(value, dtype=object)
    if items.ndim == 0 or not all(
        isinstance(v, numbers.Real) and not isinstance(v, bool | np.bool_) for v in items.flat
    ):
        return None
    return items.astype(float)


def check_start(pose, sd) -> tuple[np.ndarray, np.ndarray]:
    """The (x, y, theta) start and its (x, y, theta) standard deviations as float arrays, each
    checked: finite, within +-POSE_LIMIT, the deviations >= 0."""
    p, s = np.shape(np.asarray(pose, dtype=object)), np.shape(np.asarray(sd, dtype=object))
    if p != (3,) or s != (3,):  # (x, y) was taken with theta = 0
        raise ValueError(f"initialize: pose and sd must be (x, y, theta) triples, got {p}, {s}")
    start = _numbers(pose)
    if start is None or not np.all(np.abs(start) <= POSE_LIMIT):
        raise ValueError(
            f"initialize: pose must be 3 numbers within +-{POSE_LIMIT:g} (m, m, rad), got {pose!r}"
        )
    return start, check_spread("initialize: sd", sd)


def check_spread(name: str, sd) -> np.ndarray:
    """A start's (x, y, theta) standard deviations as a float array: 3 numbers in [0,
    POSE_LIMIT], refused naming ``name`` otherwise (the configs that hold one check it here,
    where it is given, not when the run starts)."""
    spread = _numbers(sd) if np.shape(np.asarray(sd, dtype=object)) == (3,) else None
    if spread is None or not np.all((spread >= 0) & (spread <= POSE_LIMIT)):
        raise ValueError(f"{name} must be 3 numbers in [0, {POSE_LIMIT:g}] (m, m, rad), got {sd!r}")
    return spread


def check_particles(poses, weights) -> tuple[np.ndarray, np.ndarray | None]:
    """Particle poses (n, 3), each coordinate finite and within +-POSE_LIMIT, and their weights
    (n,) finite, >= 0 and not all 0, scaled to a largest of 1 (1e308 each overflowed their sum,
    which was then said to be 0), or None (equal weights)."""
    try:
        p = np.asarray(poses, dtype=float)
    except (TypeError, ValueError):
        raise ValueError("initialize_particles: poses must be numbers, an (n, 3) array") from None
    if p.ndim != 2 or p.shape[1:] != (3,) or len(p) == 0:
        raise ValueError(
            f"initialize_particles: poses must be an (n, 3) array, n >= 1, got shape {p.shape}"
        )
    bad = ~(np.abs(p) <= POSE_LIMIT).all(axis=1)
    if bad.any():
        row = int(np.argmax(bad))
        raise ValueError(
            f"initialize_particles: poses must be finite and within +-{POSE_LIMIT:g} (m, m, rad), "
            f"row {row} is {p[row].tolist()}"
        )
    if weights is None:
        return p, None
    try:
        w = np.asarray(weights, dtype=float)
    except (TypeError, ValueError):
        w = np.full(0, np.nan)  # not numbers: refused below by its shape
    if w.shape != (len(p),) or not np.all((w >= 0) & (w < np.inf)) or not w.max() > 0:
        raise ValueError(
            f"initialize_particles: weights must be {len(p)} finite numbers >= 0 (one per pose), "
            f"not all 0, got {np.array2string(w, threshold=6)}"
        )
    return p, w / w.max()
