# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The rubble paper's tilting laser (paper 003): a planar scanner (scan angle phi, -90..90 deg)
turned about its y axis (tilt theta, -120..30 deg), 1 deg steps, each cell the median of three
sweeps, and the attitude of a 3-axis gyro with drift (kiseki.sim.gyro).

Tilt sign: theta < 0 looks down. Sensor frame x forward, y left, z up; a ray is

    (cos th cos ph, sin ph, sin th cos ph),

so theta = -90 deg looks straight down, -120 deg down and backwards, +30 deg up in front.
The paper's eq. 2 prints "z = -r sin th cos ph", which with z up is the opposite (+30 deg down,
-120 deg up and backwards); it is not followed, for these reasons in the paper's text:

1. Eq. 3, the inverse the method uses, gives "θ = tan⁻¹(z/x)": z = x tan th, so theta grows
   with z, the sign used here. Eq. 2 and eq. 3 disagree; eq. 2 also prints "y = r sin θ" for
   y = r sin phi, a typo, so eq. 3 is taken as the convention and eq. 2's sign as a second one.
2. Section 5.1: "不整地環境において、3次元自己位置推定を行う場合、地面の凹凸は、有用な情報である"
   (for 3-D localization on rough terrain the ground's irregularities are the useful
   information), and walls and ceilings are removed as featureless. With theta < 0 down, 120
   of the 150 deg of tilt see the ground (in front, below, behind); with eq. 2's sign only
   0..30 deg would, a band of range 1..5 m in front of a sensor 0.5 m high.
3. Section 7.3 shows the match with "Fig.11 A virtual S-DEM sliced θ = -17[deg]" and "Fig.12
   A current local map sliced θ = -17[deg]", after the planes were removed: the cut chosen to
   show the features must pass through them, and at -17 deg down it crosses the floor 1.7 m
   ahead of a sensor 0.5 m high; 17 deg up it would meet only walls above the sensor, which the
   plane removal takes out.

Against it: Fig. 10's caption says the ceiling's planes were removed, and with theta < 0 down
a ceiling 2.5 m above the sensor is within 5 m only for theta > 30 deg at phi = 0 (the sweep's
edge); it is seen when the sensor is lifted (the unit's pantograph) or the room is low
(environment B). ``tilt_down = "positive"`` gives eq. 2 literally, for comparison.

Noise: range SD 5 mm (the SICK scanner's "測定誤差 5mm", taken as 1 sigma); ranges of 5 m and
beyond are dropped ("5m 以内のデータのみを用いる"); "3 回計測したメディアンを取る" (the median of
three measurements): each cell is the median of ``sweeps`` noisy sweeps cast from the same
pose, and a cell missing in most of them (2 of 3) is missing (NaN); with one of three missing,
the median of the other two is their mean (numpy's median).
"""

from __future__ import annotations

import math
import warnings
from typing import Annotated, Literal

import numpy as np
from pydantic import ConfigDict, Field, model_validator
from pydantic.dataclasses import dataclass as pydantic_dataclass

from kiseki._support.schema import FiniteFloat, NonNegativeFloat, PositiveFloat
from kiseki.core import Random, check_seed, derive_seed
from kiseki.sim.gyro import Gyro
from kiseki.sim.pose6 import attitude
from kiseki.sim.sensors import MAX_RANGE

__all__ = ["MAX_TILT_RAYS", "TiltingLaser", "TiltingLaserParams", "median_of_sweeps"]

MAX_TILT_RAYS = 1_000_000
"""Rays of one tilting-laser sweep (the paper's 1 deg grid has 151 x 181 = 27,331)."""

_params = pydantic_dataclass(frozen=True, config=ConfigDict(extra="forbid"))
Range = Annotated[float, Field(strict=True, gt=0, le=MAX_RANGE, allow_inf_nan=False)]


@_params
class TiltingLaserParams:
    """Tilt theta -120..30 deg (theta < 0 down, see the module), scan phi -90..90 deg, 1 deg
    steps, 5 mm accuracy (1 sigma), 8 m range of which r < 5 m is used, the median of 3 sweeps;
    the gyro (kiseki.sim.gyro): a reading error of 0.5 deg (1 sigma, assumption), a turn-on
    rate bias of SD 0.01 deg/s and an angle random walk of 0.005 deg/sqrt(s) (assumptions: a
    consumer MEMS gyro)."""

    tilt_min_deg: FiniteFloat = -120.0
    tilt_max_deg: FiniteFloat = 30.0
    scan_min_deg: FiniteFloat = -90.0
    scan_max_deg: FiniteFloat = 90.0
    step_deg: Annotated[float, Field(strict=True, gt=0, le=360, allow_inf_nan=False)] = 1.0
    noise_sd: NonNegativeFloat = 0.005
    max_range: Range = 8.0
    usable_range: PositiveFloat = 5.0
    gyro_sd_deg: NonNegativeFloat = 0.5
    gyro_bias_sd_deg_s: NonNegativeFloat = 0.01
    gyro_arw_deg_rt_s: NonNegativeFloat = 0.005
    sweeps: Annotated[int, Field(strict=True, ge=1, le=9)] = 3
    tilt_down: Literal["negative", "positive"] = "negative"

    @model_validator(mode="after")
    def _consistent(self) -> TiltingLaserParams:
        for name in ("tilt", "scan"):
            low, high = getattr(self, f"{name}_min_deg"), getattr(self, f"{name}_max_deg")
            if not -360.0 <= low <= high <= 360.0:
                raise ValueError(
                    f"{name}_min_deg <= {name}_max_deg must lie in [-360, 360] deg, "
                    f"got {low} and {high}"
                )
        if self.sweeps % 2 == 0:
            raise ValueError(f"sweeps must be odd (a median of one value), got {self.sweeps}")
        rays = self.ray_count
        if rays > MAX_TILT_RAYS:
            raise ValueError(
                f"step_deg {self.step_deg} gives {rays:,} rays per sweep, "
                f"above the limit of {MAX_TILT_RAYS:,}"
            )
        return self

    @property
    def ray_count(self) -> int:
        """Rays of one sweep: the sizes of :meth:`grid` (as numpy's arange counts them), without
        making the grid."""

        def count(low: float, high: float) -> int:
            return max(0, math.ceil((high + 1e-9 - low) / self.step_deg))

        return count(self.tilt_min_deg, self.tilt_max_deg) * count(
            self.scan_min_deg, self.scan_max_deg
        )

    def grid(self) -> tuple[np.ndarray, np.ndarray]:
        tilt = np.arange(self.tilt_min_deg, self.tilt_max_deg + 1e-9, self.step_deg)
        scan = np.arange(self.scan_min_deg, self.scan_max_deg + 1e-9, self.step_deg)
        return np.radians(tilt), np.radians(scan)


def median_of_sweeps(sweeps) -> np.ndarray:
    """Per cell, the median of the sweeps (k, ...) over their first axis, ignoring NaN; a cell
    finite in no more than half of them is NaN."""
    s = np.asarray(sweeps, dtype=float)
    if s.ndim < 1 or len(s) == 0:
        raise ValueError(f"sweeps: expected at least one sweep, got shape {s.shape}")
    enough = 2 * np.isfinite(s).sum(axis=0) > len(s)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN cells, set to NaN below
        med = np.nanmedian(s, axis=0)
    return np.where(enough, med, np.nan)


class TiltingLaser:
    """Sweeps from a 4x4 sensor pose (world from sensor: a mount on a 6-DOF robot pose, see
    kiseki.sim.sensors.Mount.world). Ranges and the gyro are separate streams of the seed."""

    def __init__(self, params: TiltingLaserParams, seed: int) -> None:
        seed = check_seed(seed)
        self.params, self.rng = params, Random(derive_seed(seed, 0))
        self.gyro = Gyro(
            params.gyro_sd_deg, params.gyro_bias_sd_deg_s, params.gyro_arw_deg_rt_s,
            derive_seed(seed, 1),
        )  # fmt: skip

    @staticmethod
    def directions(tilt: np.ndarray, scan: np.ndarray, tilt_down: str = "negative") -> np.ndarray:
        """Unit rays (len(tilt), len(scan), 3) in the sensor frame (x forward, y left, z up):
        (cos th cos ph, sin ph, s sin th cos ph), s = 1 when theta < 0 looks down, -1 for eq. 2
        as printed (``tilt_down="positive"``)."""
        if tilt_down not in ("negative", "positive"):
            raise ValueError(f"tilt_down must be 'negative' or 'positive', got {tilt_down!r}")
        sign = 1.0 if tilt_down == "negative" else -1.0
        th, ph = np.meshgrid(tilt, scan, indexing="ij")
        return np.stack(
            [np.cos(th) * np.cos(ph), np.sin(ph), sign * np.sin(th) * np.cos(ph)], axis=-1
        )

    def sweeps(self, world, sensor_pose) -> np.ndarray:
        """The ``params.sweeps`` noisy sweeps (k, tilt, scan) from one pose, NaN where nothing
        is hit within the usable range."""
        p = self.params
        pose = np.asarray(sensor_pose, dtype=float)
        if pose.shape != (4, 4) or not np.isfinite(pose).all():
            raise ValueError(f"sensor_pose: expected a finite 4x4 matrix, got shape {pose.shape}")
        tilt, scan = p.grid()
        dirs = self.directions(tilt, scan, p.tilt_down).reshape(-1, 3) @ pose[:3, :3].T
        origins = np.broadcast_to(pose[:3, 3], dirs.shape)
        r = np.asarray(world.cast_many(np.ascontiguousarray(origins), dirs, p.max_range))
        noisy = r[None] + self.rng.normal(0.0, p.noise_sd, p.sweeps * r.size).reshape(
            p.sweeps, r.size
        )
        noisy[(noisy >= p.usable_range) | (noisy <= 0) | (r[None] >= p.max_range)] = np.nan
        return noisy.reshape(p.sweeps, len(tilt), len(scan))

    def scan(self, world, sensor_pose, t: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """Ranges r(theta, phi) (the median of the sweeps, NaN where missing) and the attitude
        (roll, pitch, yaw in rad) the gyro reports at t seconds after the start."""
        ranges = median_of_sweeps(self.sweeps(world, sensor_pose))
        return ranges, self.gyro.read(attitude(np.asarray(sensor_pose, dtype=float)), t)
