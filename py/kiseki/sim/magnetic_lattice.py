# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Steel spread through a slab or a wall (rebar mesh, steel deck) as a seeded random lattice of
point dipoles.

A uniformly magnetised mesh of bars at pitch ``a`` hardly changes the field at a distance ``D``
from it: its periodic part decays as ``exp(-2 pi D / a)`` (a 0.2 m pitch seen from 0.2 m: 0.2 %).
What a sensor sees is the mesh's *non-uniform* magnetisation: bar ends, laps, welds, bars of
different remanence. :class:`DipoleLattice` models that part statistically: one dipole per cell of
``spacing`` over an axis-aligned box (a plane when one side is flat), each with a moment drawn
from ``N(moment_mean, moment_sd^2)`` per component by :class:`kiseki.core.Random` (``seed``), so
a scene file states a whole floor's steel in one line and rebuilds it exactly.

Seen from distance ``D``, neighbouring cells' fields overlap when ``spacing <~ D``, and the field
is then a random field whose correlation length is of the order of ``D``: the depth of the steel
sets the spatial scale of the disturbance (thesis ch. 6 finds a GP length scale of 0.47 m).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from kiseki._support.real_numbers import check_number
from kiseki.core import Random, check_seed
from kiseki.sim._values import finite_array as _finite_array
from kiseki.sim._values import points as _points
from kiseki.sim.dipoles import dipole_field

__all__ = ["MAX_LATTICE_DIPOLES", "DipoleLattice"]

#: At most this many dipoles in one lattice: the field costs (points x dipoles), and 50,000
#: dipoles is a 500 m x 25 m slab at 0.25 m.
MAX_LATTICE_DIPOLES = 50_000


@dataclass(frozen=True, eq=False)
class DipoleLattice:
    """Dipoles at the centres of the ``spacing`` cells of the box ``lower``..``upper`` (m, world
    frame); a side with ``upper == lower`` is flat (one layer: a slab or a wall plane).

    A side of length ``L > 0`` holds ``max(1, round(L / spacing))`` cells of equal size. Moments
    (A m^2) are ``moment_mean + moment_sd * n`` with ``n`` standard normals drawn in row order
    (dipole by dipole, x, y, z) from ``Random(seed)``. ``radius`` (default ``spacing / 2``)
    guards each dipole's singularity as in :class:`kiseki.sim.dipoles.DipoleLine`.
    """

    lower: np.ndarray
    upper: np.ndarray
    spacing: float
    moment_sd: np.ndarray
    moment_mean: np.ndarray = field(default_factory=lambda: np.zeros(3))
    seed: int = 0
    radius: float | None = None
    positions: np.ndarray = field(init=False, repr=False)
    moments: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        lo = _finite_array(self.lower, (3,), "lower")
        hi = _finite_array(self.upper, (3,), "upper")
        if np.any(hi < lo):
            raise ValueError(f"upper: must be >= lower in x, y and z, got {hi} < {lo}")
        spacing = check_number(self.spacing, "spacing", 0.0, low_open=True, unit="m")
        sd = _finite_array(self.moment_sd, (3,), "moment_sd")
        if np.any(sd < 0):
            raise ValueError(f"moment_sd: must be >= 0, got {sd}")
        mean = _finite_array(self.moment_mean, (3,), "moment_mean")
        seed = check_seed(self.seed, "seed:")
        radius = spacing / 2 if self.radius is None else self.radius
        radius = check_number(radius, "radius", 0.0, low_open=True, unit="m")
        extent = hi - lo
        counts = [max(1, round(e / spacing)) if e > 0 else 1 for e in extent]
        total = int(np.prod(counts))
        if total > MAX_LATTICE_DIPOLES:
            raise ValueError(
                f"spacing: {spacing} m gives {total} dipoles over {extent} m, more than "
                f"{MAX_LATTICE_DIPOLES:,}"
            )
        axes = [
            lo[c] + (np.arange(n) + 0.5) * extent[c] / n if extent[c] > 0 else np.array([lo[c]])
            for c, n in enumerate(counts)
        ]
        gx, gy, gz = np.meshgrid(*axes, indexing="ij")
        positions = np.column_stack([gx.ravel(), gy.ravel(), gz.ravel()])
        normals = Random(seed).normal(0.0, 1.0, 3 * total).reshape(total, 3)
        for key, value in (
            ("lower", lo),
            ("upper", hi),
            ("spacing", spacing),
            ("moment_sd", sd),
            ("moment_mean", mean),
            ("seed", seed),
            ("radius", radius),
            ("positions", positions),
            ("moments", mean + sd * normals),
        ):
            object.__setattr__(self, key, value)

    def to_dict(self) -> dict[str, Any]:
        """The scene mapping that rebuilds this lattice (its moments come from the seed)."""
        return {
            "lower": self.lower.tolist(),
            "upper": self.upper.tolist(),
            "spacing": self.spacing,
            "moment_sd": self.moment_sd.tolist(),
            "moment_mean": self.moment_mean.tolist(),
            "seed": self.seed,
            "radius": self.radius,
        }

    def field_at(self, points: Any) -> np.ndarray:
        """Field in G at (n, 3) world points (or one (3,) point)."""
        p, single = _points(points)
        b = dipole_field(p, self.positions, self.moments, self.radius)
        return b[0] if single else b
