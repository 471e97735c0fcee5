# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Magnetic maps and magnetometers (thesis chapter 6): calibration of the sensors (eq. 6.16),
field maps from Gaussian-process regression, and localization on them (eqs. 6.17-6.18)."""

from __future__ import annotations

from kiseki.magnetic.calibration import (
    EllipsoidCalibration,
    SphereCalibration,
    calibrated_magnitude,
    fit_ellipsoid,
    fit_sphere,
)
from kiseki.magnetic.field_map import MagneticFieldMap, TrainingData
from kiseki.magnetic.localization import (
    MagneticLocalization,
    MagneticMapModel,
    MagneticMclConfig,
    localize_on_magnetic_map,
)

__all__ = [
    "EllipsoidCalibration",
    "MagneticFieldMap",
    "MagneticLocalization",
    "MagneticMapModel",
    "MagneticMclConfig",
    "SphereCalibration",
    "TrainingData",
    "calibrated_magnitude",
    "fit_ellipsoid",
    "fit_sphere",
    "localize_on_magnetic_map",
]
