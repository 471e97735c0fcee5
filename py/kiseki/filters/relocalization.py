# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Global relocalization from one scan: ranked pose hypotheses over the whole map.

The search is the C++ branch-and-bound correlative scan matcher (``kiseki._core``; Olson,
"Real-time correlative scan matching", ICRA 2009; Hess et al., "Real-time loop closure in 2D
LIDAR SLAM", ICRA 2016, sec. V, Algorithm 3). It scores the laser at every cell centre of the
map (its known free cells by default) and at every heading of a lattice with the likelihood
field's log-likelihood of the scan (Probabilistic Robotics, Table 6.3, the model
``kiseki localize`` tracks with), and returns
exactly what scoring every lattice pose would: the best pose, then the best one not within
``min_distance`` and ``min_angle`` of a pose already taken, up to ``hypotheses``. The result is
the same for any thread count; the GIL is released during the search.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from kiseki import _core
from kiseki._support.counts import check_count
from kiseki._support.field_types import check_field_types
from kiseki._support.options import BEAM_LIMIT, THREAD_LIMIT
from kiseki._support.real_numbers import check_number
from kiseki.errors import RelocalizationError
from kiseki.grid import OccupancyGrid

__all__ = [
    "Hypothesis",
    "RelocalizeConfig",
    "Relocalizer",
    "SearchDisc",
    "hypothesis_cloud",
    "relocalize",
    "render_hypotheses",
]


@dataclass(frozen=True)
class RelocalizeConfig:
    """Settings of :func:`relocalize` (units m, rad). Why each default:

    * ``beams`` 60: nav2 AMCL's ``max_beams`` and its rule (every step-th beam from the
      first, step = (n - 1) // (beams - 1)); 0 takes every beam.
    * ``sigma_hit`` 0.2 m, ``z_hit`` 0.95, ``z_rand`` 0.05, ``max_distance`` 2 m: the
      likelihood field's defaults (nav2's), so a hypothesis' score is the log-likelihood that
      tracking would give the pose.
    * ``depth`` 7: coarsest search nodes of 128 x 128 cells (Hess et al.'s default
      branch-and-bound depth).
    * ``angular_step`` 0: Hess et al. eq. (7) for the scan's longest used range (the farthest
      beam end moves by one cell between headings); a positive value fixes the step.
    * ``hypotheses`` 5, apart by ``min_distance`` 0.5 m or ``min_angle`` 0.5 rad (about 29
      degrees): distinct places or headings, not five neighbours of one peak.
    * ``free_only`` True: the laser only on known free cells (0..19, the free space MCL draws
      its uniform poses from); False searches every cell, walls and unknown space too.
    * ``threads`` 0: every hardware thread (the result does not depend on it).
    """

    beams: int = 60
    sigma_hit: float = 0.2
    z_hit: float = 0.95
    z_rand: float = 0.05
    max_distance: float = 2.0
    depth: int = 7
    angular_step: float = 0.0
    hypotheses: int = 5
    min_distance: float = 0.5
    min_angle: float = 0.5
    free_only: bool = True
    threads: int = 0

    def __post_init__(self) -> None:
        check_field_types(self)
        bounds = {
            "beams": (0, BEAM_LIMIT),
            "depth": (0, 16),
            "hypotheses": (1, 1000),
            "threads": (0, THREAD_LIMIT),
        }
        for name, (low, high) in bounds.items():
            check_count(
                getattr(self, name), f"relocalize: {name}", low, high, error=RelocalizationError
            )
        for name in ("sigma_hit", "max_distance"):
            check_number(
                getattr(self, name),
                f"relocalize: {name}",
                0.0,
                low_open=True,
                unit="m",
                error=RelocalizationError,
            )
        for name, unit in (
            ("z_hit", ""),
            ("z_rand", ""),
            ("angular_step", "rad"),
            ("min_distance", "m"),
            ("min_angle", "rad"),
        ):
            check_number(
                getattr(self, name),
                f"relocalize: {name}",
                0.0,
                unit=unit,
                error=RelocalizationError,
            )
        if not isinstance(self.free_only, bool):
            raise RelocalizationError(
                f"relocalize: free_only must be True or False, got {self.free_only!r}"
            )
        if self.z_hit + self.z_rand <= 0:
            raise RelocalizationError("relocalize: z_hit and z_rand must not both be 0")


@dataclass(frozen=True)
class Hypothesis:
    """One ranked pose: the robot pose (x, y, theta) in the map frame, its score (the sum over
    the used beams of the likelihood field's log pz), and its lattice place."""

    x: float
    y: float
    theta: float
    score: float
    cell: tuple[int, int]  # (x, y) cell of the laser
    heading: int  # heading index on the lattice


@dataclass(frozen=True)
class SearchDisc:
    """A disc (centre ``x``, ``y`` and ``radius`` in m, map frame) that restricts a search:
    ``inside`` keeps the lattice poses whose robot position is at most ``radius`` from the
    centre, otherwise those more than ``radius`` from it. The best pose on either side is
    exact, as the unrestricted search is (nodes with no cell on that side are pruned)."""

    x: float
    y: float
    radius: float
    inside: bool = True

    def __post_init__(self) -> None:
        for name, low in (("x", -math.inf), ("y", -math.inf), ("radius", 0.0)):
            check_number(
                getattr(self, name),
                f"relocalize: the search disc's {name}",
                low,
                unit="m",
                error=RelocalizationError,
            )


class Relocalizer:
    """The matcher of one map and maximum range: its score table and max-pooled grids are
    built once (here), then each :meth:`match` searches one scan."""

    def __init__(
        self,
        grid: OccupancyGrid,
        max_range: float,
        config: RelocalizeConfig | None = None,
        sensor: tuple[float, float, float] = (0.0, 0.0, 0.0),
    ) -> None:
        config = config or RelocalizeConfig()
        if not isinstance(grid, OccupancyGrid):
            raise RelocalizationError(
                f"relocalize: map must be an OccupancyGrid, got {type(grid).__name__}"
            )
        check_number(
            max_range,
            "relocalize: max_range",
            0.0,
            low_open=True,
            unit="m",
            error=RelocalizationError,
        )
        if len(sensor) != 3:
            raise RelocalizationError(
                f"relocalize: sensor must be three numbers (x, y, theta), got {sensor!r}"
            )
        for axis, value, unit in zip(("x", "y", "theta"), sensor, ("m", "m", "rad"), strict=True):
            check_number(value, f"relocalize: sensor {axis}", unit=unit, error=RelocalizationError)
        self.config = config
        self._grid, self._max_range = grid, float(max_range)
        self._sensor = _core.Pose2(*(float(v) for v in sensor))
        self._field = None  # the likelihood field of scores(), built on first use
        self._matcher = _core.CorrelativeScanMatcher(
            grid,
            max_range=float(max_range),
            sigma_hit=config.sigma_hit,
            z_hit=config.z_hit,
            z_rand=config.z_rand,
            max_beams=config.beams,
            max_distance=config.max_distance,
            sensor=_core.Pose2(*(float(v) for v in sensor)),
            depth=config.depth,
            angular_step=config.angular_step,
            hypotheses=config.hypotheses,
            min_distance=config.min_distance,
            min_angle=config.min_angle,
            free_only=config.free_only,
            threads=config.threads,
        )

    @property
    def core(self) -> _core.CorrelativeScanMatcher:
        """The C++ matcher (what the engine's matcher proposal of a sensor reset searches)."""
        return self._matcher

    def match(
        self, angles: np.ndarray, ranges: np.ndarray, disc: SearchDisc | None = None
    ) -> list[Hypothesis]:
        """The ranked hypotheses of one scan: ``angles`` (B,) rad and ``ranges`` (B,) m in the
        laser frame (NaN invalid, +inf or ``>= max_range`` no return, both skipped); an empty
        list when no beam returned. With ``disc``, only the poses on its side are ranked (an
        empty list when none is)."""
        try:
            angles = np.asarray(angles, dtype=np.float64)
            with np.errstate(over="ignore"):  # beyond float32: +inf, a no return
                ranges = np.asarray(ranges, dtype=np.float32)
        except (TypeError, ValueError):
            raise RelocalizationError(
                "relocalize: angles and ranges must be arrays of numbers"
            ) from None
        if angles.ndim != 1 or angles.shape != ranges.shape:
            raise RelocalizationError(
                "relocalize: angles and ranges must be 1-D arrays of one length, "
                f"got shapes {angles.shape} and {ranges.shape}"
            )
        if not np.isfinite(angles).all():
            raise RelocalizationError("relocalize: beam angles must be finite")
        if disc is not None and not isinstance(disc, SearchDisc):
            raise RelocalizationError(
                f"relocalize: disc must be a SearchDisc, got {type(disc).__name__}"
            )
        region = (
            None if disc is None else _core.SearchDisc(disc.x, disc.y, disc.radius, disc.inside)
        )
        poses, scores, lattice = self._matcher.match(angles, ranges, region)
        return [
            Hypothesis(
                x=float(p[0]),
                y=float(p[1]),
                theta=float(p[2]),
                score=float(s),
                cell=(int(c[0]), int(c[1])),
                heading=int(c[2]),
            )
            for p, s, c in zip(poses, scores, lattice, strict=True)
        ]

    def scores(self, angles: np.ndarray, ranges: np.ndarray, poses: np.ndarray) -> np.ndarray:
        """The score of any robot poses (N, 3), on the lattice or off it: the likelihood
        field's log-likelihood of the scan there with the matcher's beams and parameters (at a
        lattice pose, its hypothesis' score)."""
        poses = np.asarray(poses, dtype=np.float64)
        if poses.ndim != 2 or poses.shape[1] != 3 or not np.isfinite(poses).all():
            raise RelocalizationError(
                f"relocalize: poses must be finite (N, 3) x, y, theta, got shape {poses.shape}"
            )
        if self._field is None:
            c = self.config
            self._field = _core.LikelihoodFieldModel(
                self._grid,
                sigma_hit=c.sigma_hit,
                z_hit=c.z_hit,
                z_rand=c.z_rand,
                max_beams=c.beams,
                max_distance=c.max_distance,
                sensor=self._sensor,
            )
        self._field.set_scan(
            np.asarray(angles, np.float64), np.asarray(ranges, np.float32), self._max_range
        )
        return np.asarray(self._field.log_likelihoods(poses), dtype=np.float64)

    def headings(self, angles: np.ndarray, ranges: np.ndarray) -> int:
        """Headings of the search lattice for this scan."""
        return int(
            self._matcher.headings(np.asarray(angles, float), np.asarray(ranges, np.float32))
        )


def relocalize(
    grid: OccupancyGrid,
    angles: np.ndarray,
    ranges: np.ndarray,
    max_range: float,
    config: RelocalizeConfig | None = None,
    sensor: tuple[float, float, float] = (0.0, 0.0, 0.0),
) -> list[Hypothesis]:
    """The ``config.hypotheses`` best distinct poses of one scan over the whole map, best first
    (see :class:`Relocalizer`; ``sensor`` is the laser's pose in the robot frame)."""
    return Relocalizer(grid, max_range, config, sensor).match(angles, ranges)


def hypothesis_cloud(
    hypotheses: list[Hypothesis],
    count: int,
    sd_xy: float,
    sd_theta: float,
    power: float,
    rng: np.random.Generator,
) -> np.ndarray:
    """``count`` poses (count, 3) around ranked hypotheses: hypothesis i gets a share of them
    proportional to exp(power * (score_i - best score)) (its score as a tempered
    log-likelihood; the largest remainders round the shares to whole poses), each drawn from a
    Gaussian of ``sd_xy`` per axis and ``sd_theta`` around it."""
    if not hypotheses:
        raise RelocalizationError("relocalize: no hypotheses to draw a cloud around")
    count = check_count(count, "relocalize: count", 1, error=RelocalizationError)
    scores = np.array([h.score for h in hypotheses])
    share = np.exp(power * (scores - scores.max()))
    share *= count / share.sum()
    counts = np.floor(share).astype(np.int64)
    counts[np.argsort(counts - share, kind="stable")[: count - counts.sum()]] += 1
    centre = np.repeat([[h.x, h.y, h.theta] for h in hypotheses], counts, axis=0)
    poses = centre + rng.normal(0.0, 1.0, (count, 3)) * [sd_xy, sd_xy, sd_theta]
    poses[:, 2] = np.remainder(poses[:, 2] + math.pi, 2 * math.pi) - math.pi
    return poses


def render_hypotheses(
    grid: OccupancyGrid,
    hypotheses: list[Hypothesis],
    path: str | os.PathLike,
    truth: tuple[float, float, float] | None = None,
    title: str | None = None,
) -> Path:
    """The map with the hypotheses: the best a red dot, the others orange dots numbered by rank,
    each heading a green line of 1 m; the reference pose (if given) a blue cross."""
    # here, not at the top: plots loads matplotlib, which `import kiseki.filters` should not
    from kiseki.plots import draw_map, figure_for_grid, save_figure, world_xy

    fig, ax = figure_for_grid(grid)
    draw_map(ax, grid)
    for rank, h in reversed(list(enumerate(hypotheses, start=1))):
        start = world_xy(
            grid, np.array([[h.x, h.y], [h.x + math.cos(h.theta), h.y + math.sin(h.theta)]])
        )
        ax.plot(start[:, 0], start[:, 1], "-", color="tab:green", linewidth=1.0)
        colour = "tab:red" if rank == 1 else "tab:orange"
        ax.plot(start[0, 0], start[0, 1], "o", color=colour, markersize=7 if rank == 1 else 5)
        if rank > 1:
            ax.annotate(str(rank), start[0], textcoords="offset points", xytext=(4, 4), fontsize=7)
    if truth is not None:
        xy = world_xy(grid, np.array([truth[:2]]))
        ax.plot(xy[0, 0], xy[0, 1], "x", color="tab:blue", markersize=8, label="reference pose")
        ax.legend(loc="upper right", fontsize=8)
    ax.set_title(title or "relocalization hypotheses")
    return save_figure(fig, path)
