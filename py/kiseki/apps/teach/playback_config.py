# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The settings of a route playback (:mod:`kiseki.apps.teach.playback`): the thesis' method and
stop rule, the filter's particles and odometry noise, and the sensor model."""

from __future__ import annotations

import math
from dataclasses import dataclass

from kiseki._support.counts import check_count
from kiseki._support.field_types import check_field_types
from kiseki._support.options import BEAM_LIMIT, PARTICLE_LIMIT
from kiseki._support.real_numbers import check_number
from kiseki.filters import MclConfig
from kiseki.filters.initial_pose import check_spread
from kiseki.sim.run import MAX_SIM_SECONDS
from kiseki.teach.local_maps import METHODS

__all__ = ["PLAYBACK_MODELS", "PlaybackConfig"]

PLAYBACK_MODELS = ("space-observation", "ray-space-observation")


@dataclass(frozen=True)
class PlaybackConfig:
    method: str = "proposal2"
    particles: int = 1000
    seed: int = 0
    dt: float = 0.1  # s, 10 Hz as in the thesis
    speed: float = 0.5  # m/s
    goal_tolerance: float = 0.1  # m, the thesis' stop rule
    initial_sd: tuple[float, float, float] = (0.05, 0.05, math.radians(1.0))
    # Odometry motion model noise (Probabilistic Robotics Table 5.6), the same for every method,
    # set so that its 1-sigma spread covers the simulated AGV's odometry error (sim.robot_params'
    # OdometryErrorParams) at 10 Hz and 0.5 m/s (0.05 m, up to about 0.05 rad per step):
    #   alpha1 (rot -> rot): track width +0.5 % over a 90 deg turn of about 30 steps needs
    #     0.005^2 * 30 = 7.5e-4, turning slip 5e-5 rad/rad adds 5e-5 / 0.05 = 1e-3 -> 0.002;
    #   alpha2 (trans -> rot, rad^2/m^2): the 0.1 % wheel-radius difference over the 0.5 m track
    #     turns 0.002 rad/m, over a 10 m leg of 200 steps (0.002 * 10)^2 / 200 / 0.05^2 = 8e-4;
    #     wheel slip 4e-6 m/m per wheel adds 2 * 4e-6 / 0.5^2 / 0.05 = 6.4e-4 -> 0.002;
    #   alpha3 (trans -> trans): mean wheel radius -0.1 % over 200 steps 0.001^2 * 200 = 2e-4,
    #     slip 2e-6 / 0.05 = 4e-5 -> 5e-4;
    #   alpha4 (rot -> trans, m^2/rad^2): no modelled source; a floor of 5e-4.
    # (Each sum rounded up to 1, 2 or 5 times a power of ten.)
    alphas: tuple[float, float, float, float] = (0.002, 0.002, 0.0005, 0.0005)
    max_duration: float = 300.0
    # The sensor model: the thesis' on the local map L, or kiseki's ray model on L read as a
    # scan of scan_beams rays (teach.local_maps.local_map_scan): both weigh what the cameras saw.
    model: str = "space-observation"
    scan_beams: int = 360
    scan_range_scale: float = 1.0  # the ray model's readings times this (a range calibration)

    def __post_init__(self) -> None:
        check_field_types(self)
        if self.method not in METHODS:
            raise ValueError(f"method must be one of {', '.join(METHODS)}, got {self.method!r}")
        check_count(self.particles, "particles", 1, PARTICLE_LIMIT)
        # an infinite goal_tolerance "reached" the goal before the first step, an infinite dt
        # or a negative, NaN or infinite max_duration made no step or none that ends
        for name in ("dt", "speed", "goal_tolerance"):
            check_number(getattr(self, name), name, 0.0, low_open=True)
        if not self.dt <= self.max_duration <= MAX_SIM_SECONDS:
            raise ValueError(
                f"max_duration must be in [dt, {MAX_SIM_SECONDS:,.0f}] s (24 h, as a simulated "
                f"run), got {self.max_duration!r} with dt {self.dt!r}"
            )
        if self.model not in PLAYBACK_MODELS:
            raise ValueError(
                f"model must be one of {', '.join(PLAYBACK_MODELS)}, got {self.model!r}"
            )
        check_count(self.scan_beams, "scan_beams", 1, BEAM_LIMIT)
        check_spread("initial_sd", self.initial_sd)  # a NaN was refused once the run started
        MclConfig(particles=self.particles, alphas=tuple(self.alphas))  # and an alpha
        check_number(self.scan_range_scale, "scan_range_scale", 0.1, 10.0)
