# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The model of a scene file's ``magnetic:`` section (read by
:meth:`kiseki.sim.magnetic.MagneticWorld.from_dict`); every key is optional::

    magnetic:
      earth_field: [0.0, 0.3, -0.35]       # G, or {total, inclination_deg, declination_deg?}
      dipoles:                             # steel as point dipoles, A m^2
        - {position: [1, 2, -0.5], moment: [0, 0, 3], radius: 0.02}
      lines:                               # beams, pipes: rows of dipoles every `spacing` m
        - {start: [0, 0, -1], end: [5, 0, -1], moment_per_metre: [0, 1, 0], spacing: 0.1}
      lattices:                            # rebar: a seeded random lattice over a box
        - {lower: [0, 0, -0.2], upper: [10, 5, -0.2], spacing: 0.25, moment_sd: [1, 1, 1]}
      gradient: [[0, 0, 0], [0, 0, 0.02], [0, 0.02, 0]]   # G/m, dB_i / dx_j
      gradient_origin: [0, 0, 0]
      drift: {amplitude: 0.01, period: 86400, phase: 0}

A dipole, line or lattice may carry ``only_in: teach`` or ``only_in: playback``, as a scene's
objects do: the source is then in that variant's field only (steel added or moved after
teaching, the time-varying field of the thesis' Table 4.2).

What sizes time is limited, the limit in the message: a line's dipoles (its length over its
spacing, :data:`MAX_LINE_DIPOLES`), a lattice's (its volume over spacing^3,
:data:`~kiseki.sim.magnetic_lattice.MAX_LATTICE_DIPOLES`) and the whole section's
(:data:`MAX_WORLD_DIPOLES`: every field evaluation costs points x dipoles). A problem is one line
naming the file, the key path and the value (``scene.yaml: magnetic.lines[2].spacing: ...``)."""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal, Union

from pydantic import (
    BeforeValidator,
    Discriminator,
    Field,
    Tag,
    ValidationInfo,
    field_validator,
    model_validator,
)

from kiseki._support.schema import FileModel, FiniteFloat, NonNegativeFloat, PositiveFloat, Seed
from kiseki.sim.magnetic_lattice import MAX_LATTICE_DIPOLES

__all__ = [
    "MAX_LINE_DIPOLES",
    "MAX_WORLD_DIPOLES",
    "ArmSpec",
    "DipoleSpec",
    "EarthAngles",
    "LatticeSpec",
    "LineSpec",
    "MagneticSection",
    "line_dipoles",
    "lattice_dipoles",
]

#: At most this many dipoles in one line (its length / spacing), as many as in one lattice.
MAX_LINE_DIPOLES = 50_000
#: At most this many dipoles in a scene's field (point dipoles, lines' and lattices' dipoles
#: together): a field evaluation costs points x dipoles. The thesis' floor has 4,454.
MAX_WORLD_DIPOLES = 200_000


def _vector(value: Any) -> Any:
    if not isinstance(value, list | tuple) or len(value) != 3:
        raise ValueError("must be a list of 3 numbers [x, y, z]")
    return value


def _matrix(value: Any) -> Any:
    if not isinstance(value, list | tuple) or len(value) != 3:
        raise ValueError("must be a 3 x 3 list of lists (rows)")
    return value


Vector = Annotated[tuple[FiniteFloat, FiniteFloat, FiniteFloat], BeforeValidator(_vector)]
NonNegativeVector = Annotated[
    tuple[NonNegativeFloat, NonNegativeFloat, NonNegativeFloat], BeforeValidator(_vector)
]
Matrix = Annotated[tuple[Vector, Vector, Vector], BeforeValidator(_matrix)]


def _pair(value: Any) -> Any:
    if not isinstance(value, list | tuple) or len(value) != 2:
        raise ValueError("must be a list of 2 numbers [low, high]")
    return value


Pair = Annotated[tuple[FiniteFloat, FiniteFloat], BeforeValidator(_pair)]
Inclination = Annotated[float, Field(strict=True, ge=-90, le=90, allow_inf_nan=False)]
#: The variant a source is in (None: both), as a scene object's ``only_in``.
OnlyIn = Literal["teach", "playback"] | None


class _Section(FileModel):
    """A mapping of its model's keys (a list or a number is named as such)."""

    @model_validator(mode="before")
    @classmethod
    def _is_mapping(cls, value: Any) -> Any:
        if not isinstance(value, dict):
            raise ValueError(f"must be a mapping of {', '.join(cls.model_fields)}")
        return value


class EarthAngles(_Section):
    """The Earth's field by its total (G) and angles (degrees; inclination positive down,
    declination positive east of true north)."""

    total: NonNegativeFloat
    inclination_deg: Inclination
    declination_deg: FiniteFloat = 0.0


def _earth_form(value: Any) -> str:
    return "function-angles" if isinstance(value, dict) else "function-vector"


# The tags start with "function-" so that kiseki._support.schema leaves them out of the key path.
EarthField = Annotated[
    Union[  # noqa: UP007 (tagged members)
        Annotated[Vector, Tag("function-vector")],
        Annotated[EarthAngles, Tag("function-angles")],
    ],
    Discriminator(_earth_form),
]


class DipoleSpec(_Section):
    """A point dipole (:class:`kiseki.sim.magnetic.Dipole`)."""

    position: Vector
    moment: Vector
    radius: PositiveFloat = 0.02  # kiseki.sim.magnetic.DEFAULT_DIPOLE_RADIUS
    only_in: OnlyIn = None


def line_dipoles(length: float, spacing: float) -> int:
    """The dipoles of a line of ``length`` m cut every ``spacing`` m (DipoleLine's rule)."""
    return max(1, round(length / spacing))


def lattice_dipoles(lower: Any, upper: Any, spacing: float) -> int:
    """The dipoles of a lattice over the box ``lower``..``upper`` (DipoleLattice's rule)."""
    sides = zip(lower, upper, strict=True)
    counts = [max(1, round((hi - lo) / spacing)) if hi > lo else 1 for lo, hi in sides]
    return math.prod(counts)


class LineSpec(_Section):
    """A row of dipoles from ``start`` to ``end`` (:class:`kiseki.sim.magnetic.DipoleLine`)."""

    start: Vector
    end: Vector
    moment_per_metre: Vector
    spacing: PositiveFloat = 0.1
    radius: PositiveFloat | None = None
    only_in: OnlyIn = None

    @field_validator("end")
    @classmethod
    def _not_start(cls, value: tuple, info: ValidationInfo) -> tuple:
        if value == info.data.get("start"):
            raise ValueError("must differ from start (a zero-length line)")
        return value

    @field_validator("spacing")
    @classmethod
    def _few_dipoles(cls, value: float, info: ValidationInfo) -> float:
        start, end = info.data.get("start"), info.data.get("end")
        if start is not None and end is not None:
            length = math.dist(start, end)
            n = line_dipoles(length, value)
            if n > MAX_LINE_DIPOLES:
                raise ValueError(
                    f"makes {n} dipoles over the line's {length:g} m, more than the limit of "
                    f"{MAX_LINE_DIPOLES} (spacing >= {length / MAX_LINE_DIPOLES:.3g} m)"
                )
        return value

    def dipole_count(self) -> int:
        return line_dipoles(math.dist(self.start, self.end), self.spacing)


class LatticeSpec(_Section):
    """A seeded random lattice of dipoles over a box
    (:class:`kiseki.sim.magnetic_lattice.DipoleLattice`)."""

    lower: Vector
    upper: Vector
    spacing: PositiveFloat
    moment_sd: NonNegativeVector
    moment_mean: Vector = (0.0, 0.0, 0.0)
    seed: Seed = 0
    radius: PositiveFloat | None = None
    only_in: OnlyIn = None

    @field_validator("upper")
    @classmethod
    def _above_lower(cls, value: tuple, info: ValidationInfo) -> tuple:
        lower = info.data.get("lower")
        if lower is not None and any(hi < lo for lo, hi in zip(lower, value, strict=True)):
            raise ValueError(f"must be >= lower {list(lower)} in x, y and z")
        return value

    @field_validator("spacing")
    @classmethod
    def _few_dipoles(cls, value: float, info: ValidationInfo) -> float:
        lower, upper = info.data.get("lower"), info.data.get("upper")
        if lower is not None and upper is not None:
            n = lattice_dipoles(lower, upper, value)
            if n > MAX_LATTICE_DIPOLES:
                raise ValueError(
                    f"makes {n} dipoles over the box (its volume / spacing^3, a flat side one "
                    f"layer), more than the limit of {MAX_LATTICE_DIPOLES}"
                )
        return value


class Drift(_Section):
    """The slow temperature drift: amplitude G, period s, phase rad (unset keys keep
    MagneticWorld's defaults; the None defaults are never used as values)."""

    amplitude: NonNegativeFloat = None  # type: ignore[assignment]
    period: PositiveFloat = None  # type: ignore[assignment]
    phase: FiniteFloat = None  # type: ignore[assignment]


_Items = Field(max_length=MAX_WORLD_DIPOLES)


class MagneticSection(_Section):
    """A scene's ``magnetic:`` section (:class:`kiseki.sim.magnetic.MagneticWorld`)."""

    # unset keys keep MagneticWorld's defaults (the None defaults are never used as values)
    earth_field: EarthField = None  # type: ignore[assignment]
    dipoles: Annotated[list[DipoleSpec], _Items] = []
    lines: Annotated[list[LineSpec], _Items] = []
    # validated when absent too: its check counts every dipole of the section
    lattices: Annotated[list[LatticeSpec], _Items, Field(validate_default=True)] = []
    gradient: Matrix = None  # type: ignore[assignment]
    gradient_origin: Vector = None  # type: ignore[assignment]
    drift: Drift = Drift()

    @field_validator("lattices")
    @classmethod
    def _few_dipoles(cls, value: list[LatticeSpec], info: ValidationInfo) -> list[LatticeSpec]:
        dipoles, lines = info.data.get("dipoles"), info.data.get("lines")
        if dipoles is None or lines is None:
            return value
        n = (
            len(dipoles)
            + sum(line.dipole_count() for line in lines)
            + sum(lattice_dipoles(lat.lower, lat.upper, lat.spacing) for lat in value)
        )
        if n > MAX_WORLD_DIPOLES:
            raise ValueError(
                f"with the dipoles and lines: {n} dipoles in all, more than the limit of "
                f"{MAX_WORLD_DIPOLES}"
            )
        return value


class ArmSpec(_Section):
    """A magnetometer's ``arm`` mapping in a scene's robot sensors: the bar of the 2-DOF arm
    (:class:`kiseki.sim.magnetic_arm.ArmMagnetometers`) and which of its two sensors this
    entry is. Whether ``heights`` lie within the bar's reach of the pivot (the entry's mount)
    is checked where the arm is built."""

    inner: PositiveFloat
    sensors_apart: PositiveFloat = 0.6
    heights: Pair
    period: PositiveFloat
    yaw_period: PositiveFloat = None  # type: ignore[assignment]  (needed when the yaw sweeps)
    yaw_deg: Pair = (0.0, 0.0)
    sensor: Literal["near", "far"] = None  # type: ignore[assignment]

    @field_validator("heights")
    @classmethod
    def _rising(cls, value: tuple[float, float]) -> tuple[float, float]:
        if not 0.0 <= value[0] < value[1]:
            raise ValueError("must be [zmin, zmax] m with 0 <= zmin < zmax")
        return value

    @field_validator("yaw_deg")
    @classmethod
    def _ordered(cls, value: tuple[float, float], info: ValidationInfo) -> tuple[float, float]:
        if value[1] < value[0]:
            raise ValueError("must be [lo, hi] degrees with lo <= hi")
        if value[0] != value[1] and info.data.get("yaw_period") is None:
            raise ValueError("sweeps (lo != hi): yaw_period is needed")
        return value
