# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Magnetic maps and magnetometers: the linear magnetic map along a taught path (thesis
chapters 3-4), calibration of the sensors (eq. 6.16), field maps from Gaussian-process
regression, and localization on them (eqs. 6.17-6.18) (thesis chapter 6); kiseki's loop filter
for travel distance on recorded walks (:mod:`kiseki.magnetic.loop_travel_distance`)."""

from __future__ import annotations

from kiseki.magnetic.calibration import (
    EllipsoidCalibration,
    SphereCalibration,
    calibrated_magnitude,
    fit_ellipsoid,
    fit_sphere,
)
from kiseki.magnetic.field_map import MagneticFieldMap, TrainingData
from kiseki.magnetic.lidar_mcl import LidarMclConfig, MagneticLidarMcl, PathHeadingMap
from kiseki.magnetic.linear_map import (
    LinearMagneticMap,
    build_linear_map,
    geometric_features,
    path_identity,
)
from kiseki.magnetic.linear_map_folder import OtherPathError, load_linear_map, save_linear_map
from kiseki.magnetic.linear_map_run import TeachingSamples, linear_map_from_run, teaching_samples
from kiseki.magnetic.localization import (
    MagneticLocalization,
    MagneticMapModel,
    MagneticMclConfig,
    localize_on_magnetic_map,
)
from kiseki.magnetic.loop_profile import LoopProfile, fit_loop_profile, heading_invariant_channels
from kiseki.magnetic.loop_travel_distance import LoopTravelConfig, LoopTravelDistanceLocalizer
from kiseki.magnetic.loop_walk import LoopWalkResult, localize_walk_loop, map_walk_loop
from kiseki.magnetic.multi_sensor import DriftCheck, SensorDrop, localize_with_magnetometers
from kiseki.magnetic.travel_distance import (
    TravelDistanceConfig,
    TravelDistanceLocalizer,
    azimuth_heading,
    heading_from_map,
)

__all__ = [
    "DriftCheck",
    "EllipsoidCalibration",
    "LidarMclConfig",
    "LinearMagneticMap",
    "LoopProfile",
    "LoopTravelConfig",
    "LoopTravelDistanceLocalizer",
    "LoopWalkResult",
    "MagneticFieldMap",
    "MagneticLidarMcl",
    "MagneticLocalization",
    "MagneticMapModel",
    "MagneticMclConfig",
    "OtherPathError",
    "PathHeadingMap",
    "SensorDrop",
    "SphereCalibration",
    "TeachingSamples",
    "TrainingData",
    "TravelDistanceConfig",
    "TravelDistanceLocalizer",
    "azimuth_heading",
    "build_linear_map",
    "calibrated_magnitude",
    "fit_ellipsoid",
    "fit_loop_profile",
    "fit_sphere",
    "geometric_features",
    "heading_from_map",
    "heading_invariant_channels",
    "linear_map_from_run",
    "load_linear_map",
    "localize_on_magnetic_map",
    "localize_walk_loop",
    "localize_with_magnetometers",
    "map_walk_loop",
    "path_identity",
    "save_linear_map",
    "teaching_samples",
]
