# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Sensor models: nav2's beam and likelihood-field range-finder models, the teaching-and-playback
thesis' local maps and space observation model, and the interface they share with the Monte
Carlo engine (``SensorModel``: log-likelihoods per pose, readings, agreement)."""

from __future__ import annotations

from kiseki._core import BeamCombination, BeamModel, LikelihoodFieldModel, SensorModel
from kiseki.models.space_observation import (
    LocalMapBuilder,
    SpaceObservationModel,
    counts_reference,
    likelihood_reference,
    visibility_reference,
)

__all__ = [
    "BeamCombination",
    "BeamModel",
    "LikelihoodFieldModel",
    "LocalMapBuilder",
    "SensorModel",
    "SpaceObservationModel",
    "counts_reference",
    "likelihood_reference",
    "visibility_reference",
]
