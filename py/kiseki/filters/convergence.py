# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""How a global localization converged.

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
from dataclasses import asdict, dataclass, field

import numpy as np

from kiseki import _core
from kiseki._support.counts import check_count
from kiseki._support.real_numbers import check_number
from kiseki.grid import OccupancyGrid
from kiseki.scans import LaserScans, check_max_range

__all__ = [
    "FIT_BLOCK",
    "ConvergenceReport",
    "ScanFit",
    "convergence_report",
    "describe",
    "elapsed_time",
    "scan_fit",
    "spread_radius",
]


FIT_BLOCK = 100  # scans per block of ConvergenceReport.fit_by_block


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
    converged_time: float | None  # seconds after the first scan (elapsed_time)
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


def spread_radius(poses: np.ndarray, weights: np.ndarray, share: float = 0.9) -> float:
    """Radius around the weighted mean position that holds ``share`` of the weight."""
    poses = np.asarray(poses, dtype=float)
    w = np.asarray(weights, dtype=float)
    if poses.ndim != 2 or poses.shape[1] < 2 or len(poses) == 0 or w.shape != (len(poses),):
        raise ValueError(
            "spread_radius: need (n, 2) or (n, 3) poses and n weights, got "
            f"{poses.shape}, {w.shape}"
        )
    if not (np.isfinite(w).all() and (w >= 0).all() and w.sum() > 0):
        # all zero gave NaN with a numpy warning
        raise ValueError("spread_radius: weights must be finite, >= 0 and not all 0")
    share = check_number(share, "spread_radius: share", 0.0, 1.0, low_open=True)
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
    max_range = check_max_range("scan_fit", max_range)
    poses = np.ascontiguousarray(poses, dtype=np.float64)
    ranges = np.ascontiguousarray(ranges, dtype=np.float32)
    hits1, endpoints = _core.endpoint_agreement(
        grid, poses, ranges, angles, max_range, neighbourhood=1
    )
    hits2, _ = _core.endpoint_agreement(grid, poses, ranges, angles, max_range, neighbourhood=2)
    if endpoints == 0:
        raise ValueError(
            f"scan_fit: no scan endpoint (a reading > 0 and below max_range {max_range:g} m): "
            "the fit is undefined"
        )
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


def elapsed_time(times: np.ndarray, k: int) -> float:
    """Seconds of the log's clock from its first scan to scan ``k``, counting only the steps
    forward: a clock that steps back (the Intel log's does, by up to 0.86 s) never makes the
    time negative or shorter than what passed. Equals ``times[k] - times[0]`` when the clock
    only goes forward."""
    times = np.asarray(times, dtype=np.float64)
    k = check_count(k, "elapsed_time: k", 0, len(times) - 1, "a scan index")
    steps = np.diff(times[: k + 1])
    return float(times[k] - times[0] - steps[steps < 0].sum())  # less the steps back


def convergence_report(
    scans: LaserScans,
    grid: OccupancyGrid,
    converged_radius: float,
    estimates: np.ndarray,
    spread: np.ndarray,
    updates: int,
    shrunk_at: int | None,
    seconds: float,
) -> ConvergenceReport:
    """The report of a run: from when its spread stays below `converged_radius`, and how
    well the scans fit the map at its estimates (and at the estimates moved and turned)."""
    k = _converged_from(spread, converged_radius)
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
        converged_time=None if k is None else elapsed_time(scans.times, k),
        threshold=converged_radius,
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
