# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Core types: planar and 3-D poses, angle normalisation, the seeded random generator and
the seed check.

``Random`` is the one generator every stochastic part of kiseki uses: the engine is
mt19937_64 and the distributions are kiseki's own, so a seed gives the same numbers on every
platform. ``derive_seed(seed, k)`` gives stream ``k`` of a seed (per trial, robot or sensor).
"""

from __future__ import annotations

import math
import numbers

import numpy as np

from kiseki._core import Pose2, Pose3, Random, derive_seed, library_versions, normalize_angle

__all__ = [
    "Pose2",
    "Pose3",
    "Random",
    "SEED_RULE",
    "check_seed",
    "derive_seed",
    "library_versions",
    "normalize_angle",
    "rotation_zyx",
]


SEED_RULE = "must be an integer in [0, 2**64)"
"""What a seed is, as every seed error words it (numpy's and the C++ core's 64-bit generators
take any such integer)."""


def check_seed(seed, name: str = "seed") -> int:
    """A seed as kiseki takes it: an integer in [0, 2**64) (numpy integers too); anything else
    a ValueError ``"NAME must be an integer in [0, 2**64), got X"``. The one seed check: the
    file models' ``Seed`` (:mod:`kiseki._support.schema`) words its problem with
    :data:`SEED_RULE`."""

    if isinstance(seed, bool) or not isinstance(seed, numbers.Integral) or not 0 <= seed < 2**64:
        raise ValueError(f"{name} {SEED_RULE}, got {seed!r}")
    return int(seed)


def rotation_zyx(yaw: float, pitch: float = 0.0, roll: float = 0.0) -> np.ndarray:
    """Rz(yaw) Ry(pitch) Rx(roll), radians: the 3-D attitude convention of kiseki (the
    simulator's bodies and sensors, the gyro's attitude in the terrain area)."""
    cz, sz, cy, sy, cx, sx = (f(a) for a in (yaw, pitch, roll) for f in (math.cos, math.sin))
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    return rz @ ry @ rx
