# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""kiseki's one particle-filter engine (C++, ``kiseki._core``) as Python sees it:
:class:`MclConfig` holds the engine's parameters; :class:`MonteCarloLocalizer` is the filter
with AMCL's update gate (predict and weigh only once the odometry has moved ``update_min_d`` or
turned ``update_min_a`` since the last update; between updates the estimate follows the
odometry). Log replay (:func:`kiseki.filters.tracking.localize`), global localization
(:mod:`kiseki.filters.global_localization`) and the thesis' route playback all step this one
object.

* Recovery: ``none``, ``augmented`` (Augmented MCL) or ``resetting`` (expansion resetting, then
  sensor resetting); see ``kiseki._core.MonteCarloLocalization``'s C++ header for the rules.
* Every stochastic part takes the seed; the same seed gives the same trajectory for any
  ``threads``.
* The odometry may move at most ``MAX_ODOMETRY_JUMP`` (10 m, the engine's
  ``kMaxOdometryJump``) between two updates; the log readers check it between consecutive
  scans.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, fields

import numpy as np

from kiseki import _core
from kiseki._support.counts import check_count
from kiseki._support.field_types import check_field_types
from kiseki._support.options import PARTICLE_LIMIT, THREAD_LIMIT
from kiseki._support.real_numbers import check_number
from kiseki._support.schema import INT32_MAX
from kiseki.core import Pose2, check_seed
from kiseki.filters.initial_pose import check_particles, check_start
from kiseki.grid import OccupancyGrid
from kiseki.scans import MAX_ODOMETRY_JUMP

__all__ = [
    "RECOVERY_MODES",
    "REAL_ODOMETRY_ALPHAS",
    "RESAMPLING_METHODS",
    "RESET_PROPOSALS",
    "MclConfig",
    "MonteCarloLocalizer",
]

RECOVERY_MODES = ("none", "augmented", "resetting")
RESAMPLING_METHODS = ("multinomial", "systematic", "stratified", "residual")
RESET_PROPOSALS = ("uniform", "matcher")
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
    * ``sensor_reset_proposal`` uniform (the candidates uniform over the free cells, as before
      the matcher existed) or matcher (around the correlative scan matcher's hypotheses for the
      current scan: :meth:`MonteCarloLocalizer.set_matcher` and the scan in :meth:`step`);
      ``matcher_search_every`` 5: while the cloud stays lost the matcher searches the map on
      every fifth sensor reset only, the resets between drawing around its last hypotheses
      moved with the odometry (a search costs up to a second on a building's map; a newer
      scan's place waits at most 4 updates, a fifth of the 20 scans an excursion may last;
      1: a search on every reset, as before the option);
      ``reset_look_elsewhere`` False: with True a sensor reset's margin grows by ln N for a
      best of N poses searched (the engine's look_elsewhere_term: even prior odds of "here" and
      "elsewhere", the second spread over the N poses). ``reset_needs_agreement`` True: a
      reset is kept only if the map also agrees with the scan from the place it proposes (the
      likelihood-weighted mean of its poses within 0.5 m and 0.3 rad of its best) at least as
      well as from the estimate and by at least ``reset_threshold``, so that it never moves the
      cloud to a place where it would count as lost; without it, beams cut short by unknown
      obstacles draw the cloud to cluttered places elsewhere (mcl-unknown-obstacles).
      ``sensor_reset_confirm`` True: a sensor reset that passes is held, moved with the
      odometry, and made only if it passes again on the next scan (one scan that fits a place
      elsewhere better does not move a cloud that is right).
    * ``update_min_d`` / ``update_min_a``: 0 (every scan is an update); nav2 uses 0.25 m / 0.2 rad.
    * ``threads`` 0: every core, or one thread while one is measured faster (the engine times
      its updates with each, compares the medians of their last five, and tries the other once
      every 50 x its time ratio updates; see ThreadChooser; the results are the same for any
      thread count, so only the time changes: on a robot whose cores other processes keep
      busy, waking a second thread can cost more than it gives); n > 0: n threads throughout.
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
    sensor_reset_proposal: str = "uniform"
    matcher_search_every: int = 5
    reset_look_elsewhere: bool = False
    reset_needs_agreement: bool = True
    sensor_reset_confirm: bool = True
    update_min_d: float = 0.0
    update_min_a: float = 0.0
    threads: int = 0

    def __post_init__(self) -> None:
        check_field_types(self)
        check_count(self.particles, "particles", 1, PARTICLE_LIMIT)
        check_count(self.min_particles, "min_particles", 1, PARTICLE_LIMIT)
        _check(
            not self.kld or self.min_particles <= self.particles,
            f"with kld, min_particles ({self.min_particles}) must not exceed particles "
            f"({self.particles}, the maximum)",
        )
        _check(
            self.motion_model in ("differential", "omnidirectional"),
            f"motion_model must be differential or omnidirectional, got {self.motion_model!r}",
        )
        _check(  # their values: the motion model's validate, in [0, 1000]
            len(self.alphas) in (4, 5), f"alphas must be 4 (or 5) numbers, got {self.alphas}"
        )
        _check(
            self.resampling in RESAMPLING_METHODS,
            f"resampling must be one of {', '.join(RESAMPLING_METHODS)}, got {self.resampling!r}",
        )
        _check(
            self.recovery in RECOVERY_MODES,
            f"recovery must be one of {', '.join(RECOVERY_MODES)}, got {self.recovery!r}",
        )
        check_count(self.threads, "threads", 0, THREAD_LIMIT, "0 = chosen by measured time")
        _check(
            self.sensor_reset_proposal in RESET_PROPOSALS,
            f"sensor_reset_proposal must be one of {', '.join(RESET_PROPOSALS)}, "
            f"got {self.sensor_reset_proposal!r}",
        )
        check_count(self.matcher_search_every, "matcher_search_every", 1, 1000)
        for name in ("reset_look_elsewhere", "reset_needs_agreement", "sensor_reset_confirm"):
            value = getattr(self, name)
            _check(isinstance(value, bool), f"{name} must be True or False, got {value!r}")
        for name, unit in (("update_min_d", "m"), ("update_min_a", "rad")):
            check_number(getattr(self, name), name, 0.0, unit=unit)
        # the engine's bounds (KldParams and MclParams::validate), each named here: the engine
        # words two fields in one message ('err must lie in (0, 1] and z in [0, 10]')
        check_number(self.kld_err, "kld_err", 0.0, 1.0, low_open=True)
        check_number(self.kld_z, "kld_z", 0.0, 10.0)
        check_number(
            self.expansion_position, "expansion_position", 0.0, MAX_ODOMETRY_JUMP, unit="m"
        )
        check_number(self.expansion_orientation, "expansion_orientation", 0.0, math.pi, unit="rad")
        _check(  # a turn is wrapped to at most pi: above it means never on rotation alone
            self.update_min_a <= 2 * math.pi,
            f"update_min_a must be <= 2 pi, got {self.update_min_a}",
        )
        for f in fields(self):  # the core's ints (10**300 was a pybind11 list of signatures)
            value = getattr(self, f.name)
            if f.type == "int" and not -INT32_MAX - 1 <= value <= INT32_MAX:
                raise ValueError(f"{f.name} must be a C++ int (within +-2**31), got {value}")
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
        p.sensor_reset_proposal = self.sensor_reset_proposal
        p.matcher_search_every = self.matcher_search_every
        p.reset_look_elsewhere = self.reset_look_elsewhere
        p.reset_needs_agreement = self.reset_needs_agreement
        p.sensor_reset_confirm = self.sensor_reset_confirm
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
        if not isinstance(config, MclConfig):
            raise TypeError(f"config must be an MclConfig, got {type(config).__name__}")
        if free_space is not None and not isinstance(free_space, OccupancyGrid):
            raise TypeError(
                "free_space must be a kiseki OccupancyGrid or None, "
                f"got {type(free_space).__name__}"
            )
        self.config = config
        self.engine = _core.MonteCarloLocalization(config.to_core(), check_seed(seed))
        if free_space is not None:
            self.engine.set_free_space(free_space)
        self._last_update: np.ndarray | None = None
        self._estimate_at_update = np.zeros(3)
        self.estimate = np.zeros(3)
        self.last_report: _core.UpdateReport | None = None
        self.updates = 0

    def initialize(self, pose, sd: tuple[float, float, float]) -> None:
        """Particles drawn around ``pose`` (x, y, theta) with standard deviations ``sd``, each
        within +-1e9 (:data:`kiseki.filters.initial_pose.POSE_LIMIT`)."""
        p, s = check_start(pose, sd)
        self.engine.initialize_gaussian(Pose2(*p), *s)
        self.estimate = self.engine.estimate().to_array()

    def initialize_particles(self, poses: np.ndarray, weights: np.ndarray | None = None) -> None:
        """Particles at the given poses (n, 3), with weights (normalised) or equal ones."""
        self.engine.set_particles(*check_particles(poses, weights))
        self.estimate = self.engine.estimate().to_array()

    def initialize_global(self) -> None:
        """Particles uniform over the free space given at construction."""
        if not self.engine.has_free_space:
            raise ValueError("global localization needs a map with free cells (free_space)")
        self.engine.initialize_uniform()
        self.estimate = self.engine.estimate().to_array()

    def set_matcher(self, relocalizer) -> None:
        """The matcher (a :class:`kiseki.filters.Relocalizer` of the filter's map) that a sensor
        reset with the matcher proposal searches the scan given to :meth:`step` with."""
        self._relocalizer = relocalizer  # kept alive with the engine's reference to its core
        self.engine.set_matcher(relocalizer.core)

    def due(self, odometry: np.ndarray) -> bool:
        """Whether a measurement update is due at this odometry pose (AMCL's gate)."""
        if self._last_update is None:
            return True
        d, a = _moved(self._last_update, odometry)
        return d >= self.config.update_min_d or a >= self.config.update_min_a

    def step(
        self,
        odometry,
        prepare: Callable[[], _core.SensorModel] | None,
        scan: tuple[np.ndarray, np.ndarray] | None = None,
    ) -> _core.UpdateReport | None:
        """Moves the particles by the odometry since the last update and weighs them with the
        model ``prepare()`` returns (called only when an update is due), or, when none is due,
        moves the estimate with the odometry. ``scan``: the (angles, ranges) the model holds,
        which a sensor reset with the matcher proposal searches. Returns the update's report or
        None."""
        odometry = _odometry_pose(odometry, self._last_update)
        if prepare is None:
            self._follow(odometry)
            return None
        if not self._predict_if_due(odometry):
            return None
        model = prepare()
        if scan is None:
            return self._updated(odometry, self.engine.update(model))
        return self._updated(odometry, self.engine.update(model, scan[0], scan[1]))

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
    def matcher_hypotheses(self) -> np.ndarray:
        """(k, 3): the matcher's places of the current lost spell, moved with the odometry
        since its last search (none when not lost or with the uniform proposal)."""
        return self.engine.matcher_hypotheses

    @property
    def reliability(self) -> float:
        return float(self.engine.reliability)

    @property
    def size(self) -> int:
        return int(self.engine.size)
