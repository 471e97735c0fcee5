# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Global localization along a recorded log: Monte Carlo localization from a uniform start
(no initial pose), for logs without reference poses such as the CMU Wean Hall robotdata logs.

* Start: ``particles`` poses drawn uniformly over the map's free cells (uniform position inside
  each cell, uniform heading), from the seed.
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
  (KLD sampling, Fox 2003), between ``tracking_particles`` and ``particles``.
* Recovery (``recovery``, ``none`` by default) while tracking: ``augmented`` (Augmented MCL,
  Probabilistic Robotics Table 8.3, nav2's alpha_slow 0.001 and alpha_fast 0.1) or
  ``resetting`` (expansion, then sensor resetting); see :mod:`kiseki.localization`. Without it,
  a cloud converged on a wrong place or lost stays so, and the fit figures of the report are
  what tells.
* Every step is the one engine of :mod:`kiseki.localization` (:class:`MonteCarloLocalizer`).

Convergence report (:class:`ConvergenceReport`): after every scan the 90 %-weight radius
(``spread``); the filter is *converged* from the first scan after which the spread stays below
``converged_radius`` to the end of the log. The fit of the scans to the map at the estimated
poses from then on: the share of beam endpoints (readings below max range) within one and within
two cells (Chebyshev, 3x3 and 5x5 blocks) of an occupied cell, and the mean distance of the
endpoints inside the map to the nearest occupied cell. The same figures for the estimates moved
1 m sideways and turned by 10 degrees are given as a control: a wrong pose must fit much worse.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import os
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
from tqdm import tqdm

from kiseki import _core
from kiseki._atomic import atomic_write
from kiseki.core import check_seed, derive_seed
from kiseki.grid import OccupancyGrid
from kiseki.localization import (
    REAL_ODOMETRY_ALPHAS,
    RECOVERY_MODES,
    LocalizeConfig,
    MclConfig,
    MonteCarloLocalizer,
    scan_model,
    scan_preparer,
)
from kiseki.scans import LaserScans, check_odometry_jumps

__all__ = [
    "GlobalConfig",
    "GlobalResult",
    "ConvergenceReport",
    "ScanFit",
    "describe",
    "global_localize",
    "render_global",
    "scan_fit",
    "spread_radius",
    "write_report",
]


FIT_BLOCK = 100  # scans per block of ConvergenceReport.fit_by_block


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
    * ``alphas``: ``REAL_ODOMETRY_ALPHAS`` of kiseki.localization (the log's real odometry,
      of unknown error), applied once per measurement update to the odometry since the last
      one, as AMCL does.
    * ``beams`` 60: nav2 AMCL's default ``max_beams``.
    * ``sigma_hit`` 0.2 m: nav2 AMCL's default.
    * ``update_min_d`` 0.2 m, ``update_min_a`` 0.5 rad: ROS 1 AMCL's defaults (``update_min_a``
      pi/6 ~ 0.52).
    * ``converged_radius`` 0.5 m: five map cells; a tracking cloud with the noise above is a
      few decimetres wide.
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
    threads: int = 0

    def __post_init__(self) -> None:
        if self.method not in ("likelihood-field", "space-observation"):
            raise ValueError(
                "global localization: method must be likelihood-field or space-observation, "
                f"got {self.method!r}"
            )
        check_seed(self.seed)
        for name in ("particles", "tracking_particles"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or not 1 <= value <= 10**7:
                raise ValueError(
                    f"global localization: {name} must be an integer in 1..10,000,000, "
                    f"got {value!r}"
                )
        if not (isinstance(self.beams, int) and self.beams >= 0):
            raise ValueError(f"beams must be an integer >= 0 (0 = every beam), got {self.beams!r}")
        if self.recovery not in RECOVERY_MODES:
            raise ValueError(
                f"recovery must be one of {', '.join(RECOVERY_MODES)}, got {self.recovery!r}"
            )
        if self.kld and self.tracking_particles > self.particles:
            raise ValueError("with kld, tracking_particles (the minimum) must not exceed particles")
        self.mcl()  # the engine's own checks
        positive = ("sigma_hit", "shrink_radius", "converged_radius", "likelihood_power")
        for name in positive:
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be a positive number, got {value}")
        for name in ("update_min_d", "update_min_a"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0):
                raise ValueError(f"{name} must be >= 0, got {value}")
        if self.shrink_after < 1:
            raise ValueError(f"shrink_after must be >= 1, got {self.shrink_after}")
        if not 0 < self.weight_share <= 1:
            raise ValueError(f"weight_share must lie in (0, 1], got {self.weight_share}")

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
class ScanFit:
    """How well scans fit the map at given poses (endpoints below max range only)."""

    endpoints: int
    within_1_cell: float  # share of endpoints with an occupied cell in their 3x3 block
    within_2_cells: float  # ... in their 5x5 block
    mean_distance: float  # m, endpoints inside the map, to the nearest occupied cell centre


@dataclass(frozen=True)
class ConvergenceReport:
    converged: bool
    converged_scan: int | None  # first scan from which the spread stays below the threshold
    converged_time: float | None  # seconds after the first scan
    threshold: float
    final_spread: float
    fit: ScanFit | None  # at the estimates from the converged scan on
    fit_shifted_1m: ScanFit | None  # the same estimates moved 1 m sideways (to their left)
    fit_rotated_10deg: ScanFit | None  # ... turned by 10 degrees
    scans: int
    updates: int  # scans used for a measurement update
    shrunk_at: int | None  # scan at which the cloud was cut to tracking_particles
    seconds: float
    # share of endpoints within 1 cell, per block of 100 scans from the first (None: no return)
    fit_by_block: list[float | None] = field(default_factory=list)
    injected: int = 0  # uniform poses injected by the recovery (Augmented MCL)

    def to_dict(self) -> dict:
        return asdict(self)


@dataclass(frozen=True)
class GlobalResult:
    estimates: np.ndarray  # (n, 3) weighted-mean sensor pose after each scan
    spread: np.ndarray  # (n,) radius (m) holding weight_share of the weight
    particle_counts: np.ndarray  # (n,)
    report: ConvergenceReport
    reliability: np.ndarray  # (n,) the engine's reliability estimate after each scan
    config: GlobalConfig = field(repr=False)


def spread_radius(poses: np.ndarray, weights: np.ndarray, share: float = 0.9) -> float:
    """Radius around the weighted mean position that holds ``share`` of the weight."""
    w = np.asarray(weights, dtype=float)
    w = w / w.sum()
    centre = w @ poses[:, :2]
    d = np.hypot(poses[:, 0] - centre[0], poses[:, 1] - centre[1])
    order = np.argsort(d)
    cum = np.cumsum(w[order])
    k = min(int(np.searchsorted(cum, share)), len(d) - 1)
    return float(d[order[k]])


def scan_fit(
    grid: OccupancyGrid,
    poses: np.ndarray,
    ranges: np.ndarray,
    angles: np.ndarray,
    max_range: float,
    distance: np.ndarray | None = None,
) -> ScanFit:
    """Fit of scans (n, b) at sensor poses (n, 3) to the grid's occupied cells."""
    poses = np.ascontiguousarray(poses, dtype=np.float64)
    ranges = np.ascontiguousarray(ranges, dtype=np.float32)
    hits1, endpoints = _core.endpoint_agreement(
        grid, poses, ranges, angles, max_range, neighbourhood=1
    )
    hits2, _ = _core.endpoint_agreement(grid, poses, ranges, angles, max_range, neighbourhood=2)
    if endpoints == 0:
        raise ValueError("no scan endpoint below max range: the fit is undefined")
    if distance is None:
        distance = grid.distance_field()
    valid = np.isfinite(ranges) & (ranges > 0) & (ranges < max_range)
    heading = poses[:, 2:3] + angles[None, :]
    ex = poses[:, 0:1] + ranges * np.cos(heading)
    ey = poses[:, 1:2] + ranges * np.sin(heading)
    cells = grid.world_to_cell(np.column_stack([ex[valid], ey[valid]]))
    inside = (
        (cells[:, 0] >= 0)
        & (cells[:, 1] >= 0)
        & (cells[:, 0] < grid.width)
        & (cells[:, 1] < grid.height)
    )
    d = distance[cells[inside, 1], cells[inside, 0]]
    d = d[np.isfinite(d)]
    return ScanFit(
        endpoints=int(endpoints),
        within_1_cell=hits1 / endpoints,
        within_2_cells=hits2 / endpoints,
        mean_distance=float(d.mean()) if d.size else float("nan"),
    )


def _converged_from(spread: np.ndarray, threshold: float) -> int | None:
    above = np.flatnonzero(~(spread < threshold))
    if above.size == 0:
        return 0
    k = int(above[-1]) + 1
    return k if k < len(spread) else None


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
    localizer.initialize_global()
    model = scan_model(
        config.method,
        grid,
        LocalizeConfig(method=config.method, beams=config.beams, sigma_hit=config.sigma_hit),
    )
    prepare = scan_preparer(model, scans)
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
        report = localizer.step(odom[k], lambda k=k: prepare(k))
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
            shrunk_at = k
    seconds = time.perf_counter() - start
    report = _report(scans, grid, config, estimates, spread, localizer.updates, shrunk_at, seconds)
    report = dataclasses.replace(report, injected=injected)
    return GlobalResult(estimates, spread, counts, report, reliability, config)


def _report(
    scans: LaserScans,
    grid: OccupancyGrid,
    config: GlobalConfig,
    estimates: np.ndarray,
    spread: np.ndarray,
    updates: int,
    shrunk_at: int | None,
    seconds: float,
) -> ConvergenceReport:
    k = _converged_from(spread, config.converged_radius)
    fits: list[ScanFit | None] = [None, None, None]
    distance = grid.distance_field()
    if k is not None:
        poses = estimates[k:]
        shifted = poses.copy()
        shifted[:, 0] -= np.sin(poses[:, 2])  # 1 m to the left of the heading: across a
        shifted[:, 1] += np.cos(poses[:, 2])  # corridor, where the walls constrain the pose
        rotated = poses + [0.0, 0.0, np.radians(10.0)]
        args = (scans.ranges[k:], scans.angles, scans.max_range, distance)
        with contextlib.suppress(ValueError):  # no endpoint below max range: no fit
            fits = [scan_fit(grid, p, *args) for p in (poses, shifted, rotated)]
    blocks: list[float | None] = []
    for b in range(0, len(scans), FIT_BLOCK):
        try:
            fit = scan_fit(
                grid,
                estimates[b : b + FIT_BLOCK],
                scans.ranges[b : b + FIT_BLOCK],
                scans.angles,
                scans.max_range,
                distance,
            )
            blocks.append(round(fit.within_1_cell, 4))
        except ValueError:
            blocks.append(None)
    return ConvergenceReport(
        converged=k is not None,
        converged_scan=k,
        converged_time=None if k is None else float(scans.times[k] - scans.times[0]),
        threshold=config.converged_radius,
        final_spread=float(spread[-1]),
        fit=fits[0],
        fit_shifted_1m=fits[1],
        fit_rotated_10deg=fits[2],
        scans=len(scans),
        updates=updates,
        shrunk_at=shrunk_at,
        seconds=seconds,
        fit_by_block=blocks,
    )


def describe(report: ConvergenceReport) -> str:
    """One paragraph for the command line."""
    head = (
        f"{report.scans} scans ({report.updates} measurement updates) in {report.seconds:.1f} s; "
    )
    if not report.converged:
        return head + (
            f"not converged (final 90 % radius {report.final_spread:.2f} m, threshold "
            f"{report.threshold:g} m)"
        )
    text = (
        f"converged at scan {report.converged_scan} ({report.converged_time:.1f} s): the 90 % "
        f"radius stays below {report.threshold:g} m to the end"
    )
    if report.shrunk_at is not None:
        text += f" (cloud cut to the tracking size at scan {report.shrunk_at})"
    if report.injected:
        text += f"; {report.injected} uniform poses injected while tracking"
    fit, shifted, rotated = report.fit, report.fit_shifted_1m, report.fit_rotated_10deg
    if fit is not None and shifted is not None and rotated is not None:
        text += (
            f"; from then on {100 * fit.within_1_cell:.1f} % of {fit.endpoints} endpoints within "
            f"1 cell of an occupied cell ({100 * fit.within_2_cells:.1f} % within 2), mean "
            f"distance {fit.mean_distance:.3f} m; estimates moved 1 m sideways: "
            f"{100 * shifted.within_1_cell:.1f} %, {shifted.mean_distance:.3f} m; turned 10 deg: "
            f"{100 * rotated.within_1_cell:.1f} %, {rotated.mean_distance:.3f} m"
        )
    return head + text


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
