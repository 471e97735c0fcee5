# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The sensor models localization along a log weighs with.

* :func:`scan_model` makes nav2's ``beam`` or ``likelihood-field`` model, kiseki's
  ``ray-space-observation`` model, or the teaching-and-playback thesis' ``space-observation``
  model fed with local maps made from each scan. A model written in Python plugs in through
  :meth:`~kiseki.filters.engine.MonteCarloLocalizer.step_log_likelihoods` (one log-likelihood
  per particle).
* Invalid readings (NaN, zero, negative; the log readers store them as NaN, see
  :mod:`kiseki.scans`) are skipped; readings of +inf or at or beyond the scan's max range are
  "no return": the likelihood field skips them (as nav2), the beam model scores them with its
  z_max term.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from kiseki import _core
from kiseki.filters.localize_config import LocalizeConfig
from kiseki.grid import OccupancyGrid, ray_caster
from kiseki.mapping import scan_local_map
from kiseki.scans import LaserScans

__all__ = ["ScanSpaceObservation", "scan_model", "scan_preparer"]


class ScanSpaceObservation:
    """The space observation model fed with a local map made from each 2-D scan."""

    def __init__(self, grid: OccupancyGrid) -> None:
        self.model = _core.SpaceObservationModel(grid)

    def set_scan(self, angles: np.ndarray, ranges: np.ndarray, max_range: float) -> None:

        self.model.set_local_map(scan_local_map(angles, ranges, max_range))


def scan_preparer(model, scans: LaserScans) -> Callable[[int], _core.SensorModel]:
    """``prepare(k)`` for :meth:`MonteCarloLocalizer.step`: gives scan k to a model of
    :func:`scan_model` and returns what the engine weighs with."""
    engine_model = model.model if isinstance(model, ScanSpaceObservation) else model

    def prepare(k: int) -> _core.SensorModel:
        model.set_scan(scans.angles, scans.ranges[k], scans.max_range)
        return engine_model

    return prepare


def scan_model(method: str, grid: OccupancyGrid, config: LocalizeConfig | None = None):
    """The sensor model of a method over a map; give it each scan with ``set_scan``."""
    config = config or LocalizeConfig(method=method)
    combination = getattr(_core.BeamCombination, config.combination)
    if method == "likelihood-field":
        return _core.LikelihoodFieldModel(
            grid,
            sigma_hit=config.sigma_hit,
            z_hit=config.z_hit,
            z_rand=config.z_rand,
            max_beams=config.beams,
            combination=combination,
            beam_skip=config.beam_skip,
            beam_skip_distance=config.beam_skip_distance,
            beam_skip_threshold=config.beam_skip_threshold,
            beam_skip_error_threshold=config.beam_skip_error_threshold,
        )
    if method == "beam":
        return _core.BeamModel(
            grid,
            z_hit=config.z_hit,
            z_short=config.z_short,
            z_max=config.z_max,
            z_rand=config.z_rand,
            sigma_hit=config.sigma_hit,
            lambda_short=config.lambda_short,
            max_beams=config.beams,
            combination=combination,
            caster=ray_caster(config.caster),
        )
    if method == "ray-space-observation":
        return _core.RaySpaceObservationModel(
            grid,
            sigma_hit=config.sigma_hit,
            z_hit=config.z_hit,
            z_rand=config.z_rand,
            z_intrusion=config.z_intrusion,
            lambda_short=config.lambda_short,
            max_beams=config.beams,
            agreement_skips_intrusion=config.intrusion_tolerant_resets,
        )
    if method == "space-observation":
        return ScanSpaceObservation(grid)
    raise ValueError(
        f"no sensor model for method {method!r}: use likelihood-field, beam, space-observation "
        "or ray-space-observation"
    )
