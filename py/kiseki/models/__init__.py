# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Sensor models: the teaching-and-playback thesis' local maps and space observation model."""

from __future__ import annotations

from kiseki.models.space_observation import (
    LocalMapBuilder,
    SpaceObservationModel,
    counts_reference,
    likelihood_reference,
    visibility_reference,
)

__all__ = [
    "LocalMapBuilder",
    "SpaceObservationModel",
    "counts_reference",
    "likelihood_reference",
    "visibility_reference",
]
