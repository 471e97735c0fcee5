# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Checks of the numbers the simulator's magnetic models take (points, poses, times), shared by
kiseki.sim.magnetic_world, magnetometer, dipoles, magnetic_arm and magnetic_lattice."""

from __future__ import annotations

from typing import Any

import numpy as np


def float_array(value: Any, name: str) -> np.ndarray:
    try:
        return np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name}: expected numbers, got {value!r}") from exc


def finite_array(value: Any, shape: tuple[int | None, ...], name: str) -> np.ndarray:
    """``value`` as a float array of ``shape`` (None = any length), finite, or ValueError."""
    a = float_array(value, name)
    if a.ndim != len(shape) or any(
        s is not None and s != d for s, d in zip(shape, a.shape, strict=True)
    ):
        want = "x".join("n" if s is None else str(s) for s in shape) or "a scalar"
        raise ValueError(f"{name}: expected shape ({want}), got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name}: must be finite, got {value!r}")
    return a


def points(points: Any, name: str = "points") -> tuple[np.ndarray, bool]:
    """Points as (n, 3) and whether a single (3,) point was given."""
    a = float_array(points, name)
    single = a.shape == (3,)
    a = finite_array(a.reshape(1, 3) if single else a, (None, 3), name)
    return a, single


def poses(poses: Any, name: str = "poses") -> tuple[np.ndarray, bool]:
    """Planar poses as (n, 3) rows (x, y, theta) and whether a single pose was given."""
    if hasattr(poses, "to_array") and not isinstance(poses, np.ndarray):
        poses = poses.to_array()  # kiseki.core.Pose2
    a = float_array(poses, name)
    single = a.shape == (3,)
    a = finite_array(a.reshape(1, 3) if single else a, (None, 3), name)
    return a, single


def times(times: Any, n: int, name: str = "times") -> np.ndarray:
    t = float_array(times, name)
    if t.ndim == 0:
        t = np.full(n, float(t))
    t = finite_array(t, (n,), name)
    return t


# --------------------------------------------------------------------------------------------
# dipoles
