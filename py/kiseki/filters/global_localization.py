# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Global localization along a recorded log: Monte Carlo localization from a uniform start
(no initial pose), for logs without reference poses such as the CMU Wean Hall robotdata logs.

* Start (``start``): ``uniform``, ``particles`` poses drawn uniformly over the map's free cells
  (uniform position inside each cell, uniform heading), from the seed; or ``one-scan``, the
  first scan relocalized over the whole map (:class:`kiseki.filters.Relocalizer`, its
  ``hypotheses`` best distinct poses with the filter's beams and sigma_hit) and the particles
  drawn around those hypotheses (:func:`kiseki.filters.hypothesis_cloud`): shares by score,
  tempered by ``likelihood_power`` as the scan likelihood is, a Gaussian of one map cell per
  axis and one lattice heading step (2 pi / headings of that scan) around each, the lattice's
  own resolution. The first update then weighs that cloud with the same first scan.
* Motion: the odometry model of the particle filter (Probabilistic Robotics, Table 5.6),
  applied once per measurement update to the odometry since the previous update (AMCL's way).
* Measurement: the likelihood-field model (or the space observation model) applied only once
  the odometry has moved ``update_min_d`` or turned ``update_min_a`` since the last update
  (AMCL's rule): a robot standing still sees the same scan again and again, and multiplying
  the same evidence many times would make the filter overconfident. The first scan is used.
  Between updates the estimate follows the odometry. Until the cloud is cut (below), the
  likelihood-field scan likelihood is raised to ``likelihood_power`` (see GlobalConfig).
* Shrinking: once the cloud has stayed converged (the radius around the weighted mean that
  holds 90 % of the weight below ``shrink_radius``) for ``shrink_after`` updates, it is
  resampled down to ``tracking_particles``: a converged cloud needs far fewer particles than the
  uniform start. With ``kld`` the engine instead adapts the count at every resampling
  (KLD sampling, Fox 2003), between ``tracking_particles`` and ``particles``. From the cut
  on, ``tracking_method`` (when given) replaces ``method``: the likelihood field finds the place
  from the uniform start, where kiseki's ray model converges on look-alike places, and the ray
  model then tracks it among objects the map does not hold.
* Recovery (``recovery``, ``none`` by default) while tracking: ``augmented`` (Augmented MCL,
  Probabilistic Robotics Table 8.3, nav2's alpha_slow 0.001 and alpha_fast 0.1) or
  ``resetting`` (expansion, then sensor resetting); see :mod:`kiseki.filters`. Without it,
  a cloud converged on a wrong place or lost stays so, and the fit figures of the report are
  what tells.
* Every step is the one engine of :mod:`kiseki.filters` (:class:`MonteCarloLocalizer`).

The convergence report is :mod:`kiseki.filters.convergence`'s.
"""

from __future__ import annotations

import dataclasses
import json
import os
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
from tqdm import tqdm

from kiseki._support.atomic import atomic_write
from kiseki._support.counts import check_count
from kiseki._support.field_types import check_field_types
from kiseki._support.options import BEAM_LIMIT, PARTICLE_LIMIT
from kiseki._support.real_numbers import check_number
from kiseki.core import check_seed, derive_seed
from kiseki.filters.convergence import ConvergenceReport, convergence_report, spread_radius
from kiseki.filters.engine import (
    REAL_ODOMETRY_ALPHAS,
    RECOVERY_MODES,
    MclConfig,
    MonteCarloLocalizer,
)
from kiseki.filters.relocalization import RelocalizeConfig, Relocalizer, hypothesis_cloud
from kiseki.filters.tracking import LocalizeConfig, scan_model, scan_preparer
from kiseki.grid import OccupancyGrid
from kiseki.scans import LaserScans, check_odometry_jumps

__all__ = [
    "GlobalConfig",
    "GlobalResult",
    "global_localize",
    "render_global",
    "write_report",
]


GLOBAL_METHODS = ("likelihood-field", "space-observation", "ray-space-observation")
#: how the particles start: uniform over the free space, or around the first scan's hypotheses
START_MODES = ("uniform", "one-scan")


@dataclass(frozen=True)
class GlobalConfig:
    """Parameters of global localization (units m, rad). Why each default:

    * ``particles`` 50 000: the uniform start must put particles near the true pose in
      position and heading; Wean's map has 48 332 free cells (483 m^2), so 50 000 particles
      give about one per 0.1 m^2 per 36 degrees of heading (20 000 was not enough on
      robotdata1: seeds disagreed).
    * ``likelihood_power`` 0.1 until the cloud is cut to ``tracking_particles``: the 60 beams
      of a scan are far from independent (neighbouring beams see the same wall), and with the
      sparse uniform start a product of 60 sharp beam likelihoods wipes out, in one update,
      particles a few decimetres and degrees from the true pose. Raising the scan likelihood
      to 0.1 counts a scan like 6 independent beams. Chosen on robotdata1 (1.0 and 0.2 made
      seeds converge to different places; 0.1 made six seeds agree); runs 2 and 3 were not
      used to choose it. Position tracking afterwards uses the plain likelihood (power 1).
    * ``tracking_particles`` 1000: the count after convergence, as for position tracking.
    * ``shrink_radius`` 0.5 m held for ``shrink_after`` 10 measurement updates (about 2 m of
      travel) before the cut, so that a cloud that is tight for a moment on a wrong place
      keeps its particles.
    * ``alphas``: ``REAL_ODOMETRY_ALPHAS`` of kiseki.filters (the log's real odometry,
      of unknown error), applied once per measurement update to the odometry since the last
      one, as AMCL does.
    * ``beams`` 60: nav2 AMCL's default ``max_beams``.
    * ``sigma_hit`` 0.2 m: nav2 AMCL's default.
    * ``update_min_d`` 0.2 m, ``update_min_a`` 0.5 rad: ROS 1 AMCL's defaults (``update_min_a``
      pi/6 ~ 0.52).
    * ``converged_radius`` 0.5 m: five map cells; a tracking cloud with the noise above is a
      few decimetres wide.
    * ``start`` uniform (see the module's docstring for ``one-scan``); ``hypotheses`` 5, the
      first scan's hypotheses of a one-scan start (RelocalizeConfig's default).
    * ``tracking_method`` None: ``method`` throughout. Another of GLOBAL_METHODS is the model
      after the cut (see the module's docstring): the model that finds the place from a uniform
      start need not be the one that tracks it afterwards.
    """

    method: str = "likelihood-field"
    seed: int = 0
    particles: int = 50_000
    tracking_particles: int = 1000
    alphas: tuple[float, float, float, float] = REAL_ODOMETRY_ALPHAS
    beams: int = 60
    sigma_hit: float = 0.2
    update_min_d: float = 0.2
    update_min_a: float = 0.5
    shrink_radius: float = 0.5
    converged_radius: float = 0.5
    weight_share: float = 0.9  # share of the weight inside the spread radius
    likelihood_power: float = 0.1  # until the cut to tracking_particles
    shrink_after: int = 10  # consecutive measurement updates with the spread below shrink_radius
    recovery: str = "none"  # while tracking: none, augmented or resetting
    kld: bool = False  # adapt the count by KLD sampling instead of the fixed cut
    start: str = "uniform"  # or one-scan
    hypotheses: int = RelocalizeConfig.hypotheses  # of a one-scan start
    threads: int = 0
    tracking_method: str | None = None  # after the cut; None: method

    def __post_init__(self) -> None:
        check_field_types(self)
        tracking = self.method if self.tracking_method is None else self.tracking_method
        methods = {"method": self.method, "tracking_method": tracking}
        for name, value in methods.items():
            if value not in GLOBAL_METHODS:
                raise ValueError(
                    f"global localization: {name} must be one of {', '.join(GLOBAL_METHODS)}, "
                    f"got {value!r}"
                )
        check_seed(self.seed)
        if self.start not in START_MODES:
            raise ValueError(
                f"global localization: start must be one of {', '.join(START_MODES)}, "
                f"got {self.start!r}"
            )
        for name in ("particles", "tracking_particles", "hypotheses"):
            check_count(getattr(self, name), f"global localization: {name}", 1, PARTICLE_LIMIT)
        check_count(self.beams, "beams", 0, BEAM_LIMIT, "0 = every beam")
        if self.recovery not in RECOVERY_MODES:
            raise ValueError(
                f"recovery must be one of {', '.join(RECOVERY_MODES)}, got {self.recovery!r}"
            )
        if self.kld and self.tracking_particles > self.particles:
            raise ValueError("with kld, tracking_particles (the minimum) must not exceed particles")
        self.mcl()  # the engine's own checks
        positive = (
            ("sigma_hit", "m"),
            ("shrink_radius", "m"),
            ("converged_radius", "m"),
            ("likelihood_power", ""),
        )
        for name, unit in positive:
            check_number(getattr(self, name), name, 0.0, low_open=True, unit=unit)
        for name, unit in (("update_min_d", "m"), ("update_min_a", "rad")):
            check_number(getattr(self, name), name, 0.0, unit=unit)
        if self.shrink_after < 1:
            raise ValueError(f"shrink_after must be >= 1, got {self.shrink_after}")
        check_number(self.weight_share, "weight_share", 0.0, 1.0, low_open=True)

    def mcl(self) -> MclConfig:
        """The engine's settings: the start's likelihood power, recovery off until the cut."""
        return MclConfig(
            particles=self.particles,
            kld=self.kld,
            min_particles=min(self.tracking_particles, self.particles),
            alphas=tuple(self.alphas),
            likelihood_power=self.likelihood_power,
            update_min_d=self.update_min_d,
            update_min_a=self.update_min_a,
            threads=self.threads,
        )


@dataclass(frozen=True)
class GlobalResult:
    estimates: np.ndarray  # (n, 3) weighted-mean sensor pose after each scan
    spread: np.ndarray  # (n,) radius (m) holding weight_share of the weight
    particle_counts: np.ndarray  # (n,)
    report: ConvergenceReport
    reliability: np.ndarray  # (n,) the engine's reliability estimate after each scan
    config: GlobalConfig = field(repr=False)


def global_localize(
    scans: LaserScans, grid: OccupancyGrid, config: GlobalConfig, progress: bool = False
) -> GlobalResult:
    """Global localization along the scans' odometry from a uniform start over the map."""
    if len(scans) == 0:
        raise ValueError("global localization: the log has no scans")
    if not np.isfinite(scans.odometry).all():
        raise ValueError("global localization: the odometry has NaN or infinite poses")
    check_odometry_jumps("global localization", scans.times, scans.odometry)
    start = time.perf_counter()
    localizer = MonteCarloLocalizer(config.mcl(), derive_seed(config.seed, 2), grid)
    if config.start == "one-scan":
        localizer.initialize_particles(one_scan_start(scans, grid, config))
    else:
        localizer.initialize_global()
    prepare = _preparer(config.method, scans, grid, config)
    odom = np.asarray(scans.odometry, dtype=float)
    n = len(scans)
    estimates = np.empty((n, 3))
    spread = np.empty(n)
    counts = np.empty(n, dtype=np.int64)
    reliability = np.empty(n)
    shrunk_at: int | None = None
    tight_updates = 0
    injected = 0

    for k in tqdm(range(n), desc="global " + config.method, unit="scan", disable=not progress):
        report = localizer.step(odom[k], lambda k=k, prepare=prepare: prepare(k))
        estimates[k] = localizer.estimate
        reliability[k] = localizer.reliability
        if report is None:  # no update: the cloud stays, the estimate follows the odometry
            spread[k], counts[k] = spread[k - 1], counts[k - 1]
            continue
        injected += report.injected
        spread[k] = spread_radius(localizer.poses, localizer.weights, config.weight_share)
        counts[k] = localizer.size
        tight_updates = tight_updates + 1 if spread[k] < config.shrink_radius else 0
        if shrunk_at is None and tight_updates >= config.shrink_after:
            # Converged: cut to the tracking size (without KLD), use the plain likelihood and
            # recover from now on.
            if not config.kld and config.tracking_particles < localizer.size:
                localizer.engine.resample_to(config.tracking_particles)
            localizer.engine.set_likelihood_power(1.0)
            localizer.engine.set_recovery(config.recovery)
            if config.tracking_method not in (None, config.method):
                prepare = _preparer(config.tracking_method, scans, grid, config)
            shrunk_at = k
    seconds = time.perf_counter() - start
    report = convergence_report(
        scans,
        grid,
        config.converged_radius,
        estimates,
        spread,
        localizer.updates,
        shrunk_at,
        seconds,
    )
    report = dataclasses.replace(report, injected=injected)
    return GlobalResult(estimates, spread, counts, report, reliability, config)


def _preparer(method: str, scans: LaserScans, grid: OccupancyGrid, config: GlobalConfig):
    """The scan model of `method` with the config's beams and sigma_hit, as the engine's
    prepare callback: scan k -> the model holding scan k."""
    settings = LocalizeConfig(method=method, beams=config.beams, sigma_hit=config.sigma_hit)
    return scan_preparer(scan_model(method, grid, settings), scans)


def one_scan_start(scans: LaserScans, grid: OccupancyGrid, config: GlobalConfig) -> np.ndarray:
    """The particles of a one-scan start (see the module's docstring): the first scan's
    hypotheses over the whole map and a cloud of ``config.particles`` poses around them."""
    relocalizer = Relocalizer(
        grid,
        scans.max_range,
        RelocalizeConfig(
            beams=config.beams,
            sigma_hit=config.sigma_hit,
            hypotheses=config.hypotheses,
            threads=config.threads,
        ),
    )
    found = relocalizer.match(scans.angles, scans.ranges[0])
    if not found:
        raise ValueError("global localization: one-scan start: the first scan has no return")
    step = 2 * np.pi / relocalizer.headings(scans.angles, scans.ranges[0])
    rng = np.random.default_rng(derive_seed(config.seed, 3))
    return hypothesis_cloud(
        found, config.particles, grid.resolution, step, config.likelihood_power, rng
    )


def write_report(result: GlobalResult, path: str | os.PathLike) -> Path:
    """The report, the parameters and the per-scan spread and particle counts as JSON."""
    path = Path(path)
    doc = {
        "config": asdict(result.config),
        "report": result.report.to_dict(),
        "spread": [round(float(v), 4) for v in result.spread],
        "particles": [int(v) for v in result.particle_counts],
    }
    text = json.dumps(doc, indent=1) + "\n"
    return atomic_write(path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))


def render_global(
    grid: OccupancyGrid, result: GlobalResult, path: str | os.PathLike, title: str | None = None
) -> Path:
    """The map with the estimates after convergence (blue), before it (faint) and the
    convergence point (red)."""
    # here, not at the top: plots loads matplotlib, which `import kiseki.filters` should not
    from kiseki.plots import draw_map, figure_for_grid, save_figure, world_xy

    fig, ax = figure_for_grid(grid)
    draw_map(ax, grid)
    k = result.report.converged_scan
    xy = world_xy(grid, result.estimates)
    if k is None:
        ax.plot(xy[:, 0], xy[:, 1], "-", color="tab:orange", linewidth=0.8, label="not converged")
    else:
        if k > 0:
            ax.plot(
                xy[: k + 1, 0],
                xy[: k + 1, 1],
                ":",
                color="tab:orange",
                linewidth=0.8,
                label="before convergence",
            )
        ax.plot(xy[k:, 0], xy[k:, 1], "-", color="tab:blue", linewidth=1.2, label="estimate")
        ax.plot(
            xy[k, 0], xy[k, 1], "o", color="tab:red", markersize=6, label=f"converged (scan {k})"
        )
    ax.legend(loc="upper right", fontsize=8)
    ax.set_title(title or "global localization")
    return save_figure(fig, path)
