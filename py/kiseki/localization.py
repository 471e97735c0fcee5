# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Monte Carlo localization: kiseki's one particle-filter engine (C++, ``kiseki._core``) and the
Python API over it.

* :class:`MclConfig` holds the engine's parameters; :class:`MonteCarloLocalizer` is the filter
  with AMCL's update gate (predict and weigh only once the odometry has moved ``update_min_d`` or
  turned ``update_min_a`` since the last update; between updates the estimate follows the
  odometry). Log replay (:func:`localize`), global localization
  (:mod:`kiseki.global_localization`) and the thesis' route playback
  (:mod:`kiseki.teach.playback`) all step this one object.
* Sensor models: :func:`scan_model` makes nav2's ``beam`` or ``likelihood-field`` model, or the
  teaching-and-playback thesis' ``space-observation`` model fed with local maps made from each
  scan. A model written in Python plugs in through
  :meth:`MonteCarloLocalizer.step_log_likelihoods` (one log-likelihood per particle).
* Recovery: ``none``, ``augmented`` (Augmented MCL) or ``resetting`` (expansion resetting, then
  sensor resetting); see ``kiseki._core.MonteCarloLocalization``'s C++ header for the rules.
* Every stochastic part takes the seed; the same seed gives the same trajectory for any
  ``threads``.

Invalid readings (NaN, zero, negative; the log readers store them as NaN, see
:mod:`kiseki.scans`) are skipped; readings of +inf or at or beyond the scan's max range are "no
return": the likelihood field skips them (as nav2), the beam model scores them with its z_max
term. The odometry may move at most ``MAX_ODOMETRY_JUMP`` (10 m, the engine's
``kMaxOdometryJump``) between two updates; the log readers check it between consecutive scans.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field

import numpy as np
from tqdm import tqdm

from kiseki import _core
from kiseki.core import Pose2, Random, check_seed, derive_seed
from kiseki.grid import OccupancyGrid
from kiseki.scans import MAX_ODOMETRY_JUMP, LaserScans, check_odometry_jumps

__all__ = [
    "LOCALIZATION_METHODS",
    "RECOVERY_MODES",
    "REAL_ODOMETRY_ALPHAS",
    "LocalizationResult",
    "LocalizeConfig",
    "MclConfig",
    "MonteCarloLocalizer",
    "ScanSpaceObservation",
    "localize",
    "motion_alphas",
    "noisy_odometry",
    "scan_model",
    "scan_preparer",
]

LOCALIZATION_METHODS = ("odometry", "space-observation", "likelihood-field", "beam")
RECOVERY_MODES = ("none", "augmented", "resetting")
RESAMPLING_METHODS = ("multinomial", "systematic", "stratified", "residual")
# The motion noise for a log's own odometry, whose error is unknown: wide, AMCL-like values.
REAL_ODOMETRY_ALPHAS = (0.05, 0.01, 0.05, 0.01)


def _check(condition: bool, message: str) -> None:
    if not condition:
        raise ValueError(message)


@dataclass(frozen=True)
class MclConfig:
    """Parameters of the Monte Carlo engine. Defaults and their sources:

    * ``particles`` 500; with ``kld`` the maximum, ``min_particles`` the minimum (nav2: 500 and
      2000; kiseki's tracking uses fewer), ``kld_err`` 0.05 and ``kld_z`` 0.99 (nav2's pf_err
      and pf_z), bins 0.5 m x 0.5 m x 10 deg (nav2's).
    * ``resampling`` systematic when the ESS falls below ``resample_threshold`` x n (1.0:
      every update, as nav2's resample_interval 1).
    * ``recovery``: ``alpha_slow`` 0.001 and ``alpha_fast`` 0.1 (nav2's suggested values);
      resetting when the agreement falls below ``reset_threshold`` 0.6 (fewer than 60 % of the
      beams end near a wall without passing through one: a majority with a margin for people
      and furniture the map does not hold) or the likelihood drops below ``reset_likelihood_drop``
      0.5 of its long-term average (w_fast / w_slow: a place that looks alike) for 2 updates in
      a row, expansion by +-0.2 m and +-0.2 rad, a sensor reset after 4 such updates in a row
      drawing half the particles from 20,000 uniform candidates (each reset kept only if it
      explains the scan better than the cloud did by ``reset_evidence`` ln 10, a Bayes factor
      of 10); ``resetting_injects`` adds Augmented MCL's injection (off: on real logs an
      injected pose that fits one odd scan better than the cloud pulls the estimate away).
    * ``update_min_d`` / ``update_min_a``: 0 (every scan is an update); nav2 uses 0.25 m / 0.2 rad.
    """

    particles: int = 500
    kld: bool = False
    min_particles: int = 100
    kld_err: float = 0.05
    kld_z: float = 0.99
    motion_model: str = "differential"
    alphas: tuple[float, ...] = REAL_ODOMETRY_ALPHAS
    resampling: str = "systematic"
    resample_threshold: float = 0.5
    likelihood_power: float = 1.0
    recovery: str = "none"
    alpha_slow: float = 0.001
    alpha_fast: float = 0.1
    resetting_injects: bool = False
    reset_threshold: float = 0.6
    reset_likelihood_drop: float = 0.5
    reset_evidence: float = math.log(10.0)
    expansion_position: float = 0.2
    expansion_orientation: float = 0.2
    reset_after: int = 2
    sensor_reset_after: int = 4
    sensor_reset_share: float = 0.5
    sensor_reset_candidates: int = 20_000
    update_min_d: float = 0.0
    update_min_a: float = 0.0
    threads: int = 0

    def __post_init__(self) -> None:
        _check(
            isinstance(self.particles, int) and 1 <= self.particles <= 10_000_000,
            f"particles must be an integer in 1..10,000,000, got {self.particles!r}",
        )
        _check(
            isinstance(self.min_particles, int) and self.min_particles >= 1,
            f"min_particles must be an integer >= 1, got {self.min_particles!r}",
        )
        _check(
            not self.kld or self.min_particles <= self.particles,
            f"with kld, min_particles ({self.min_particles}) must not exceed particles "
            f"({self.particles}, the maximum)",
        )
        _check(
            self.motion_model in ("differential", "omnidirectional"),
            f"motion_model must be differential or omnidirectional, got {self.motion_model!r}",
        )
        _check(
            len(self.alphas) in (4, 5) and all(a >= 0 and math.isfinite(a) for a in self.alphas),
            f"alphas must be 4 (or 5) finite numbers >= 0, got {self.alphas}",
        )
        _check(
            self.resampling in RESAMPLING_METHODS,
            f"resampling must be one of {', '.join(RESAMPLING_METHODS)}, got {self.resampling!r}",
        )
        _check(
            self.recovery in RECOVERY_MODES,
            f"recovery must be one of {', '.join(RECOVERY_MODES)}, got {self.recovery!r}",
        )
        _check(
            isinstance(self.threads, int) and 0 <= self.threads <= 1024,
            f"threads must be an integer in 0..1024 (0 = every core), got {self.threads!r}",
        )
        for name in ("update_min_d", "update_min_a"):
            value = getattr(self, name)
            _check(value >= 0 and math.isfinite(value), f"{name} must be >= 0, got {value}")
        _check(
            self.update_min_d < MAX_ODOMETRY_JUMP,
            f"update_min_d must be below kiseki's limit of {MAX_ODOMETRY_JUMP:g} m for the "
            f"odometry between two updates, got {self.update_min_d}",
        )
        self.to_core().validate()  # the engine's own checks, as ValueError

    def to_core(self) -> _core.MclParams:
        p = _core.MclParams()
        p.particles = self.particles
        p.kld = self.kld
        p.kld_min_particles = self.min_particles
        p.kld_err = self.kld_err
        p.kld_z = self.kld_z
        p.motion_model = self.motion_model
        p.alphas = list(self.alphas)
        p.resampling = self.resampling
        p.resample_threshold = self.resample_threshold
        p.likelihood_power = self.likelihood_power
        p.recovery = self.recovery
        p.alpha_slow = self.alpha_slow
        p.alpha_fast = self.alpha_fast
        p.resetting_injects = self.resetting_injects
        p.reset_threshold = self.reset_threshold
        p.reset_likelihood_drop = self.reset_likelihood_drop
        p.reset_evidence = self.reset_evidence
        p.expansion_position = self.expansion_position
        p.expansion_orientation = self.expansion_orientation
        p.reset_after = self.reset_after
        p.sensor_reset_after = self.sensor_reset_after
        p.sensor_reset_share = self.sensor_reset_share
        p.sensor_reset_candidates = self.sensor_reset_candidates
        p.threads = self.threads
        return p


def _odometry_pose(odometry, last: np.ndarray | None) -> np.ndarray:
    """An odometry pose (x, y, theta) checked before it moves the particles: finite, and at
    most MAX_ODOMETRY_JUMP from the last update (the engine's own limit)."""
    pose = np.asarray(odometry, dtype=float)
    if pose.shape != (3,) or not np.isfinite(pose).all():
        raise ValueError(f"odometry must be 3 finite numbers (x, y, theta), got {odometry!r}")
    if last is not None:
        step = math.hypot(*(pose[:2] - last[:2]))
        if not step <= MAX_ODOMETRY_JUMP:
            raise ValueError(
                f"odometry jumps {step:.4g} m since the last update: more than kiseki's limit "
                f"of {MAX_ODOMETRY_JUMP:g} m between two updates"
            )
    return pose


def _moved(a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    step = Pose2(*a).between(Pose2(*b))
    return math.hypot(step.x, step.y), abs(step.theta)


class MonteCarloLocalizer:
    """The engine with AMCL's update gate, stepped once per measurement by every driver."""

    def __init__(
        self, config: MclConfig, seed: int, free_space: OccupancyGrid | None = None
    ) -> None:
        self.config = config
        self.engine = _core.MonteCarloLocalization(config.to_core(), seed)
        if free_space is not None:
            self.engine.set_free_space(free_space)
        self._last_update: np.ndarray | None = None
        self._estimate_at_update = np.zeros(3)
        self.estimate = np.zeros(3)
        self.last_report: _core.UpdateReport | None = None
        self.updates = 0

    def initialize(self, pose, sd: tuple[float, float, float]) -> None:
        self.engine.initialize_gaussian(Pose2(*np.asarray(pose, dtype=float)), *sd)
        self.estimate = self.engine.estimate().to_array()

    def initialize_global(self) -> None:
        """Particles uniform over the free space given at construction."""
        if not self.engine.has_free_space:
            raise ValueError("global localization needs a map with free cells (free_space)")
        self.engine.initialize_uniform()
        self.estimate = self.engine.estimate().to_array()

    def due(self, odometry: np.ndarray) -> bool:
        """Whether a measurement update is due at this odometry pose (AMCL's gate)."""
        if self._last_update is None:
            return True
        d, a = _moved(self._last_update, odometry)
        return d >= self.config.update_min_d or a >= self.config.update_min_a

    def step(
        self, odometry, prepare: Callable[[], _core.SensorModel] | None
    ) -> _core.UpdateReport | None:
        """Moves the particles by the odometry since the last update and weighs them with the
        model ``prepare()`` returns (called only when an update is due), or, when none is due,
        moves the estimate with the odometry. Returns the update's report or None."""
        odometry = _odometry_pose(odometry, self._last_update)
        if prepare is None:
            self._follow(odometry)
            return None
        if not self._predict_if_due(odometry):
            return None
        return self._updated(odometry, self.engine.update(prepare()))

    def step_log_likelihoods(
        self,
        odometry,
        log_likelihoods: Callable[[np.ndarray], np.ndarray],
        readings: int = 1,
        agreement: float = float("nan"),
    ) -> _core.UpdateReport | None:
        """As :meth:`step` for a model written elsewhere: ``log_likelihoods(poses)`` gives one
        log-likelihood per particle pose (n, 3)."""
        odometry = _odometry_pose(odometry, self._last_update)
        if not self._predict_if_due(odometry):
            return None
        log_l = np.asarray(log_likelihoods(self.engine.poses), dtype=float)
        report = self.engine.update_log_likelihoods(log_l, readings, agreement)
        return self._updated(odometry, report)

    def _predict_if_due(self, odometry: np.ndarray) -> bool:
        """AMCL's gate: if an update is due, moves the particles by the odometry since the last
        one and returns True; else moves the estimate with the odometry."""
        if not self.due(odometry):
            self._follow(odometry)
            return False
        if self._last_update is not None:
            self.engine.predict(Pose2(*self._last_update), Pose2(*odometry))
        return True

    def _follow(self, odometry: np.ndarray) -> None:
        if self._last_update is None:
            return
        step = Pose2(*self._last_update).between(Pose2(*odometry))
        self.estimate = (Pose2(*self._estimate_at_update) * step).to_array()

    def _updated(self, odometry: np.ndarray, report: _core.UpdateReport) -> _core.UpdateReport:
        self._last_update = odometry
        self.estimate = self._estimate_at_update = self.engine.posterior().to_array()
        self.last_report = report
        self.updates += 1
        return report

    @property
    def poses(self) -> np.ndarray:
        return self.engine.poses

    @property
    def weights(self) -> np.ndarray:
        return self.engine.weights

    @property
    def reliability(self) -> float:
        return float(self.engine.reliability)

    @property
    def size(self) -> int:
        return int(self.engine.size)


class ScanSpaceObservation:
    """The space observation model fed with a local map made from each 2-D scan."""

    def __init__(self, grid: OccupancyGrid) -> None:
        self.model = _core.SpaceObservationModel(grid)

    def set_scan(self, angles: np.ndarray, ranges: np.ndarray, max_range: float) -> None:
        from kiseki.mapping import scan_local_map

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
    * ``combination`` product (beams independent) or nav2 (1 + sum pz^3).
    * ``alphas`` None: :func:`motion_alphas` (the noise the odometry has).
    """

    method: str = "likelihood-field"
    seed: int = 0
    odometry_noise: float = 0.0  # SD as a fraction of each odometry increment's component
    particles: int = 500
    initial_sd: tuple[float, float, float] = (0.1, 0.1, math.radians(3.0))
    alphas: tuple[float, ...] | None = None
    beams: int = 90
    sigma_hit: float = 0.2
    z_hit: float = 0.95
    z_rand: float = 0.05
    z_short: float = 0.05
    z_max: float = 0.05
    lambda_short: float = 0.1
    combination: str = "product"
    kld: bool = False
    min_particles: int = 100
    resampling: str = "systematic"
    resample_threshold: float = 0.5
    recovery: str = "none"
    update_min_d: float = 0.0
    update_min_a: float = 0.0
    threads: int = 0
    global_start: bool = False  # start uniformly over the map (no initial pose)
    resetting_injects: bool = False  # resetting adds Augmented MCL's injection (MclConfig)
    likelihood_power: float = 1.0

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
        )
    if method == "space-observation":
        return ScanSpaceObservation(grid)
    raise ValueError(
        f"no sensor model for method {method!r}: use likelihood-field, beam or space-observation"
    )


def motion_alphas(config: LocalizeConfig, scans: LaserScans) -> tuple[float, ...]:
    """The filter's motion noise: `config.alphas` if given, else the noise the odometry has.

    That is the log's own odometry error plus the noise `noisy_odometry` adds. The log's own:
    none when its odometry equals its reference poses (the CARMEN "corrected" logs), else
    unknown, and then `REAL_ODOMETRY_ALPHAS`. The added noise has SD F |component| on each
    increment, so in the motion model's terms a rotation SD of F |rotation| and a translation
    SD of F |translation|: alpha1 = alpha3 = F^2; the cross terms (translation turning the
    heading, rotation moving the robot) get a tenth of that. A filter told of more noise than
    the odometry has spreads its particles further than one scan can pull them back, which the
    weakly peaked space observation model does not survive on long corridors."""
    if config.alphas is not None:
        return tuple(config.alphas)
    exact = scans.odometry.shape == scans.poses.shape and np.allclose(
        scans.odometry, scans.poses, atol=1e-6
    )
    base = (0.0, 0.0, 0.0, 0.0) if exact else REAL_ODOMETRY_ALPHAS
    f2 = config.odometry_noise**2
    added = (f2, 0.1 * f2, f2, 0.1 * f2)
    return tuple(max(b + a, 1e-6) for b, a in zip(base, added, strict=True))


def noisy_odometry(poses: np.ndarray, fraction: float, seed: int) -> np.ndarray:
    """Odometry rebuilt from the increments of `poses` (in each previous pose's frame), each
    component perturbed by zero-mean Gaussian noise with SD = fraction x |component|."""
    poses = np.asarray(poses, dtype=float)
    rng = Random(seed)
    out = np.empty_like(poses)
    out[0] = poses[0]
    current = Pose2(*poses[0])
    for k in range(1, len(poses)):
        step = Pose2(*poses[k - 1]).between(Pose2(*poses[k])).to_array()
        if fraction > 0:
            step = step + fraction * np.abs(step) * rng.normal(0.0, 1.0, 3)
        current = current * Pose2(*step)
        out[k] = current.to_array()
    return out


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
    scans: LaserScans, grid: OccupancyGrid, config: LocalizeConfig, progress: bool = False
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
    prepare = scan_preparer(scan_model(config.method, grid, config), scans)
    estimates = np.empty((n, 3))
    reliability = np.empty(n)
    counts = np.empty(n, dtype=np.int64)
    updated = np.zeros(n, dtype=bool)
    resets = np.full(n, "none", dtype=object)
    seconds: list[float] = []

    for k in tqdm(range(n), desc=config.method, unit="scan", disable=not progress):
        start = time.perf_counter()
        report = localizer.step(odom[k], lambda k=k: prepare(k))
        if report is not None:
            seconds.append(time.perf_counter() - start)
            updated[k] = True
            resets[k] = report.reset
        estimates[k] = localizer.estimate
        reliability[k] = localizer.reliability
        counts[k] = localizer.size
    return LocalizationResult(
        estimates,
        reliability,
        counts,
        updated,
        np.asarray(seconds),
        resets.astype(str),
        config,
    )
