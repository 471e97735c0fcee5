# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The settings of localization along a log (:class:`LocalizeConfig`), each default held once;
saved with every result."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

from kiseki._support.counts import check_count
from kiseki._support.field_types import check_field_types
from kiseki._support.options import BEAM_LIMIT
from kiseki._support.real_numbers import check_number
from kiseki.core import check_seed
from kiseki.filters.engine import REAL_ODOMETRY_ALPHAS, MclConfig
from kiseki.filters.initial_pose import check_spread
from kiseki.filters.odometry_noise import NOISE_FRACTION_LIMIT
from kiseki.filters.reliability import RELIABILITY_ESTIMATES
from kiseki.grid import DEFAULT_RAY_CASTER, ray_caster

__all__ = ["LOCALIZATION_METHODS", "LocalizeConfig"]

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
    * ``intrusion_tolerant_resets`` (ray-space-observation with recovery resetting; off; kiseki's
      own trigger): the cloud counts as lost only by penetration, not by intrusion: the
      agreement leaves out the beams that end in the open without passing a wall (what an
      unmapped object reads, which the intrusion term explains), and the likelihood-drop
      trigger is off (the likelihood falls wherever such objects stand in the view); a place a
      reset proposes is still judged with every beam (a wrong place in a wider space, whose
      beams end in the open, would pass the laxer measure). Without it, unknown objects that
      hide most of the view make the true cloud look lost, and a reset moves it to a place
      whose walls happen to meet the short beams. The agreement it reports (and the reliability
      estimate ``agreement`` built on it) is the tolerant one.
    * ``combination`` product (beams independent) or nav2 (1 + sum pz^3).
    * ``sensor_reset_proposal`` matcher (with recovery resetting): a sensor reset draws its
      candidates around the branch-and-bound scan matcher's five best poses for the scan
      (:class:`~kiseki.filters.relocalization.Relocalizer`, built once per run) instead of
      uniformly over the free cells (uniform, :class:`MclConfig`'s); chosen by the rule the
      README states before its runs (mcl-excursions and mcl-unknown-obstacles with either).
    * ``caster``: how the beam model casts z* (:mod:`kiseki.grid.casters`: both exact, the same
      weights); the C++ model's default.
    * ``alphas`` None: :func:`motion_alphas` (the noise the odometry has).
    * the engine's settings (particles, KLD, resampling, recovery, update thresholds,
      threads) default to :class:`MclConfig`'s, which holds each of them once.
    * ``beam_skip`` (likelihood-field only; off): nav2's beam skipping, a beam is weighed with
      only when at least ``beam_skip_threshold`` 0.3 of the particles see its end within
      ``beam_skip_distance`` 0.5 m of a wall, unless more than ``beam_skip_error_threshold`` 0.9
      of the beams would be skipped (then every beam is); nav2's defaults
      (``kiseki._core.LikelihoodFieldModel``'s header states the rule).
    * ``budget_ms`` (None: no budget): the time per update the particle and beam counts are
      chosen for, from a calibrated cost model (:mod:`kiseki.filters.budget`);
      ``budget_share`` 0.8 of it is what the model's prediction may fill (the rest absorbs
      what the model does not hold: the scheduler, other processes, caches);
      ``budget_min_beams`` 30 (half nav2's default max_beams 60) is the fewest beams it cuts to.
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
    # ray-space-observation with recovery resetting: only penetration counts as lost (the
    # class docstring)
    intrusion_tolerant_resets: bool = False
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
    # the sensor reset's candidates: around the correlative scan matcher's hypotheses for the
    # scan, or uniform over the free cells (MclConfig's, the engine's own default)
    sensor_reset_proposal: str = "matcher"
    matcher_search_every: int = MclConfig.matcher_search_every  # searches while lost (MclConfig)
    reset_look_elsewhere: bool = MclConfig.reset_look_elsewhere
    # a reset must also agree with the map from the place it proposes (MclConfig)
    reset_needs_agreement: bool = MclConfig.reset_needs_agreement
    # ... and must pass again on the next scan before it is made (MclConfig)
    sensor_reset_confirm: bool = MclConfig.sensor_reset_confirm
    likelihood_power: float = MclConfig.likelihood_power
    # the `reliability` of the result: the engine's "agreement" or a learned probability,
    # fitted on simulated ("learned") or recorded ("learned-real") updates
    # (kiseki.filters.reliability)
    reliability: str = "agreement"
    beam_skip: bool = False
    beam_skip_distance: float = 0.5
    beam_skip_threshold: float = 0.3
    beam_skip_error_threshold: float = 0.9
    budget_ms: float | None = None
    budget_share: float = 0.8
    budget_min_beams: int = 30

    def __post_init__(self) -> None:
        check_field_types(self)
        _check(
            self.method in LOCALIZATION_METHODS,
            f"method must be one of {', '.join(LOCALIZATION_METHODS)}, got {self.method!r}",
        )
        check_seed(self.seed)
        # the SD as a multiple of each step
        check_number(
            self.odometry_noise, "odometry_noise", 0.0, NOISE_FRACTION_LIMIT, high_open=True
        )
        check_spread("initial_sd", self.initial_sd)  # 1e300 was refused only by the run
        check_count(self.beams, "beams", 0, BEAM_LIMIT, "0 = every beam")
        _check(
            self.combination in ("product", "nav2"),
            f"combination must be product or nav2, got {self.combination!r}",
        )
        ray_caster(self.caster)  # ValueError unless it names one
        for name, unit in (("sigma_hit", "m"), ("lambda_short", "1/m")):
            check_number(getattr(self, name), name, 0.0, low_open=True, unit=unit)
        for name in ("z_hit", "z_rand", "z_short", "z_max", "z_intrusion"):
            check_number(getattr(self, name), name, 0.0)
        _check(self.z_hit + self.z_rand > 0, "z_hit and z_rand must not both be 0")
        _check(
            self.alphas is None or len(self.alphas) in (4, 5),
            f"alphas must be 4 (or 5) numbers, got {self.alphas}",
        )
        _check(
            isinstance(self.intrusion_tolerant_resets, bool),
            "intrusion_tolerant_resets must be true or false, "
            f"got {self.intrusion_tolerant_resets!r}",
        )
        _check(
            not self.intrusion_tolerant_resets or self.method == "ray-space-observation",
            "intrusion_tolerant_resets applies only to ray-space-observation, "
            f"not to {self.method}",
        )
        _check(
            not self.intrusion_tolerant_resets or self.recovery == "resetting",
            "intrusion_tolerant_resets applies only with recovery resetting, "
            f"not with {self.recovery}",
        )
        _check(
            not (self.intrusion_tolerant_resets and self.resetting_injects),
            "intrusion_tolerant_resets does not go with resetting_injects (the injection answers "
            "the likelihood's drop, which the switch stops reading as being lost)",
        )
        _check(
            not self.intrusion_tolerant_resets or self.reliability == "agreement",
            "intrusion_tolerant_resets needs reliability agreement (the learned estimates were "
            f"fitted on the plain agreement), not {self.reliability}",
        )
        _check(
            self.reliability in RELIABILITY_ESTIMATES,
            f"reliability must be one of {', '.join(RELIABILITY_ESTIMATES)}, "
            f"got {self.reliability!r}",
        )
        _check(
            not self.beam_skip or self.method == "likelihood-field",
            f"beam skipping applies only to the likelihood field, not to {self.method}",
        )
        check_number(self.beam_skip_distance, "beam_skip_distance", 0.0, unit="m")
        for name in ("beam_skip_threshold", "beam_skip_error_threshold"):
            check_number(getattr(self, name), name, 0.0, 1.0)
        if self.budget_ms is not None:
            check_number(
                self.budget_ms, "budget_ms", 0.0, low_open=True, unit="ms (or None: no budget)"
            )
        _check(
            self.budget_ms is None or self.method in ("likelihood-field", "beam"),
            f"a time budget applies to the likelihood-field and beam models, not to {self.method}",
        )
        check_number(self.budget_share, "budget_share", 0.0, 1.0, low_open=True)
        check_count(self.budget_min_beams, "budget_min_beams", 1, BEAM_LIMIT)
        # the engine's checks, as ValueError, of the alphas given (1e300 was taken here and
        # refused by the run); those derived from odometry_noise stay within them (F < 10)
        self.mcl(REAL_ODOMETRY_ALPHAS if self.alphas is None else self.alphas)

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
            matcher_search_every=self.matcher_search_every,
            reset_look_elsewhere=self.reset_look_elsewhere,
            reset_needs_agreement=self.reset_needs_agreement,
            sensor_reset_confirm=self.sensor_reset_confirm,
            # the agreement alone decides: a likelihood that drops where unmapped objects
            # stand in the view is what the intrusion term expects
            reset_likelihood_drop=(
                0.0 if self.intrusion_tolerant_resets else MclConfig.reset_likelihood_drop
            ),
            update_min_d=self.update_min_d,
            update_min_a=self.update_min_a,
            threads=self.threads,
        )

    def to_dict(self) -> dict:
        return asdict(self)
