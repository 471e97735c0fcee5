# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The world's magnetic field of a simulated scene (:class:`MagneticWorld`): the Earth's field,
steel as dipoles, rows and lattices of them, a linear gradient and a slow drift, in G in the
world frame (x east, y north, z up). The facts behind it, the units and the frames are in
:mod:`kiseki.sim.magnetic`, which also gathers this module's names and the magnetometer's."""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

import numpy as np

from kiseki._support.real_numbers import check_number
from kiseki._support.schema import parse
from kiseki.sim._values import finite_array as _finite_array
from kiseki.sim._values import points as _points
from kiseki.sim._values import times as _times
from kiseki.sim.dipoles import Dipole, DipoleLine, dipole_field
from kiseki.sim.magnetic_lattice import DipoleLattice
from kiseki.sim.magnetic_schema import EarthAngles, MagneticSection

__all__ = [
    "DEFAULT_DECLINATION_DEG",
    "DEFAULT_DRIFT_AMPLITUDE",
    "DEFAULT_DRIFT_PERIOD",
    "DEFAULT_EARTH_TOTAL",
    "DEFAULT_INCLINATION_DEG",
    "MagneticWorld",
    "default_earth_field",
    "earth_field_from_angles",
]

#: Total intensity of the Earth's field, G (46.5 uT). Assumption: the thesis' experiments were
#: at Utsunomiya and Tsukuba (thesis ch. 5, Tsukuba Challenge), near the JMA Kakioka observatory
#: (36.2 N, 140.2 E); IGRF values there in the 2010s are about 46-47 uT, rounded here.
DEFAULT_EARTH_TOTAL = 0.465
#: Inclination (dip), degrees, positive = field points down. Same source as the total; it lies
#: between the ISEE stations Kagoshima (31.5 N, 45.1 deg) and Moshiri (44.4 N, 58.6 deg).
DEFAULT_INCLINATION_DEG = 49.5
#: Declination, degrees, positive east of true north: magnetic north is about 7.5 deg west
#: of true north in Kanto (same source; ISEE stations: -6.1 to -9.5 deg).
DEFAULT_DECLINATION_DEG = -7.5

#: Temperature-drift amplitude, G. The thesis shows drift (Figs. 2.1-2.4, 10-30 deg C indoors,
#: -3-12 deg C outdoors) but prints no number; it states the drift is much smaller than the
#: steel disturbances. Assumption: of the order of the sensor noise (0.01 G, thesis ch. 6) and
#: of the thesis' disturbance threshold (0.01 G, sec. 3.3.2), i.e. about 2 % of the field, what
#: a magnetoresistive sensor's sensitivity temperature coefficient gives over ~10 deg C.
#: The geomagnetic daily variation itself (~20-50 nT = 2e-4-5e-4 G) is negligible beside it.
DEFAULT_DRIFT_AMPLITUDE = 0.01
#: Drift period, s: one day (the daily temperature cycle). Assumption.
DEFAULT_DRIFT_PERIOD = 86400.0

_TWO_PI = 2.0 * math.pi


def earth_field_from_angles(
    total: float, inclination_deg: float, declination_deg: float
) -> np.ndarray:
    """The Earth's field (3,) in G in the world frame (x east, y north, z up).

    ``total`` G; ``inclination_deg`` positive when the field points down (northern
    hemisphere); ``declination_deg`` positive when magnetic north is east of true north.
    """
    f = check_number(total, "total", 0.0, unit="G")
    inc = math.radians(check_number(inclination_deg, "inclination_deg", -90.0, 90.0, unit="deg"))
    dec = math.radians(check_number(declination_deg, "declination_deg"))
    h = f * math.cos(inc)
    return np.array([h * math.sin(dec), h * math.cos(dec), -f * math.sin(inc)])


def default_earth_field() -> np.ndarray:
    """The default Earth field: 0.465 G, inclination 49.5 deg down, declination -7.5 deg."""
    return earth_field_from_angles(
        DEFAULT_EARTH_TOTAL, DEFAULT_INCLINATION_DEG, DEFAULT_DECLINATION_DEG
    )


class MagneticWorld:
    """The magnetic field of a scene, in G in the world frame (x east, y north, z up).

    ``B(p, t) = earth_field + G (p - gradient_origin) + sum of dipoles, lines, lattices + drift(t)``

    * ``earth_field`` (3,) G; default :func:`default_earth_field`.
    * ``dipoles``, ``lines``, ``lattices``: steel (a
      :class:`~kiseki.sim.magnetic_lattice.DipoleLattice` is a slab's or a wall's rebar as a
      seeded random lattice). Scale: a moment of m A m^2 at r m gives 1e-3 m / r^3 to
      2e-3 m / r^3 G, so a disturbance that stands well above the thesis' 0.01 G threshold at
      0.5-1 m (a buried pipe is at least 0.2 m from the sensor, sec. 2.4) needs m of order
      1-10 A m^2.
    * ``gradient`` (3, 3) G/m, ``gradient[i, j] = dB_i / dx_j``, about ``gradient_origin``:
      the slow cross-track slopes of thesis Fig. 2.8. A source-free static field has a
      symmetric, traceless gradient; that is not enforced, so a scene may use a one-component
      slope (e.g. only dBz/dy) as the thesis' figures show.
    * drift: ``drift_amplitude * sin(2 pi t / drift_period + drift_phase) * u``, uniform in
      space, with ``u`` the Earth field's direction (a temperature-dependent change of the
      sensor's scale factor acts along the field it measures). Deterministic, bounded by
      ``drift_amplitude`` and slow: its rate is at most ``2 pi A / P`` (7e-7 G/s with the
      defaults 0.01 G and one day, see :data:`DEFAULT_DRIFT_AMPLITUDE`).
    """

    def __init__(
        self,
        earth_field: Any = None,
        dipoles: Iterable[Dipole] = (),
        lines: Iterable[DipoleLine] = (),
        gradient: Any = None,
        gradient_origin: Any = (0.0, 0.0, 0.0),
        drift_amplitude: float = DEFAULT_DRIFT_AMPLITUDE,
        drift_period: float = DEFAULT_DRIFT_PERIOD,
        drift_phase: float = 0.0,
        lattices: Iterable[Any] = (),
    ) -> None:
        self.earth_field = (
            default_earth_field()
            if earth_field is None
            else _finite_array(earth_field, (3,), "earth_field")
        )
        self.dipoles: tuple[Dipole, ...] = tuple(dipoles)
        self.lines: tuple[DipoleLine, ...] = tuple(lines)
        for d in self.dipoles:
            if not isinstance(d, Dipole):
                raise ValueError(f"dipoles: expected Dipole objects, got {d!r}")
        for line in self.lines:
            if not isinstance(line, DipoleLine):
                raise ValueError(f"lines: expected DipoleLine objects, got {line!r}")
        self.lattices: tuple[DipoleLattice, ...] = tuple(lattices)
        for lattice in self.lattices:
            if not isinstance(lattice, DipoleLattice):
                raise ValueError(f"lattices: expected DipoleLattice objects, got {lattice!r}")
        self.gradient = (
            np.zeros((3, 3)) if gradient is None else _finite_array(gradient, (3, 3), "gradient")
        )
        self.gradient_origin = _finite_array(gradient_origin, (3,), "gradient_origin")
        self.drift_amplitude = check_number(drift_amplitude, "drift_amplitude", 0.0, unit="G")
        self.drift_period = check_number(drift_period, "drift_period", 0.0, low_open=True, unit="s")
        self.drift_phase = check_number(drift_phase, "drift_phase")
        norm = float(np.linalg.norm(self.earth_field))
        self.drift_direction = self.earth_field / norm if norm > 0 else np.array([0.0, 0.0, -1.0])
        spread = (*self.lines, *self.lattices)
        pos = [d.position[None] for d in self.dipoles] + [s.positions for s in spread]
        mom = [d.moment[None] for d in self.dipoles] + [s.moments for s in spread]
        rad = [np.array([d.radius]) for d in self.dipoles] + [
            np.full(len(s.positions), s.radius) for s in spread
        ]
        self._positions = np.concatenate(pos) if pos else np.zeros((0, 3))
        self._moments = np.concatenate(mom) if mom else np.zeros((0, 3))
        self._radii = np.concatenate(rad) if rad else np.zeros(0)

    def drift(self, t: Any) -> np.ndarray:
        """Drift (3,) G at time ``t`` s, or (n, 3) for (n,) times."""
        ts = np.asarray(t, dtype=float)
        if not np.all(np.isfinite(ts)):
            raise ValueError(f"t: must be finite, got {t!r}")
        s = self.drift_amplitude * np.sin(_TWO_PI * ts / self.drift_period + self.drift_phase)
        return s[..., None] * self.drift_direction

    def static_field_at(self, points: Any) -> np.ndarray:
        """Field without the drift, (n, 3) G at (n, 3) points (or (3,) at one point)."""
        p, single = _points(points)
        b = self.earth_field + (p - self.gradient_origin) @ self.gradient.T
        b = b + dipole_field(p, self._positions, self._moments, self._radii)
        return b[0] if single else b

    def field_at(self, points: Any, t: Any = 0.0) -> np.ndarray:
        """Field (n, 3) G at (n, 3) world points and time ``t`` s (scalar or (n,)).

        One (3,) point gives one (3,) field.
        """
        p, single = _points(points)
        ts = _times(t, p.shape[0], "t")
        b = self.static_field_at(p) + self.drift(ts)
        return b[0] if single else b

    def to_dict(self) -> dict[str, Any]:
        """The scene mapping :meth:`from_dict` reads back."""
        return {
            "earth_field": self.earth_field.tolist(),
            "dipoles": [
                {"position": d.position.tolist(), "moment": d.moment.tolist(), "radius": d.radius}
                for d in self.dipoles
            ],
            "lines": [
                {
                    "start": ln.start.tolist(),
                    "end": ln.end.tolist(),
                    "moment_per_metre": ln.moment_per_metre.tolist(),
                    "spacing": ln.spacing,
                    "radius": ln.radius,
                }
                for ln in self.lines
            ],
            "lattices": [lattice.to_dict() for lattice in self.lattices],
            "gradient": self.gradient.tolist(),
            "gradient_origin": self.gradient_origin.tolist(),
            "drift": {
                "amplitude": self.drift_amplitude,
                "period": self.drift_period,
                "phase": self.drift_phase,
            },
        }

    @classmethod
    def from_dict(
        cls,
        d: Mapping[str, Any],
        source: str = "<scene>",
        at: Sequence[str | int] = (),
        variant: str = "teach",
    ) -> MagneticWorld:
        """Build from a scene file's ``magnetic:`` mapping, checked by
        :class:`kiseki.sim.magnetic_schema.MagneticSection`; every key is optional (defaults as
        the constructor). ``earth_field``: ``[x, y, z]`` G, or ``{total, inclination_deg,
        declination_deg?}``; ``dipoles``: ``[{position, moment, radius?}]``; ``lines``:
        ``[{start, end, moment_per_metre, spacing?, radius?}]``; ``lattices``:
        ``[{lower, upper, spacing, moment_sd, moment_mean?, seed?, radius?}]`` (see
        :class:`~kiseki.sim.magnetic_lattice.DipoleLattice`); ``gradient``: 3x3 G/m;
        ``gradient_origin``: ``[x, y, z]``; ``drift``: ``{amplitude?, period?, phase?}``.
        Unknown keys, wrong shapes, non-numbers, NaN, out-of-range values and sections with
        too many dipoles raise a SchemaError (a ValueError) naming ``source``, the key path
        (after ``at``, e.g. ``("magnetic",)``) and the value. ``variant`` (``teach`` or
        ``playback``, as :func:`kiseki.sim.scene.load_scene`'s) keeps the sources marked
        ``only_in`` that variant and drops those marked with the other one."""
        if variant not in ("teach", "playback"):
            raise ValueError(f"{source}: variant must be teach or playback, got {variant!r}")
        spec = parse(MagneticSection, d, source, at=at)
        given = spec.model_fields_set

        def here(items: Iterable[Any]) -> list[Any]:
            return [x for x in items if x.only_in is None or x.only_in == variant]

        kwargs: dict[str, Any] = {
            "dipoles": [Dipole(x.position, x.moment, x.radius) for x in here(spec.dipoles)],
            "lines": [
                DipoleLine(x.start, x.end, x.moment_per_metre, x.spacing, x.radius)
                for x in here(spec.lines)
            ],
            "lattices": [
                DipoleLattice(
                    x.lower, x.upper, x.spacing, x.moment_sd, x.moment_mean, x.seed, x.radius
                )
                for x in here(spec.lattices)
            ],
        }
        earth = spec.earth_field
        if isinstance(earth, EarthAngles):
            earth = earth_field_from_angles(
                earth.total, earth.inclination_deg, earth.declination_deg
            )
        if "earth_field" in given:
            kwargs["earth_field"] = earth
        for key in ("gradient", "gradient_origin"):
            if key in given:
                kwargs[key] = np.array(getattr(spec, key), dtype=float)
        for key in spec.drift.model_fields_set:
            kwargs[f"drift_{key}"] = getattr(spec.drift, key)
        return cls(**kwargs)
