# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Tracking a robot along a log with the engine (:func:`localize`), and the sensor models it
weighs with.

* Sensor models: :func:`scan_model` makes nav2's ``beam`` or ``likelihood-field`` model, or the
  teaching-and-playback thesis' ``space-observation`` model fed with local maps made from each
  scan. A model written in Python plugs in through
  :meth:`~kiseki.filters.engine.MonteCarloLocalizer.step_log_likelihoods` (one log-likelihood
  per particle).
* Invalid readings (NaN, zero, negative; the log readers store them as NaN, see
  :mod:`kiseki.scans`) are skipped; readings of +inf or at or beyond the scan's max range are
  "no return": the likelihood field skips them (as nav2), the beam model scores them with its
  z_max term.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field

import numpy as np
from tqdm import tqdm

from kiseki import _core
from kiseki.core import check_seed, derive_seed
from kiseki.filters.engine import REAL_ODOMETRY_ALPHAS, MclConfig, MonteCarloLocalizer
from kiseki.filters.odometry_noise import motion_alphas, noisy_odometry
from kiseki.filters.reliability import (
    LEARNED_RELIABILITY,
    RELIABILITY_ESTIMATES,
    LearnedReliability,
    ReliabilityModel,
)
from kiseki.filters.relocalization import RelocalizeConfig, Relocalizer
from kiseki.grid import DEFAULT_RAY_CASTER, OccupancyGrid, ray_caster
from kiseki.mapping import scan_local_map
from kiseki.scans import LaserScans, check_odometry_jumps

__all__ = [
    "LOCALIZATION_METHODS",
    "LocalizationResult",
    "LocalizeConfig",
    "ScanSpaceObservation",
    "localize",
    "scan_model",
    "scan_preparer",
]

LOCALIZATION_METHODS = (
    "odometry",
    "space-observation",
    "ray-space-observation",
    "likelihood-field",
    "beam",
)


def _check(condition: bool, message: str) -> None:
    """A config's check: ValueError with `message` unless `condition` holds."""
    if not condition:
        raise ValueError(message)


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


@dataclass(frozen=True)
class LocalizeConfig:
    """Localization along a log: the method, its sensor model and the engine's settings.

    * ``method`` likelihood-field: nav2 AMCL's model and the baseline MCL (Probabilistic Robotics);
      what ``kiseki localize`` runs by default (it reads this default).
    * ``beams`` 90: nav2's max_beams rule (every k-th beam); 90 is half of a 180-beam scan.
    * ``sigma_hit`` 0.2 m (nav2); ``z_hit`` 0.95 / ``z_rand`` 0.05 (Probabilistic Robotics'
      likelihood field); the beam model adds ``z_short``, ``z_max``, ``lambda_short`` (nav2's).
    * ``ray-space-observation`` (kiseki's, ``kiseki._core.RaySpaceObservationModel``): the
      likelihood field's terms, the thesis' penetration per ray, and ``z_intrusion`` 0.95 (=
      z_hit: equal prior odds that a beam's end is a mapped wall or an unmapped object) times
      the beam model's ``lambda_short`` density for a beam stopped short in free space.
    * ``combination`` product (beams independent) or nav2 (1 + sum pz^3).
    * ``caster``: how the beam model casts z* (:mod:`kiseki.grid.casters`: both exact, the same
      weights); the C++ model's default.
    * ``alphas`` None: :func:`motion_alphas` (the noise the odometry has).
    * the engine's settings (particles, KLD, resampling, recovery, update thresholds,
      threads) default to :class:`MclConfig`'s, which holds each of them once.
    """

    method: str = "likelihood-field"
    seed: int = 0
    odometry_noise: float = 0.0  # SD as a fraction of each odometry increment's component
    particles: int = MclConfig.particles
    initial_sd: tuple[float, float, float] = (0.1, 0.1, math.radians(3.0))
    alphas: tuple[float, ...] | None = None
    beams: int = 90
    sigma_hit: float = 0.2
    z_hit: float = 0.95
    z_rand: float = 0.05
    z_short: float = 0.05
    z_max: float = 0.05
    lambda_short: float = 0.1
    z_intrusion: float = 0.95
    combination: str = "product"
    caster: str = DEFAULT_RAY_CASTER
    kld: bool = MclConfig.kld
    min_particles: int = MclConfig.min_particles
    resampling: str = MclConfig.resampling
    resample_threshold: float = MclConfig.resample_threshold
    recovery: str = MclConfig.recovery
    update_min_d: float = MclConfig.update_min_d
    update_min_a: float = MclConfig.update_min_a
    threads: int = MclConfig.threads
    global_start: bool = False  # start uniformly over the map (no initial pose)
    resetting_injects: bool = MclConfig.resetting_injects  # Augmented MCL's injection
    # the sensor reset's candidates: uniform or around the matcher's hypotheses (MclConfig)
    sensor_reset_proposal: str = MclConfig.sensor_reset_proposal
    reset_look_elsewhere: bool = MclConfig.reset_look_elsewhere
    likelihood_power: float = MclConfig.likelihood_power
    # the `reliability` of the result: the engine's "agreement" or the "learned" probability
    # (kiseki.filters.reliability)
    reliability: str = "agreement"

    def __post_init__(self) -> None:
        _check(
            self.method in LOCALIZATION_METHODS,
            f"method must be one of {', '.join(LOCALIZATION_METHODS)}, got {self.method!r}",
        )
        check_seed(self.seed)
        _check(
            self.odometry_noise >= 0 and math.isfinite(self.odometry_noise),
            f"odometry noise must be >= 0, got {self.odometry_noise}",
        )
        _check(
            len(self.initial_sd) == 3 and all(s >= 0 and math.isfinite(s) for s in self.initial_sd),
            f"initial_sd must be three finite numbers >= 0, got {self.initial_sd}",
        )
        _check(
            isinstance(self.beams, int) and self.beams >= 0,
            f"beams must be an integer >= 0 (0 = every beam), got {self.beams!r}",
        )
        _check(
            self.combination in ("product", "nav2"),
            f"combination must be product or nav2, got {self.combination!r}",
        )
        ray_caster(self.caster)  # ValueError unless it names one
        for name in ("sigma_hit", "lambda_short"):
            value = getattr(self, name)
            _check(value > 0 and math.isfinite(value), f"{name} must be > 0, got {value}")
        for name in ("z_hit", "z_rand", "z_short", "z_max"):
            value = getattr(self, name)
            _check(value >= 0 and math.isfinite(value), f"{name} must be >= 0, got {value}")
        _check(self.z_hit + self.z_rand > 0, "z_hit and z_rand must not both be 0")
        if self.alphas is not None:
            _check(
                len(self.alphas) in (4, 5)
                and all(a >= 0 and math.isfinite(a) for a in self.alphas),
                f"alphas must be 4 (or 5) finite numbers >= 0, got {self.alphas}",
            )
        _check(
            self.reliability in RELIABILITY_ESTIMATES,
            f"reliability must be one of {', '.join(RELIABILITY_ESTIMATES)}, "
            f"got {self.reliability!r}",
        )
        self.mcl(REAL_ODOMETRY_ALPHAS)  # the engine's checks, as ValueError

    def mcl(self, alphas: tuple[float, ...]) -> MclConfig:
        return MclConfig(
            particles=self.particles,
            kld=self.kld,
            min_particles=self.min_particles,
            alphas=tuple(alphas),
            resampling=self.resampling,
            resample_threshold=self.resample_threshold,
            likelihood_power=self.likelihood_power,
            recovery=self.recovery,
            resetting_injects=self.resetting_injects,
            sensor_reset_proposal=self.sensor_reset_proposal,
            reset_look_elsewhere=self.reset_look_elsewhere,
            update_min_d=self.update_min_d,
            update_min_a=self.update_min_a,
            threads=self.threads,
        )

    def to_dict(self) -> dict:
        return asdict(self)


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
        )
    if method == "space-observation":
        return ScanSpaceObservation(grid)
    raise ValueError(
        f"no sensor model for method {method!r}: use likelihood-field, beam, space-observation "
        "or ray-space-observation"
    )


@dataclass(frozen=True)
class LocalizationResult:
    estimates: np.ndarray  # (n, 3) estimated sensor pose after each scan
    reliability: np.ndarray  # (n,) the engine's reliability estimate after each scan
    particle_counts: np.ndarray  # (n,)
    updated: np.ndarray  # (n,) bool: a measurement update was made at this scan
    update_seconds: (
        np.ndarray
    )  # (updates,) wall time of each update (motion + weighing + resampling)
    resets: np.ndarray  # (n,) str: none, expansion or sensor
    # (n,) the engine's agreement-based estimate, whichever `reliability` holds
    agreement_reliability: np.ndarray
    # (n, 2) the learned estimate's features at each update (NaN elsewhere, and when
    # config.reliability is "agreement")
    reliability_features: np.ndarray
    config: LocalizeConfig = field(repr=False)


def _check_scans(scans: LaserScans, grid: OccupancyGrid) -> None:
    if len(scans) == 0:
        raise ValueError("the log has no scans")
    if scans.ranges.ndim != 2 or scans.ranges.shape[1] != scans.angles.shape[0]:
        raise ValueError(
            f"scans: {scans.ranges.shape[1] if scans.ranges.ndim == 2 else '?'} ranges per scan "
            f"but {scans.angles.shape[0]} beam angles"
        )
    if not np.isfinite(scans.odometry).all():
        raise ValueError("scans: the odometry has NaN or infinite poses")
    if not np.any(grid.cells == 0):
        raise ValueError("the map has no free cell (empty or all unknown): nothing to localize in")


def localize(
    scans: LaserScans,
    grid: OccupancyGrid,
    config: LocalizeConfig,
    progress: bool = False,
    reliability_model: ReliabilityModel = LEARNED_RELIABILITY,
) -> LocalizationResult:
    """Localization along a log: tracking from its first reference pose, or from a uniform start
    over the map's free cells with ``config.global_start``. Estimates are sensor poses."""
    _check_scans(scans, grid)
    odom = noisy_odometry(scans.odometry, config.odometry_noise, derive_seed(config.seed, 1))
    noise = f" with noise {config.odometry_noise:g}" if config.odometry_noise else ""
    check_odometry_jumps(f"the odometry{noise}", scans.times, odom)
    n = len(scans)
    if config.method == "odometry":
        return LocalizationResult(
            odom,
            np.full(n, np.nan),
            np.zeros(n, dtype=np.int64),
            np.zeros(n, dtype=bool),
            np.zeros(0),
            np.full(n, "none"),
            np.full(n, np.nan),
            np.full((n, 2), np.nan),
            config,
        )
    if not config.global_start and not np.isfinite(scans.poses[0]).all():
        raise ValueError("the log has no reference pose to start from: use a global start")
    localizer = MonteCarloLocalizer(
        config.mcl(motion_alphas(config, scans)), derive_seed(config.seed, 2), grid
    )
    if config.global_start:
        localizer.initialize_global()
    else:
        localizer.initialize(scans.poses[0], config.initial_sd)
    matcher = config.recovery == "resetting" and config.sensor_reset_proposal == "matcher"
    if matcher:  # scores with this config's likelihood-field terms, RelocalizeConfig's beams
        terms = dict(sigma_hit=config.sigma_hit, z_hit=config.z_hit, z_rand=config.z_rand)
        rc = RelocalizeConfig(**terms, threads=config.threads)
        localizer.set_matcher(Relocalizer(grid, scans.max_range, rc))
    prepare = scan_preparer(scan_model(config.method, grid, config), scans)
    learned = LearnedReliability(reliability_model) if config.reliability == "learned" else None
    estimates = np.empty((n, 3))
    reliability = np.empty(n)
    engine_reliability = np.empty(n)
    features = np.full((n, 2), np.nan)
    # the learned estimate before the first update: 1 from a known pose, 0 from a uniform start
    probability = 0.0 if config.global_start else 1.0
    counts = np.empty(n, dtype=np.int64)
    updated = np.zeros(n, dtype=bool)
    resets = np.full(n, "none", dtype=object)
    seconds: list[float] = []

    weighed_with: list = [None]  # the model holding the scan the last update weighed with

    def prepared(k: int):
        weighed_with[0] = prepare(k)
        return weighed_with[0]

    for k in tqdm(range(n), desc=config.method, unit="scan", disable=not progress):
        start = time.perf_counter()
        scan = (scans.angles, scans.ranges[k]) if matcher else None
        report = localizer.step(odom[k], lambda k=k: prepared(k), scan)
        if report is not None:
            seconds.append(time.perf_counter() - start)
            updated[k] = True
            resets[k] = report.reset
            if learned is not None:
                probability, features[k] = learned.update(
                    weighed_with[0], localizer.estimate, report.agreement
                )
        estimates[k] = localizer.estimate
        engine_reliability[k] = localizer.reliability
        reliability[k] = engine_reliability[k] if learned is None else probability
        counts[k] = localizer.size
    return LocalizationResult(
        estimates,
        reliability,
        counts,
        updated,
        np.asarray(seconds),
        resets.astype(str),
        engine_reliability,
        features,
        config,
    )
