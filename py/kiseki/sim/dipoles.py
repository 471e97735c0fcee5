# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Steel as permanent magnetic dipoles: the closed-form field of point dipoles
(:func:`dipole_field`), one dipole (:class:`Dipole`) and a row of them (:class:`DipoleLine`).

The sources that :class:`kiseki.sim.magnetic.MagneticWorld` sums and that
:class:`kiseki.sim.magnetic_lattice.DipoleLattice` spreads through a slab both build on this
module (it imports neither). Units: gauss for fields, metres, A m^2 for moments.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from kiseki._support.real_numbers import check_number
from kiseki.sim._values import finite_array as _finite_array
from kiseki.sim._values import points as _points

__all__ = ["DEFAULT_DIPOLE_RADIUS", "MU0_OVER_4PI_GAUSS", "Dipole", "DipoleLine", "dipole_field"]

#: mu0 / (4 pi) in G m / A: 1e-7 T m / A (exact in the pre-2019 SI, 1e-10 relative off since)
#: times 1e4 G / T. A moment of m A m^2 at r metres gives fields of order 1e-3 m / r^3 G.
MU0_OVER_4PI_GAUSS = 1e-3

#: Default radius of the uniformly magnetised sphere a :class:`Dipole` stands for, m.
DEFAULT_DIPOLE_RADIUS = 0.02


def dipole_field(points: Any, positions: Any, moments: Any, radii: Any) -> np.ndarray:
    """Field in G at ``points`` (n, 3) of dipoles at ``positions`` (k, 3) with ``moments``
    (k, 3) A m^2, summed over the dipoles.

    Outside radius ``radii[j]`` of dipole j this is the closed form
    ``B = mu0/(4 pi) (3 (m . r_hat) r_hat - m) / |r|^3`` (Jackson, Classical Electrodynamics,
    eq. 5.56). Inside it, the source is taken to be a uniformly magnetised sphere of that radius
    (whose outside field is exactly the dipole field), so the field there is the sphere's uniform
    interior field ``mu0/(4 pi) 2 m / R^3`` (Jackson eq. 5.104): bounded, and equal to the
    on-axis outside field at the surface. This guards the 1/r^3 singularity.
    """
    p, _ = _points(points)
    q = np.asarray(positions, dtype=float).reshape(-1, 3)
    m = np.asarray(moments, dtype=float).reshape(-1, 3)
    rad = np.broadcast_to(np.asarray(radii, dtype=float), (q.shape[0],))
    out = np.zeros_like(p)
    k = q.shape[0]
    if k == 0 or p.shape[0] == 0:
        return out
    block = max(1, 250_000 // k)  # bounds the (block, k) temporaries to ~2 MB each
    inside_field = 2.0 * m / rad[:, None] ** 3  # (k, 3)
    rad2 = rad**2
    for start in range(0, p.shape[0], block):
        pb = p[start : start + block]
        r = [pb[:, c : c + 1] - q[:, c] for c in range(3)]  # components of p - q, (b, k) each
        d2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2]
        inside = d2 < rad2
        any_inside = bool(inside.any())
        inv2 = 1.0 / (np.where(inside, 1.0, d2) if any_inside else d2)
        inv3 = inv2 * np.sqrt(inv2)  # 1 / |r|^3
        mr3 = (r[0] * m[:, 0] + r[1] * m[:, 1] + r[2] * m[:, 2]) * (3.0 * inv2)  # 3 (m.r) / r^2
        for c in range(3):
            b = (mr3 * r[c] - m[:, c]) * inv3
            if any_inside:
                b = np.where(inside, inside_field[:, c], b)
            out[start : start + block, c] = b.sum(axis=1)
    return MU0_OVER_4PI_GAUSS * out


@dataclass(frozen=True, eq=False)
class Dipole:
    """A permanent point dipole: a piece of steel, a motor, a battery.

    ``position`` (3,) m and ``moment`` (3,) A m^2 in the frame of whoever holds it (the world
    for :class:`kiseki.sim.magnetic.MagneticWorld`, the body for a
    :class:`kiseki.sim.magnetic.Magnetometer`'s self-sources).
    ``radius`` m: inside it the source is a uniformly magnetised sphere (see
    :func:`dipole_field`); default 0.02 m, an assumption (the size of a small motor).
    """

    position: np.ndarray
    moment: np.ndarray
    radius: float = DEFAULT_DIPOLE_RADIUS

    def __post_init__(self) -> None:
        object.__setattr__(self, "position", _finite_array(self.position, (3,), "position"))
        object.__setattr__(self, "moment", _finite_array(self.moment, (3,), "moment"))
        r = check_number(self.radius, "radius", 0.0, low_open=True, unit="m")
        object.__setattr__(self, "radius", r)

    def field_at(self, points: Any) -> np.ndarray:
        """Field in G at (n, 3) points (or one (3,) point) in the holder's frame."""
        p, single = _points(points)
        b = dipole_field(p, self.position, self.moment, self.radius)
        return b[0] if single else b


@dataclass(frozen=True, eq=False)
class DipoleLine:
    """A steel beam, pipe or rebar from ``start`` to ``end`` (m) as a row of point dipoles.

    The segment is cut into ``N = max(1, round(L / spacing))`` equal pieces; piece i is a dipole
    at its midpoint ``start + (i + 1/2) (end - start) / N`` with moment
    ``moment_per_metre * L / N`` (A m^2), so the total moment is ``moment_per_metre * L``
    (midpoint rule for a uniformly magnetised line). Sensors more than about one ``spacing``
    away see a smooth line; closer they see the individual dipoles. ``radius`` (default
    ``spacing / 2``, neighbouring spheres touching) guards each dipole's singularity.
    """

    start: np.ndarray
    end: np.ndarray
    moment_per_metre: np.ndarray
    spacing: float = 0.1
    radius: float | None = None
    positions: np.ndarray = field(init=False, repr=False)
    moments: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        a = _finite_array(self.start, (3,), "start")
        b = _finite_array(self.end, (3,), "end")
        mpm = _finite_array(self.moment_per_metre, (3,), "moment_per_metre")
        spacing = check_number(self.spacing, "spacing", 0.0, low_open=True, unit="m")
        length = float(np.linalg.norm(b - a))
        if length == 0.0:
            raise ValueError("DipoleLine: start and end coincide (zero length)")
        radius = spacing / 2 if self.radius is None else self.radius
        radius = check_number(radius, "radius", 0.0, low_open=True, unit="m")
        n = max(1, round(length / spacing))
        frac = (np.arange(n) + 0.5) / n
        object.__setattr__(self, "start", a)
        object.__setattr__(self, "end", b)
        object.__setattr__(self, "moment_per_metre", mpm)
        object.__setattr__(self, "spacing", spacing)
        object.__setattr__(self, "radius", radius)
        object.__setattr__(self, "positions", a + frac[:, None] * (b - a))
        object.__setattr__(self, "moments", np.tile(mpm * (length / n), (n, 1)))

    @property
    def length(self) -> float:
        return float(np.linalg.norm(self.end - self.start))

    def dipoles(self) -> list[Dipole]:
        """The line's point dipoles."""
        return [
            Dipole(p, m, self.radius) for p, m in zip(self.positions, self.moments, strict=True)
        ]

    def field_at(self, points: Any) -> np.ndarray:
        """Field in G at (n, 3) points (or one (3,) point)."""
        p, single = _points(points)
        b = dipole_field(p, self.positions, self.moments, self.radius)
        return b[0] if single else b
