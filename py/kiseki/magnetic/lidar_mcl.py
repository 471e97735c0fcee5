# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""MCL with a LIDAR and the magnetic heading correction of the magnetic-navigation thesis
(``002_74cea16d239c028f.txt``, ch. 5, sec. 5.2), on kiseki's engine
(:class:`kiseki.filters.MonteCarloLocalizer` with the C++ beam model).

Per laser scan (sec. 5.2, steps 1-6):

1. motion update (eq. 5.3): the engine's differential odometry model, the encoder increments
   plus Gaussian noise (``alphas``, the same for the laser-only and the corrected filter);
2. heading from the magnetic map (eqs. 5.4-5.5): at the odometry pose ``x^_t`` (the last
   estimate moved by this step's odometry increment, "one step of odometry holds almost no
   error") the map gives ``theta_m = theta_n - m_theta,n``; when ``r_z >= 0.992`` and
   ``r_theta >= 0.990`` (eqs. 4.5, 4.13) the heading is ``theta = theta_m + m_theta,t``
   (:func:`kiseki.magnetic.travel_distance.azimuth_heading`);
3. every particle's heading becomes ``theta + N(0, sigma_theta^2)`` (eq. 5.6). The thesis prints
   "sigma_theta^2 = 1 deg"; we read it as sigma_theta = 1 deg (a variance in deg would be deg^2);
4. the beam model (eq. 5.7: the product over the beams of N(d_j; d^_j, sigma_d), d^_j ray-cast
   in the occupancy grid), nav2's mixture with its z_short, z_max and z_rand terms so that a
   beam with no return or a passer-by does not zero a particle; sigma_d: 0.2 m (the thesis gives
   no value; nav2's sigma_hit);
5. the weighted mean (eq. 5.9: the engine's posterior);
6. resampling only when ESS < 9n/10 (sec. 5.2.4, eq. 4.11).

The heading is written into the particles between steps 1 and 4: the engine calls the model's
``prepare`` after its motion update (:meth:`MonteCarloLocalizer.step`), and the reset keeps the
particles' weights (``set_particles(poses, weights)``); no C++ is added.

The magnetic map (sec. 5.2.2): the thesis keeps a 2-D grid of 0.1 m whose cells hold values only
along the taught path. Here it is the taught path's :class:`LinearMagneticMap` (the same nodes
every 0.1 m of travel, the same averaged m_theta, m_z and heading) looked up by position:
:class:`PathHeadingMap` takes the node nearest the odometry pose, and none when that node is
farther than ``reach`` (0.3 m: the taught and the driven path differ by some tenths of a metre,
Fig. 5.4, where a strict 0.1 m cell would miss; the r_z and r_theta gates still refuse a node
whose field does not match). Off the path no correction is made, as the thesis says (sec. 5.4).
One map kind serves chapters 3-5 this way, and the nodes need positions (the map's
``position``), which a teaching run in the map frame gives.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np

from kiseki import _core
from kiseki._support.counts import check_count
from kiseki._support.field_types import check_field_types
from kiseki._support.options import BEAM_LIMIT, PARTICLE_LIMIT
from kiseki._support.real_numbers import check_number, hold_number
from kiseki.core import Pose2, check_seed, derive_seed
from kiseki.filters import REAL_ODOMETRY_ALPHAS, MclConfig, MonteCarloLocalizer
from kiseki.filters.initial_pose import check_spread
from kiseki.grid import OccupancyGrid
from kiseki.magnetic.linear_map import LinearMagneticMap
from kiseki.magnetic.travel_distance import R_THETA_GATE, R_Z_GATE, azimuth_heading

__all__ = [
    "SIGMA_THETA",
    "LidarMclConfig",
    "LidarMclStep",
    "MagneticLidarMcl",
    "PathHeadingMap",
]

SIGMA_THETA = math.radians(1.0)
"""rad: sigma_theta of eq. 5.6 (the thesis prints "sigma_theta^2 = 1 deg"; read as 1 deg)."""


@dataclass(frozen=True)
class LidarMclConfig:
    """The localizer's settings (see the module text). ``magnetic`` False gives the
    laser-only MCL the thesis compares with (the same filter without steps 2-3)."""

    particles: int = 500
    sigma_d: float = 0.2  # m, eq. 5.7 (nav2's sigma_hit; the thesis gives none)
    beams: int = 60  # beams of each scan weighed (nav2's max_beams)
    sigma_theta: float = SIGMA_THETA  # rad, eq. 5.6
    r_z_gate: float = R_Z_GATE  # eq. 4.5, sec. 5.2.2
    r_theta_gate: float = R_THETA_GATE  # eq. 4.13, sec. 5.2.2
    reach: float = 0.3  # m: the farthest map node used (see the module text)
    resample_threshold: float = 0.9  # ESS < 9n/10 (sec. 5.2.4)
    alphas: tuple[float, ...] = REAL_ODOMETRY_ALPHAS  # the motion noise (eq. 5.3's noise)
    magnetic: bool = True
    seed: int = 0
    threads: int = 1  # the engine's threads (0: every core); one seed gives one run for any

    def __post_init__(self) -> None:
        check_field_types(self)
        check_count(self.particles, "lidar MCL: particles", 1, PARTICLE_LIMIT)
        check_count(self.beams, "lidar MCL: beams", 1, BEAM_LIMIT)

        def hold(name: str, *bounds: float, **rule: Any) -> None:
            hold_number(self, name, f"lidar MCL: {name}", *bounds, **rule)

        hold("sigma_d", 1e-6, unit="m")
        hold("sigma_theta", 0.0, math.pi, unit="rad")
        hold("r_z_gate", 0.0, 1.0)
        hold("r_theta_gate", 0.0, 1.0)
        hold("reach", 0.0, unit="m")
        hold("resample_threshold", 0.0, 1.0)
        if not isinstance(self.magnetic, bool):
            raise ValueError(f"lidar MCL: magnetic must be true or false, got {self.magnetic!r}")
        check_seed(self.seed)
        self.mcl()  # the engine's own checks (particles, alphas)

    def mcl(self) -> MclConfig:
        return MclConfig(
            particles=self.particles,
            alphas=tuple(self.alphas),
            resample_threshold=self.resample_threshold,
            threads=self.threads,
        )


class PathHeadingMap:
    """The taught path's magnetic map looked up by position (sec. 5.2.2, see the module
    text): the node nearest (x, y) within ``reach`` m."""

    def __init__(self, linear_map: LinearMagneticMap, reach: float = 0.3) -> None:
        if not isinstance(linear_map, LinearMagneticMap):
            raise ValueError(
                f"lidar MCL: the magnetic map must be a LinearMagneticMap, got "
                f"{type(linear_map).__name__}"
            )
        if len(linear_map) == 0:
            raise ValueError("lidar MCL: the magnetic map is empty")
        if not np.isfinite(linear_map.position).all():
            raise ValueError(
                "lidar MCL: the magnetic map's nodes need positions (a map taught with "
                "positions in the map frame); some are NaN"
            )
        self.map = linear_map
        self.reach = check_number(reach, "lidar MCL: reach", 0.0, unit="m")

    def nearest(self, xy: Any) -> int | None:
        """The index of the node nearest ``xy`` (2,), or None beyond ``reach``."""
        q = np.asarray(xy, dtype=np.float64)
        if q.shape != (2,) or not np.isfinite(q).all():
            raise ValueError(f"lidar MCL: a position must be 2 finite numbers, got {xy!r}")
        d2 = np.sum((self.map.position - q) ** 2, axis=1)
        k = int(np.argmin(d2))
        return k if d2[k] <= self.reach**2 else None


class LidarMclStep(NamedTuple):
    """What one step did: the estimate (x, y, theta), whether the heading was reset, r_z and
    r_theta (NaN: no map node or no reading), the ESS before resampling, whether it resampled,
    and the particles' SD in (x, y, theta) after the step (Fig. 5.6)."""

    estimate: np.ndarray
    reset: bool
    r_z: float
    r_theta: float
    ess: float
    resampled: bool
    sd: np.ndarray


def _reading(value: Any) -> np.ndarray:
    m = np.asarray(value, dtype=np.float64)
    if m.shape != (3,) or not np.isfinite(m).all():
        raise ValueError(
            f"lidar MCL: a reading must be 3 finite numbers (mx, my, mz) G, got {value!r}"
        )
    return m


class MagneticLidarMcl:
    """Chapter 5's localizer. ``grid``: the occupancy grid; ``heading_map``: the taught path's
    map (None, or ``config.magnetic`` False: laser-only MCL); ``laser``: the laser's pose in
    the robot frame (x, y, yaw); ``start``/``start_sd``: the initial Gaussian cloud.
    ``model``: a beam model made by :meth:`beam_model` with the same grid, config and laser, to
    share between filters run one after the other on one map (building it takes about a second
    on a large map); each step sets its own scan first. None builds one."""

    @staticmethod
    def beam_model(grid: OccupancyGrid, config: LidarMclConfig, laser: Any) -> _core.BeamModel:
        """Step 4's beam model (eq. 5.7) on ``grid`` for ``config`` and the laser mount."""
        mount = np.asarray(laser, dtype=np.float64)
        if mount.shape != (3,) or not np.isfinite(mount).all():
            raise ValueError("lidar MCL: laser must be 3 finite numbers (x, y, theta)")
        return _core.BeamModel(
            grid, sigma_hit=config.sigma_d, max_beams=config.beams, sensor=Pose2(*mount)
        )

    def __init__(
        self,
        grid: OccupancyGrid,
        heading_map: PathHeadingMap | None,
        config: LidarMclConfig,
        start: Any,
        start_sd: tuple[float, float, float] = (0.1, 0.1, math.radians(2.0)),
        laser: Any = (0.0, 0.0, 0.0),
        model: _core.BeamModel | None = None,
    ) -> None:
        if not isinstance(config, LidarMclConfig):
            raise ValueError(f"lidar MCL: config must be a LidarMclConfig, got {config!r}")
        if not isinstance(grid, OccupancyGrid):
            raise ValueError(f"lidar MCL: grid must be an OccupancyGrid, got {type(grid).__name__}")
        if config.magnetic and not isinstance(heading_map, PathHeadingMap):
            raise ValueError("lidar MCL: the magnetic correction needs a PathHeadingMap")
        pose = np.asarray(start, dtype=np.float64)
        mount = np.asarray(laser, dtype=np.float64)
        for name, v in (("start", pose), ("laser", mount)):
            if v.shape != (3,) or not np.isfinite(v).all():
                raise ValueError(f"lidar MCL: {name} must be 3 finite numbers (x, y, theta)")
        sd = check_spread("lidar MCL: start_sd", start_sd)
        self.config = config
        self.heading_map = heading_map if config.magnetic else None
        self.localizer = MonteCarloLocalizer(config.mcl(), derive_seed(config.seed, 1))
        self.localizer.initialize(pose, tuple(sd))
        if model is not None and not isinstance(model, _core.BeamModel):
            raise ValueError(f"lidar MCL: model must be a BeamModel, got {type(model).__name__}")
        self.model = self.beam_model(grid, config, mount) if model is None else model
        self.rng = np.random.default_rng(derive_seed(config.seed, 2))
        self._odometry: np.ndarray | None = None

    @property
    def estimate(self) -> np.ndarray:
        return self.localizer.estimate

    def reset_headings(self, theta: float) -> None:
        """Eq. 5.6: every particle's heading becomes theta + N(0, sigma_theta^2); positions
        and weights are kept."""
        theta = check_number(theta, "lidar MCL: theta")
        engine = self.localizer.engine
        poses = engine.poses.copy()
        noise = self.rng.normal(0.0, self.config.sigma_theta, len(poses))
        poses[:, 2] = np.arctan2(np.sin(theta + noise), np.cos(theta + noise))
        engine.set_particles(poses, engine.weights)

    def _odometry_pose(self, odometry: Any) -> np.ndarray:
        """x^_t: the last estimate moved by this step's odometry increment (sec. 5.2.2)."""
        if self._odometry is None:
            return self.estimate.copy()
        step = Pose2(*self._odometry).between(Pose2(*odometry))
        return (Pose2(*self.estimate) * step).to_array()

    def step(self, odometry: Any, scan: tuple, reading: Any = None) -> LidarMclStep:
        """One step: the odometry pose (x, y, theta) now, the scan (angles (n,), ranges (n,),
        max range) and the magnetometer's reading (mx, my, mz) G in the sensor frame (x
        forward, y right, z down), or None when there is none this step."""
        odo = np.asarray(odometry, dtype=np.float64)
        if odo.shape != (3,) or not np.isfinite(odo).all():
            raise ValueError(f"lidar MCL: odometry must be 3 finite numbers, got {odometry!r}")
        if not (isinstance(scan, tuple) and len(scan) == 3):
            raise ValueError("lidar MCL: scan must be (angles, ranges, max_range)")
        angles = np.asarray(scan[0], dtype=np.float64)
        ranges = np.asarray(scan[1], dtype=np.float32)
        max_range = check_number(scan[2], "lidar MCL: max_range", 1e-6, unit="m")
        if angles.ndim != 1 or angles.shape != ranges.shape or not np.isfinite(angles).all():
            raise ValueError("lidar MCL: the scan's angles and ranges must be 1-D of one length")
        m = None if reading is None else _reading(reading)
        x_hat = self._odometry_pose(odo)
        fix, r_z, r_theta = None, math.nan, math.nan
        if self.heading_map is not None and m is not None:
            k = self.heading_map.nearest(x_hat[:2])
            if k is not None:
                lm = self.heading_map.map
                fix = azimuth_heading(
                    float(x_hat[2]),
                    math.atan2(m[1], m[0]),
                    float(m[2]),
                    float(lm.heading[k]),
                    float(lm.m_theta[k]),
                    float(lm.field[k, 2]),
                    self.config.r_z_gate,
                    self.config.r_theta_gate,
                )
                r_z, r_theta = fix.r_z, fix.r_theta

        def prepare() -> _core.SensorModel:  # called after the motion update
            if fix is not None and fix.applied:
                self.reset_headings(fix.theta)
            self.model.set_scan(angles, ranges, max_range)
            return self.model

        report = self.localizer.step(odo, prepare)
        self._odometry = odo
        sd = np.sqrt(np.maximum(np.diag(self.localizer.engine.covariance()), 0.0))
        return LidarMclStep(
            self.estimate.copy(),
            bool(fix is not None and fix.applied),
            r_z,
            r_theta,
            float(report.effective_sample_size),
            bool(report.resampled),
            sd,
        )
