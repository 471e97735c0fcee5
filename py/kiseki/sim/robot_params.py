# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Parameters of the simulated robots and of their odometry errors: the factory AGV of paper 000
(:class:`DiffDriveParams`, :class:`OdometryErrorParams`) and the hospital robot of paper 004
(:class:`OmniParams`, :class:`OmniOdometryErrorParams`), as a scene file's sections give them.

Defaults of :class:`OdometryErrorParams` are chosen so that the factory AGV's odometry
reproduces the magnitude of paper 000's Exp. 1 (odometry minus truth at P2, 13 m straight, 11
runs: y mean -0.20 m, SD 0.23 m; at P1, 7.4 m: y mean -0.07 m, SD 0.11 m). With the defaults the
closed-form prediction is y mean -0.21 m / SD 0.22 m at 13 m and -0.08 m / 0.11 m at 7.4 m.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Mapping, Sequence
from typing import Annotated, Any, TypeVar

from pydantic import ConfigDict, Field, RootModel
from pydantic.dataclasses import dataclass as pydantic_dataclass

from kiseki._support.schema import (
    FiniteFloat,
    NonNegativeFloat,
    PositiveFloat,
    PositiveInt,
    parse,
)

__all__ = ["DiffDriveParams", "OdometryErrorParams", "OmniOdometryErrorParams", "OmniParams"]


# The parameter classes are pydantic dataclasses: still frozen dataclasses (dataclasses.fields,
# replace and asdict work), checked on construction by pydantic with kiseki._support.schema's strict
# number types (an int is a float, a float is not an int, a bool is not a number, NaN and
# infinities are errors). A relative error e gives a physical value nominal * (1 + e), so it
# must lie in (-1, 1) for the value to stay positive.
_params = pydantic_dataclass(frozen=True, config=ConfigDict(extra="forbid"))
RelativeError = Annotated[float, Field(strict=True, gt=-1.0, lt=1.0, allow_inf_nan=False)]
Flag = Annotated[bool, Field(strict=True)]

_P = TypeVar("_P", bound="_Params")


@functools.cache
def _document(cls: type) -> type[RootModel]:
    """A model whose document is one parameter section (``parse`` needs a pydantic model)."""
    return RootModel[cls]  # type: ignore[valid-type]


class _Params:
    """``from_dict`` and ``to_dict`` of the parameter classes."""

    @classmethod
    def from_dict(
        cls: type[_P], d: Mapping[str, Any], source: str = "<dict>", at: Sequence[str | int] = ()
    ) -> _P:
        """Builds the parameters from a mapping (a parsed YAML/TOML/JSON section).

        Missing keys keep their documented defaults. Unknown keys, non-numeric values, NaN or
        infinite values and values out of range (sizes and limits must be > 0) raise
        :class:`kiseki._support.schema.SchemaError` (a ValueError) naming ``source`` (e.g. the
        config file), the key (after the path ``at`` of the section in its file) and the value.
        """
        return parse(_document(cls), d, source, at=at).root

    def to_dict(self) -> dict[str, Any]:
        """The parameters as a plain dict (``from_dict(p.to_dict()) == p``)."""
        return dataclasses.asdict(self)  # type: ignore[call-overload]


# --------------------------------------------------------------------------------------------
# Robot parameters
# --------------------------------------------------------------------------------------------


@_params
class DiffDriveParams(_Params):
    """The factory AGV of paper 000 (CARTIS Type B, a differential-drive cart).

    Attributes (value -- source):
        length: 1.05 m -- thesis 000, sec. 3.1 (overall length 1050 mm).
        width: 0.58 m -- thesis 000, sec. 3.1 (580 mm).
        height: 0.99 m -- thesis 000, sec. 3.1 (990 mm).
        wheel_radius: 0.075 m -- NOT in the thesis (the base is an AirBuggy COCO stroller whose
            wheel size it does not give); a stated assumption: a 150 mm drive wheel, common on
            carts of this size. This is the NOMINAL radius, the value the odometry software
            uses; the as-built radii are set by :class:`OdometryErrorParams`.
        track_width: 0.50 m -- NOT in the thesis; stated assumption: the two rear drive wheels
            sit just inside the 0.58 m body (40 mm each side for wheel and mount). This is the
            distance between the wheels' contact points of the simulated (true) robot; the
            odometry's calibrated value differs by :attr:`OdometryErrorParams.track_width_error`.
        max_speed: 1.0 m/s -- stated assumption: the cart is pushed by a worker while teaching
            and drives itself at about walking pace during playback; the thesis gives no limit.
        max_yaw_rate: 1.0 rad/s -- stated assumption (adds +-0.25 m/s at each wheel with the
            0.50 m track, well inside what a 24 V RE35 with 70:1 gear can deliver).
        max_accel: 0.5 m/s^2 -- stated assumption for a light (20 kg payload) cart with a caster.
        max_yaw_accel: 1.0 rad/s^2 -- stated assumption (0.25 m/s^2 at each wheel).
        encoder_counts_per_rev: 500 -- thesis 000, sec. 3.1 (Maxon MR Type L, 500 counts per
            motor turn, on each motor).
        gear_ratio: 70.0 -- thesis 000, sec. 3.1 (reduction 70:1 between motor and wheel).
        quadrature: True -- datasheet reading: Maxon rates its MR encoders in counts per turn
            per channel, and a quadrature decoder (the SH2 counter under YP-Spur) counts all four
            edges, giving 4 x 500 = 2000 counts per motor turn. Set False for x1 counting.
    """

    length: PositiveFloat = 1.05
    width: PositiveFloat = 0.58
    height: PositiveFloat = 0.99
    wheel_radius: PositiveFloat = 0.075
    track_width: PositiveFloat = 0.50
    max_speed: PositiveFloat = 1.0
    max_yaw_rate: PositiveFloat = 1.0
    max_accel: PositiveFloat = 0.5
    max_yaw_accel: PositiveFloat = 1.0
    encoder_counts_per_rev: PositiveInt = 500
    gear_ratio: PositiveFloat = 70.0
    quadrature: Flag = True

    @property
    def counts_per_wheel_rev(self) -> float:
        """Encoder counts per wheel revolution: counts x gear x (4 with quadrature decoding).

        140000 with the defaults (500 x 70 x 4).
        """
        return self.encoder_counts_per_rev * self.gear_ratio * (4 if self.quadrature else 1)

    @property
    def distance_per_count(self) -> float:
        """Ground travel of one encoder count at the nominal radius (3.37e-6 m by default)."""
        return 2.0 * math.pi * self.wheel_radius / self.counts_per_wheel_rev


@_params
class OmniParams(_Params):
    """The omnidirectional hospital transport robot of paper 004 (MKR-003).

    Attributes (value -- source):
        length: 0.70 m -- NOT in paper 004; stated assumption: a square footprint as wide as
            the robot.
        width: 0.70 m -- paper 004 (w1 = 0.70 m, the robot width in the width term f(w)).
        max_speed: 0.5 m/s -- paper 004 (v_max), applied to the norm of the body velocity.
        max_accel: 0.5 m/s^2 -- paper 004 (maximum acceleration), applied to the norm of the
            change of the body-frame velocity vector.
        max_yaw_rate: 1.0 rad/s -- NOT in paper 004; stated assumption: the rim of the 0.70 m
            body then moves at 0.35 m/s, below v_max.
        max_yaw_accel: 1.0 rad/s^2 -- NOT in paper 004; stated assumption: rim acceleration
            0.35 m/s^2, below a_max.
    """

    length: PositiveFloat = 0.70
    width: PositiveFloat = 0.70
    max_speed: PositiveFloat = 0.5
    max_accel: PositiveFloat = 0.5
    max_yaw_rate: PositiveFloat = 1.0
    max_yaw_accel: PositiveFloat = 1.0


@_params
class OdometryErrorParams(_Params):
    """Systematic and random odometry errors of the differential-drive AGV.

    Conventions: the as-built wheel radii are ``wheel_radius * (1 + e)``; the as-built track
    (the simulated robot's, :attr:`DiffDriveParams.track_width`) is ``(1 + track_width_error)``
    times the nominal track the odometry integrates with, i.e. ``1 + track_width_error`` is
    Borenstein & Feng's E_b = b_actual / b_nominal.

    Attributes (value -- source):
        left_radius_error: -0.0015 (-0.15 %) -- stated assumption, fitted to paper 000 Exp. 1:
            the loaded tyres roll on a slightly smaller radius than the nominal one. Tenths of a
            percent is the size of the uncalibrated wheel-diameter errors UMBmark reports.
        right_radius_error: -0.0005 (-0.05 %) -- stated assumption, as above. The left-right
            difference of 0.1 % makes the odometry curve to the right (y error -0.17 m after
            13 m, growing with distance squared, as the thesis's mean error does: 2.7 times
            larger at 13 m than at 7.4 m), the mean of -0.1 % gives the thesis's +0.01 m along
            the track.
        track_width_error: +0.005 (+0.5 %) -- stated assumption: the effective contact point
            of a wide tyre is uncertain by a few millimetres (2.5 mm of 0.50 m). Odometry turns
            are then 0.5 % too large.
        initial_heading_offset: -0.2 deg (-3.49e-3 rad) -- stated assumption: a constant
            mis-alignment when the cart is placed on the start mark; the odometry's initial
            heading is the true one plus this offset (and the random part below). The thesis
            (sec. 4.1.2) names the placement error as the main cause of its odometry drift.
        initial_heading_sd: 0.7 deg (1.22e-2 rad) -- standard deviation of the random placement
            error, drawn once per odometry instance; fitted to the growth of the run-to-run
            spread of Exp. 1 together with the slip noise.
        slip_distance_coeff: 4e-6 m -- k_d: each wheel's slip has variance k_d * |travel|
            (2 mm SD per metre rolled). Fitted to Exp. 1's spread (with the placement error:
            predicted SD 0.11 m at 7.4 m and 0.22 m at 13 m vs the thesis's 0.11 and 0.23 m).
        slip_rotation_coeff: 5e-5 rad -- k_r: turning scrubs the tyres and the caster; an equal
            and opposite slip on the two wheels whose induced heading error has variance
            k_r * |true rotation| (1.0 deg SD per full turn). Stated assumption.
    """

    left_radius_error: RelativeError = -0.0015
    right_radius_error: RelativeError = -0.0005
    track_width_error: RelativeError = 0.005
    initial_heading_offset: FiniteFloat = math.radians(-0.2)
    initial_heading_sd: NonNegativeFloat = math.radians(0.7)
    slip_distance_coeff: NonNegativeFloat = 4e-6
    slip_rotation_coeff: NonNegativeFloat = 5e-5

    @classmethod
    def none(cls) -> OdometryErrorParams:
        """No systematic and no random error: only the encoder quantisation remains."""
        return cls(**{f.name: 0.0 for f in dataclasses.fields(cls)})


@_params
class OmniOdometryErrorParams(_Params):
    """Random odometry error of the omnidirectional robot (a simple, documented model).

    Each step's true body-frame displacement (dx, dy, dtheta) gets independent zero-mean
    Gaussian noise: each translation component with variance ``translation_coeff * distance``,
    the heading with variance ``heading_distance_coeff * distance + heading_rotation_coeff *
    |dtheta|``, where ``distance`` is the path length of the step. Paper 004 gives no odometry
    model; the values are stated assumptions (omni-wheel rollers slip more than plain tyres,
    so the coefficients are larger than those of :class:`OdometryErrorParams`).

    Attributes (value -- source):
        translation_coeff: 1e-4 m -- 1 cm SD per component after 1 m (assumption).
        heading_distance_coeff: 1e-4 rad -- rad^2 per metre: 0.57 deg SD after 1 m (assumption).
        heading_rotation_coeff: 5e-4 rad -- rad^2 per rad turned: 3.2 deg SD per full turn
            (assumption).
    """

    translation_coeff: NonNegativeFloat = 1e-4
    heading_distance_coeff: NonNegativeFloat = 1e-4
    heading_rotation_coeff: NonNegativeFloat = 5e-4

    @classmethod
    def none(cls) -> OmniOdometryErrorParams:
        """No noise: the odometry equals the truth."""
        return cls(**{f.name: 0.0 for f in dataclasses.fields(cls)})
