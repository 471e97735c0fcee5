# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""A time budget per measurement update, kept by choosing the particle and beam counts from a
deterministic cost model (``LocalizeConfig.budget_ms``, ``kiseki localize --budget-ms``).

The cost model: the time of one update (motion, weighing, resampling) of N particles with B
beams is

    t(N, B) = fixed_ms + per_particle_ms N + per_beam_ms N B,

the engine's loops being over particles (motion, resampling: N) and over particles x beams
(weighing: N B evaluations of a beam; beam skipping's count doubles it). :func:`calibrate`
fits the three coefficients once, by non-negative least squares, to the 90th percentile of
timed updates of the real engine on the run's map and log, with the run's model and threads,
at 3 particle counts x 3 beam counts (1/16, 1/4 and all of the particles asked for; 1/4, 1/2
and all of the beams). The model is saved as JSON with the run's output, and can be given back
(:meth:`CostModel.load`, ``--cost-model FILE``): nothing else is timed.

The choice (:func:`choose_counts`) is a pure function of the budget, the cost model, the
particle bounds and the beams asked for, never of a time measured during the run, so one seed
and one cost model give one trajectory, for any thread count. Its rule, with T = share x
budget (``budget_share`` 0.8: the prediction leaves a fifth of the budget to what the model
does not hold), and the particle bounds [``min_particles``, ``particles``] (KLD sampling's;
without KLD ``min_particles`` is only the budget's floor):

1. Keep the beams asked for, B, and take the largest N with t(N, B) <= T, capped at the
   maximum particle count (with KLD sampling its maximum: KLD then adapts below it, down to
   its minimum).
2. If even the minimum particle count does not fit, keep the minimum and cut the beams to the
   largest B' with t(N_min, B') <= T, down to ``budget_min_beams``.
3. If that does not fit either, run at the minimum and the floor, and say the budget is not
   kept (``fits`` False): the prediction is reported.

The choice is fixed for the run; sensor resetting's candidates are not budgeted.
"""

from __future__ import annotations

import dataclasses
import json
import math
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.optimize import nnls

from kiseki._support.atomic import atomic_write
from kiseki._support.inputs import MIB, read_input_text
from kiseki._support.real_numbers import check_number
from kiseki._support.schema import MAGNITUDE_LIMIT
from kiseki.filters.engine import MonteCarloLocalizer
from kiseki.filters.localize_config import LocalizeConfig
from kiseki.filters.scan_models import scan_model
from kiseki.grid import OccupancyGrid
from kiseki.scans import LaserScans

__all__ = [
    "BudgetChoice",
    "CostModel",
    "budgeted_config",
    "calibrate",
    "choose_counts",
    "requested_beams",
]

COST_MODEL_KIND = "kiseki update cost model"
COST_MODEL_LIMIT = MIB  # a saved model is a few hundred bytes of JSON
CALIBRATION_PARTICLES = (1 / 16, 1 / 4, 1.0)  # shares of the particles asked for
CALIBRATION_BEAMS = (1 / 4, 1 / 2, 1.0)  # shares of the beams asked for
CALIBRATION_WARMUP = 3  # updates not timed (the first tabulates the field)
CALIBRATION_UPDATES = 10  # updates timed per setting
CALIBRATION_QUANTILE = 0.9  # of each setting's times: the prediction is of a slow update
_COEFFICIENTS = ("fixed_ms", "per_particle_ms", "per_beam_ms")


@dataclass(frozen=True)
class CostModel:
    """t(N, B) = fixed_ms + per_particle_ms N + per_beam_ms N B, in ms per update, and where it
    was calibrated (``calibration``: free-form, saved as it is)."""

    fixed_ms: float
    per_particle_ms: float
    per_beam_ms: float
    calibration: dict = dataclasses.field(default_factory=dict)

    def __post_init__(self) -> None:
        for name in _COEFFICIENTS:
            check_number(getattr(self, name), name, 0.0, MAGNITUDE_LIMIT, unit="ms")
        if self.per_particle_ms + self.per_beam_ms <= 0:
            raise ValueError("per_particle_ms and per_beam_ms must not both be 0")

    def predict_ms(self, particles: int, beams: int) -> float:
        return self.fixed_ms + particles * (self.per_particle_ms + self.per_beam_ms * beams)

    def to_dict(self) -> dict:
        formula = "t_ms = fixed_ms + per_particle_ms * N + per_beam_ms * N * B"
        return {"kind": COST_MODEL_KIND, "formula": formula, **dataclasses.asdict(self)}

    def save(self, path: Path) -> Path:
        text = json.dumps(self.to_dict(), indent=2) + "\n"
        atomic_write(path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))
        return path

    @classmethod
    def load(cls, path: Path) -> CostModel:
        """A saved cost model; ValueError naming the file and the problem otherwise."""
        path = Path(path)
        try:  # a device, FIFO or oversized file is refused unread (read_input_text)
            doc = json.loads(read_input_text(path, "cost models", COST_MODEL_LIMIT))
        except OSError as err:
            raise ValueError(f"{path}: cannot read the cost model ({err.strerror})") from None
        except (UnicodeDecodeError, json.JSONDecodeError) as err:
            raise ValueError(f"{path}: not a cost model: not JSON ({err})") from None
        if not isinstance(doc, dict) or doc.get("kind") != COST_MODEL_KIND:
            raise ValueError(f'{path}: not a cost model (no "kind": "{COST_MODEL_KIND}")')
        missing = [name for name in _COEFFICIENTS if name not in doc]
        if missing:
            raise ValueError(f"{path}: not a cost model: no {', '.join(missing)}")
        calibration = doc.get("calibration", {})
        try:
            return cls(*(doc[name] for name in _COEFFICIENTS), calibration=calibration)
        except ValueError as err:
            raise ValueError(f"{path}: invalid cost model: {err}") from None


@dataclass(frozen=True)
class BudgetChoice:
    """What the budget chose: the particle count (with KLD its maximum), the beams (nav2's
    max_beams), the cost model's prediction for them and whether it keeps the budget."""

    budget_ms: float
    particles: int
    beams: int
    predicted_ms: float
    fits: bool

    def describe(self) -> str:
        kept = "keeps" if self.fits else "cannot keep"
        return (
            f"budget {self.budget_ms:g} ms: {self.particles:,} particles x {self.beams} beams, "
            f"predicted {self.predicted_ms:.2f} ms per update ({kept} the budget)"
        )


def choose_counts(
    budget_ms: float,
    cost: CostModel,
    min_particles: int,
    max_particles: int,
    beams: int,
    min_beams: int,
    share: float,
) -> BudgetChoice:
    """The particle and beam counts for a budget, by the module's rule (1-3)."""
    check_number(budget_ms, "the budget", 0.0, low_open=True, unit="ms")
    if not 1 <= min_particles <= max_particles or beams < 1 or min_beams < 1:
        raise ValueError(
            f"need 1 <= min_particles ({min_particles}) <= max_particles ({max_particles}), "
            f"beams ({beams}) >= 1 and min_beams ({min_beams}) >= 1"
        )
    target = share * budget_ms
    per_particle = cost.per_particle_ms + cost.per_beam_ms * beams
    fit = math.floor((target - cost.fixed_ms) / per_particle)  # rule 1
    while fit >= min_particles and cost.predict_ms(fit, beams) > target:  # rounding
        fit -= 1
    if fit >= min_particles:
        n = min(fit, max_particles)
        return BudgetChoice(budget_ms, n, beams, cost.predict_ms(n, beams), True)
    floor_beams = min(min_beams, beams)
    b = floor_beams
    if cost.per_beam_ms > 0:  # rule 2: the largest B' with t(N_min, B') <= T
        room = (target - cost.fixed_ms) / min_particles - cost.per_particle_ms
        b = min(beams, max(floor_beams, math.floor(room / cost.per_beam_ms)))
        while b > floor_beams and cost.predict_ms(min_particles, b) > target:  # rounding
            b -= 1
    predicted = cost.predict_ms(min_particles, b)
    return BudgetChoice(budget_ms, min_particles, b, predicted, predicted <= target)  # rule 3


def requested_beams(config: LocalizeConfig, scans: LaserScans) -> int:
    """The beams the config asks for on this log: max_beams, or every beam of a scan."""
    every = int(scans.angles.shape[0])
    return every if config.beams == 0 else min(config.beams, every)


def _particle_bounds(config: LocalizeConfig) -> tuple[int, int]:
    return min(config.min_particles, config.particles), config.particles


def budgeted_config(
    config: LocalizeConfig, scans: LaserScans, cost: CostModel
) -> tuple[LocalizeConfig, BudgetChoice]:
    """The config the run uses under ``config.budget_ms``: its particles (with KLD the maximum)
    and beams replaced by :func:`choose_counts`' choice."""
    low, high = _particle_bounds(config)
    choice = choose_counts(
        config.budget_ms,
        cost,
        low,
        high,
        requested_beams(config, scans),
        config.budget_min_beams,
        config.budget_share,
    )
    run = dataclasses.replace(
        config,
        particles=choice.particles,
        beams=choice.beams,
        min_particles=min(config.min_particles, choice.particles),
    )
    return run, choice


def _update_times(scans, grid, config: LocalizeConfig, alphas, particles: int, beams: int):
    """Seconds per update of the engine along the log's first scans, as localize() times them
    (the scan given to the model, motion, weighing, resampling); every update resamples."""
    run = dataclasses.replace(config, particles=particles, beams=beams, min_particles=particles)
    mcl = dataclasses.replace(run.mcl(alphas), resample_threshold=1.0)
    localizer = MonteCarloLocalizer(mcl, 0, grid)
    start = scans.poses[0] if np.isfinite(scans.poses[0]).all() else scans.odometry[0]
    localizer.initialize(start, config.initial_sd)
    model = scan_model(config.method, grid, run)
    times = []
    for k in range(min(len(scans), CALIBRATION_WARMUP + CALIBRATION_UPDATES)):
        begin = time.perf_counter()
        model.set_scan(scans.angles, scans.ranges[k], scans.max_range)
        localizer.step(scans.odometry[k], lambda: model)
        times.append(time.perf_counter() - begin)
    return times[CALIBRATION_WARMUP:] or times


def calibrate(
    scans: LaserScans, grid: OccupancyGrid, config: LocalizeConfig, alphas: tuple[float, ...]
) -> CostModel:
    """Times the real update on this map and log with the config's model and threads, and fits
    the cost model (see the module's docstring). The only place a budget measures time."""
    low, high = _particle_bounds(config)
    beams = requested_beams(config, scans)
    counts = sorted({max(low, round(high * f)) for f in CALIBRATION_PARTICLES})
    beam_counts = sorted({max(1, round(beams * f)) for f in CALIBRATION_BEAMS})
    rows, quantiles = [], []
    for n in counts:
        for b in beam_counts:
            times = _update_times(scans, grid, config, alphas, n, b)
            rows.append((1.0, n, n * b))
            quantiles.append(1000.0 * float(np.quantile(times, CALIBRATION_QUANTILE)))
    a = np.asarray(rows)
    scale = a.max(axis=0)  # columns of 1, N and N B differ by 10^7: solve on a common scale
    coef, _ = nnls(a / scale, np.asarray(quantiles))
    coef = coef / scale
    if coef[1] + coef[2] <= 0:  # times flat in N (a tiny log): charge it all per particle
        coef[1] = max(quantiles) / max(counts)
    calibration = {
        "method": config.method,
        "threads": config.threads,
        "beam_skip": config.beam_skip,
        "kld": config.kld,
        "map_cells": [grid.width, grid.height],
        "particles": counts,
        "beams": beam_counts,
        "updates_timed": CALIBRATION_UPDATES,
        "quantile": CALIBRATION_QUANTILE,
        "quantile_ms": [round(q, 4) for q in quantiles],
    }
    return CostModel(float(coef[0]), float(coef[1]), float(coef[2]), calibration)
