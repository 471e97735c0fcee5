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
  resampled (low variance) down to ``tracking_particles``: a converged cloud needs far fewer
  particles than the uniform start. This is a simple fixed rule instead of KLD-sampling
  (Fox 2003), which adapts the count at every step; both sizes are the user's choice.
* Recovery (``recovery``, off by default): Augmented MCL (Probabilistic Robotics, Table 8.3)
  while tracking, with ROS AMCL's suggested ``alpha_slow`` 0.001 and ``alpha_fast`` 0.1. The
  average likelihood is the weighted mean over particles of the per-beam (geometric mean) scan
  likelihood, so that it does not depend on how many beams returned. At every update a share
  ``1 - w_fast / w_slow`` of the cloud is replaced by uniform poses over the free cells.
  Without it, a cloud converged on a wrong place or lost stays so, and the fit figures of the
  report are what tells.

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
from kiseki.core import Pose2, derive_seed
from kiseki.datasets.carmen import LaserScans
from kiseki.grid import FREE, OccupancyGrid
from kiseki.localization import REAL_ODOMETRY_ALPHAS

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
    "uniform_free_poses",
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
    * ``beam_stride`` 3: 60 of 180 beams, nav2 AMCL's default ``max_beams`` 60.
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
    beam_stride: int = 3
    sigma_hit: float = 0.2
    update_min_d: float = 0.2
    update_min_a: float = 0.5
    shrink_radius: float = 0.5
    converged_radius: float = 0.5
    weight_share: float = 0.9  # share of the weight inside the spread radius
    likelihood_power: float = 0.1  # until the cut to tracking_particles
    shrink_after: int = 10  # consecutive measurement updates with the spread below shrink_radius
    recovery: bool = False  # Augmented MCL while tracking (random poses when the fit drops)
    alpha_slow: float = 0.001
    alpha_fast: float = 0.1

    def __post_init__(self) -> None:
        if self.method not in ("likelihood-field", "space-observation"):
            raise ValueError(
                "global localization: method must be likelihood-field or space-observation, "
                f"got {self.method!r}"
            )
        if self.particles < 1 or self.tracking_particles < 1:
            raise ValueError("global localization: particle counts must be >= 1")
        if self.beam_stride < 1:
            raise ValueError(f"beam stride must be >= 1, got {self.beam_stride}")
        positive = ("sigma_hit", "shrink_radius", "converged_radius", "likelihood_power")
        for name in positive:
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be a positive number, got {value}")
        for name in ("update_min_d", "update_min_a"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0):
                raise ValueError(f"{name} must be >= 0, got {value}")
        if not (0 < self.alpha_slow < self.alpha_fast <= 1):
            raise ValueError("need 0 < alpha_slow < alpha_fast <= 1")
        if self.shrink_after < 1:
            raise ValueError(f"shrink_after must be >= 1, got {self.shrink_after}")
        if not 0 < self.weight_share <= 1:
            raise ValueError(f"weight_share must lie in (0, 1], got {self.weight_share}")


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
    config: GlobalConfig = field(repr=False)


def uniform_free_poses(grid: OccupancyGrid, n: int, rng: np.random.Generator) -> np.ndarray:
    """n poses (n, 3) uniform over the free cells of the grid (position uniform inside the
    cell) with uniform heading in [-pi, pi)."""
    if n < 1:
        raise ValueError(f"need n >= 1 poses, got {n}")
    free = np.flatnonzero(grid.cells.ravel() == FREE)
    if free.size == 0:
        raise ValueError("the map has no free cells: global localization has nowhere to start")
    pick = free[rng.integers(0, free.size, size=n)]
    gx = pick % grid.width + rng.random(n)
    gy = pick // grid.width + rng.random(n)
    o = grid.origin
    c, s = np.cos(o.theta), np.sin(o.theta)
    res = grid.resolution
    x = o.x + res * (c * gx - s * gy)
    y = o.y + res * (s * gx + c * gy)
    theta = rng.uniform(-np.pi, np.pi, n)
    return np.column_stack([x, y, theta])


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


def _systematic_resample(
    poses: np.ndarray, weights: np.ndarray, n: int, rng: np.random.Generator
) -> np.ndarray:
    w = np.asarray(weights, dtype=float)
    cum = np.cumsum(w / w.sum())
    cum[-1] = 1.0
    u = (rng.random() + np.arange(n)) / n
    return poses[np.searchsorted(cum, u)]


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


def _per_beam_average(
    log_l: np.ndarray,
    weights: np.ndarray,
    ranges: np.ndarray,
    max_range: float,
    config: GlobalConfig,
) -> float:
    """The weighted mean over particles of the per-beam (geometric mean) likelihood: the scale
    does not depend on how many beams of the scan returned, unlike the product."""
    used = ranges[:: config.beam_stride]
    beams = int(np.count_nonzero(np.isfinite(used) & (used > 0) & (used < max_range)))
    if beams == 0:
        return float("nan")
    per_beam = log_l / beams
    top = per_beam.max()
    return float(np.exp(top) * np.dot(weights, np.exp(per_beam - top)))


def _moved(a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    step = Pose2(*a).between(Pose2(*b))
    return float(np.hypot(step.x, step.y)), abs(float(step.theta))


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
    start = time.perf_counter()
    rng = np.random.default_rng(derive_seed(config.seed, 3))
    a1, a2, a3, a4 = config.alphas
    pf = _core.ParticleFilter(config.particles, a1, a2, a3, a4, 0.5, derive_seed(config.seed, 2))
    pf.set_particles(uniform_free_poses(grid, config.particles, rng))
    if config.method == "space-observation":
        from kiseki.mapping import scan_local_map

        so_model = _core.SpaceObservationModel(grid)
    else:
        lf_model = _core.LikelihoodFieldModel(
            grid, sigma_hit=config.sigma_hit, beam_stride=config.beam_stride
        )
    odom = np.asarray(scans.odometry, dtype=float)
    n = len(scans)
    estimates = np.empty((n, 3))
    spread = np.empty(n)
    counts = np.empty(n, dtype=np.int64)
    last_update: np.ndarray | None = None
    last_estimate = np.zeros(3)
    updates = 0
    shrunk_at: int | None = None
    tight_updates = 0
    w_slow: float | None = None
    w_fast: float | None = None
    injected = 0
    for k in tqdm(range(n), desc="global " + config.method, unit="scan", disable=not progress):
        moved_d, moved_a = (np.inf, np.inf) if last_update is None else _moved(last_update, odom[k])
        if not (moved_d >= config.update_min_d or moved_a >= config.update_min_a):
            # No update: the cloud stays; the estimate follows the odometry since the update.
            step = Pose2(*last_update).between(Pose2(*odom[k]))
            estimates[k] = (Pose2(*last_estimate) * step).to_array()
            spread[k], counts[k] = spread[k - 1], counts[k - 1]
            continue
        if last_update is not None:  # the motion model once per update, as in AMCL
            pf.predict(Pose2(*last_update), Pose2(*odom[k]))
        last_update = odom[k]
        updates += 1
        ranges = scans.ranges[k]
        if config.method == "space-observation":
            so_model.set_local_map(scan_local_map(scans.angles, ranges, scans.max_range))
            pf.weight(so_model.likelihoods(pf.poses))
        else:
            lf_model.set_scan(scans.angles, ranges, scans.max_range)
            log_l = lf_model.log_likelihoods(pf.poses)
            if shrunk_at is None:
                log_l *= config.likelihood_power
            elif config.recovery and np.isfinite(
                w_avg := _per_beam_average(log_l, pf.weights, ranges, scans.max_range, config)
            ):
                w_slow = w_avg if w_slow is None else w_slow + config.alpha_slow * (w_avg - w_slow)
                w_fast = w_avg if w_fast is None else w_fast + config.alpha_fast * (w_avg - w_fast)
            pf.weight(np.exp(log_l - log_l.max()))
        poses, weights = pf.poses, pf.weights
        estimates[k] = last_estimate = pf.estimate().to_array()
        spread[k] = spread_radius(poses, weights, config.weight_share)
        counts[k] = len(poses)
        tight_updates = tight_updates + 1 if spread[k] < config.shrink_radius else 0
        if shrunk_at is None and tight_updates >= config.shrink_after:
            if config.tracking_particles < len(poses):
                keep = _systematic_resample(poses, weights, config.tracking_particles, rng)
                pf.set_particles(keep)
            shrunk_at = k
        elif w_slow is not None and w_fast is not None and w_fast < w_slow:
            # Augmented MCL: resample with a share 1 - w_fast / w_slow of uniform poses.
            inject = rng.binomial(len(poses), 1.0 - w_fast / w_slow)
            keep = _systematic_resample(poses, weights, len(poses) - inject, rng)
            if inject > 0:
                keep = np.vstack([keep, uniform_free_poses(grid, inject, rng)])
            pf.set_particles(keep)
            injected += inject
        else:
            pf.resample_if_needed()
    seconds = time.perf_counter() - start
    report = _report(scans, grid, config, estimates, spread, updates, shrunk_at, seconds)
    report = dataclasses.replace(report, injected=injected)
    return GlobalResult(estimates, spread, counts, report, config)


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
    from kiseki.plots import _figure, _save, _world_xy, draw_map

    fig, ax = _figure(grid)
    draw_map(ax, grid)
    k = result.report.converged_scan
    xy = _world_xy(grid, result.estimates)
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
    return _save(fig, Path(path))
