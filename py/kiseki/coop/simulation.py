# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Noisy runs of a plan of the cooperative positioning loop of Hirose, Nagata and Kurazume
(sec. 2, Fig. 1; the plans in :mod:`kiseki.coop.positioning`). Errors build up as the group
advances: each triangulation inherits the standing robots' errors.

**Measurement.** Standing robot i measures theta_i, the angle between the directions to the
other standing robot j and to the mover (the paper's theta_1, theta_2: no heading reference is
needed), with Gaussian noise. Its line of sight in the world is then the direction of
(estimate_j - estimate_i) turned by the measured theta_i, and the mover's estimate is where the
two lines meet (kiseki.coop.triangulate). A robot drives exactly to its planned point (the
paper models no motion error); the error at the goal is the distance between the estimate of the
robot that moved to the goal and the goal.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

import numpy as np

from kiseki import _core
from kiseki._support.counts import check_count
from kiseki._support.real_numbers import check_number
from kiseki.coop.positioning import ANGLE_SIGMA, Plan
from kiseki.coop.triangulation import MIN_INTERSECTION_ANGLE
from kiseki.core import check_seed

__all__ = ["CoopRun", "CoopRun3D", "simulate", "simulate_3d"]


@dataclass(frozen=True)
class CoopRun:
    """``runs`` noisy runs of one plan."""

    plan: Plan
    estimates: np.ndarray  # (runs, moves + 1, 3, 2): every robot's estimate after each move
    truth: np.ndarray  # (moves + 1, 3, 2)
    angle_sigma: float

    @property
    def goal_errors(self) -> np.ndarray:
        """(runs,) distance between the goal and the estimate of the robot that moved there."""
        last = self.plan.steps[-1]
        return np.hypot(*(self.estimates[:, -1, last.robot] - last.target).T)


def _wrap(a: np.ndarray) -> np.ndarray:
    return np.remainder(a + np.pi, 2 * np.pi) - np.pi


def _check_runs(the_plan, runs, limit: int, seed, *sigmas) -> list[float]:
    """A Plan (None was an AttributeError), runs in 1..limit, the angle SDs in [0, 10 deg)."""
    if not isinstance(the_plan, Plan):
        raise TypeError(f"the_plan must be a Plan (see plan()), got {type(the_plan).__name__}")
    runs = check_count(runs, "runs", 1, limit)
    for name, v in zip(("angle_sigma", "elevation_sigma"), sigmas, strict=False):
        if isinstance(v, bool) or not (isinstance(v, numbers.Real) and 0 <= v < math.radians(10)):
            raise ValueError(f"{name} must lie in [0, 10 deg), got {v!r}")
    check_seed(seed)
    return [float(v) + 0.0 for v in sigmas]  # -0.0 as 0.0, a scale numpy's normal refuses


def simulate(
    the_plan: Plan, runs: int = 100, angle_sigma: float = ANGLE_SIGMA, seed: int = 0
) -> CoopRun:
    """``runs`` runs of a plan with Gaussian noise of SD ``angle_sigma`` (rad) on every measured
    angle. Seeded: the same seed gives the same runs."""
    (angle_sigma,) = _check_runs(the_plan, runs, 1_000_000, seed, angle_sigma)
    rng = np.random.default_rng(seed)
    truth = the_plan.nominal_positions()
    est = np.empty((runs, len(the_plan.steps) + 1, 3, 2))
    est[:, 0] = the_plan.start  # the start positions are measured beforehand (sec. 2)
    for k, move in enumerate(the_plan.steps):
        at = truth[k]
        i, j = move.standing
        current = est[:, k].copy()
        bearings = []
        for a, b in ((i, j), (j, i)):
            measured = _wrap(
                math.atan2(*(move.target - at[a])[::-1]) - math.atan2(*(at[b] - at[a])[::-1])
            ) + rng.normal(0.0, angle_sigma, runs)
            baseline = current[:, b] - current[:, a]
            bearings.append(np.arctan2(baseline[:, 1], baseline[:, 0]) + measured)
        try:
            found = _core.triangulate_pairs(
                current[:, i], current[:, j], bearings[0], bearings[1], MIN_INTERSECTION_ANGLE
            )
        except ValueError as err:
            raise ValueError(
                f"form {the_plan.form}, move {k + 1} (robot {move.robot + 1}): {err}"
            ) from None
        current[:, move.robot] = found
        est[:, k + 1] = current
    return CoopRun(the_plan, est, truth, angle_sigma)


@dataclass(frozen=True)
class CoopRun3D:
    """``runs`` noisy runs of a plan on uneven ground, in 3-D."""

    plan: Plan
    estimates: np.ndarray  # (runs, moves + 1, 3, 3)
    truth: np.ndarray  # (moves + 1, 3, 3): the markers
    angle_sigma: float
    elevation_sigma: float

    @property
    def goal_offsets(self) -> np.ndarray:
        """(runs, 3) estimate minus truth of the robot that moved to the goal."""
        last = self.plan.steps[-1]
        return self.estimates[:, -1, last.robot] - self.truth[-1, last.robot]

    @property
    def goal_errors(self) -> np.ndarray:
        return np.linalg.norm(self.goal_offsets, axis=1)


def simulate_3d(
    the_plan: Plan,
    ground,
    runs: int = 100,
    angle_sigma: float = ANGLE_SIGMA,
    elevation_sigma: float | None = None,
    seed: int = 0,
    marker_height: float = 0.5,
) -> CoopRun3D:
    """The 3-D case (the paper's sec. 5: measure elevation angles too): the robots stand on
    ``ground`` (a function z(x, y) of numpy arrays), each carrying a levelled sensor and a
    marker ``marker_height`` above the ground. The standing robots measure the horizontal
    angle between each other and the mover, as in 2-D, and the mover's elevation above the
    horizontal; the mover's estimate is the least-squares point of the two lines of sight in
    3-D (kiseki.coop.triangulate with elevations). ``elevation_sigma`` defaults to
    ``angle_sigma``."""
    e_sigma = angle_sigma if elevation_sigma is None else elevation_sigma
    angle_sigma, e_sigma = _check_runs(the_plan, runs, 100_000, seed, angle_sigma, e_sigma)
    check_number(marker_height, "marker_height", 0.0, 10.0, high_open=True, unit="m")
    if not callable(ground):
        raise TypeError(f"ground must be a function z(x, y), got {type(ground).__name__}")
    flat = the_plan.nominal_positions()
    z = np.asarray(ground(flat[..., 0], flat[..., 1]), dtype=float)
    if z.shape != flat.shape[:-1] or not np.isfinite(z).all():
        raise ValueError("ground(x, y) must return finite heights of the shape of x")
    truth = np.concatenate([flat, (z + marker_height)[..., None]], axis=-1)
    rng = np.random.default_rng(seed)
    est = np.empty((runs, len(the_plan.steps) + 1, 3, 3))
    est[:, 0] = truth[0]
    for k, move in enumerate(the_plan.steps):
        at, target = truth[k], truth[k + 1][move.robot]
        i, j = move.standing
        current = est[:, k].copy()
        measured = {}
        for a, b in ((i, j), (j, i)):
            d_target, d_other = target - at[a], at[b] - at[a]
            horizontal = _wrap(
                math.atan2(d_target[1], d_target[0]) - math.atan2(d_other[1], d_other[0])
            )
            elevation = math.atan2(d_target[2], math.hypot(d_target[0], d_target[1]))
            measured[a] = (
                horizontal + rng.normal(0.0, angle_sigma, runs),
                elevation + rng.normal(0.0, e_sigma, runs),
            )
        for r in range(runs):
            pa, pb = current[r, i], current[r, j]
            bearings = [
                math.atan2(*(pb - pa)[1::-1]) + measured[i][0][r],
                math.atan2(*(pa - pb)[1::-1]) + measured[j][0][r],
            ]
            try:
                position, _cov, _ranges, _angle = _core.triangulate_3d(
                    np.stack([pa, pb]),
                    bearings,
                    [measured[i][1][r], measured[j][1][r]],
                    0.0,
                    0.0,
                    MIN_INTERSECTION_ANGLE,
                )
            except ValueError as err:
                raise ValueError(
                    f"form {the_plan.form}, move {k + 1} (robot {move.robot + 1}): {err}"
                ) from None
            current[r, move.robot] = position
        est[:, k + 1] = current
    return CoopRun3D(the_plan, est, truth, angle_sigma, e_sigma)
