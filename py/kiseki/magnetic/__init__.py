# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Magnetic maps and magnetometers (thesis chapter 6): calibration of the sensors (eq. 6.16)."""

from __future__ import annotations

from kiseki.magnetic.calibration import (
    EllipsoidCalibration,
    SphereCalibration,
    calibrated_magnitude,
    fit_ellipsoid,
    fit_sphere,
)

__all__ = [
    "EllipsoidCalibration",
    "SphereCalibration",
    "calibrated_magnitude",
    "fit_ellipsoid",
    "fit_sphere",
]
