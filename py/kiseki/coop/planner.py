# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Predicted error of a cooperative positioning plan, to first order, and a planner that picks
each move to make the predicted error at the goal small (beyond the paper).

**Propagation.** A move's estimate is where two lines of sight meet: from the standing robots'
estimates p_i, p_j, turned from their baseline (direction beta) by the measured angles. With
n_k the normal of line k, u_k its direction and r_k the range, n_k^T dx = n_k^T dp_k + r_k
dphi_k, where dphi_k = dbeta + dtheta_k and dbeta = n_ij^T (dp_j - dp_i) / |p_j - p_i| (both
lines turn with the baseline). So the mover's error is a_i e_i + a_j e_j + b_i dtheta_i +
b_j dtheta_j, and the joint covariance P of the three robots' estimates (6 x 6) goes through
each move exactly, to first order (``predict``; checked against Monte Carlo in the tests),
kept as the gains from every angle noise so far so that it stays positive semi-definite.

**Planner** (``plan_moves``). From the start, each step considers every robot as the mover
(the other two standing) and every point of a grid of candidate places ahead, and keeps the
move after which finishing (one robot moving onto the goal, measured by the other two) has the
smallest predicted error; it stops with that finishing move as soon as no further move makes
the prediction smaller. One-step lookahead on the exact first-order covariance.
"""

from __future__ import annotations

import math

import numpy as np

from kiseki._support.counts import check_count
from kiseki._support.real_numbers import check_number
from kiseki.coop.positioning import ANGLE_SIGMA, GOAL, MAX_MOVES, START, Move, Plan
from kiseki.coop.triangulation import MIN_INTERSECTION_ANGLE


def _jacobians(pi: np.ndarray, pj: np.ndarray, x: np.ndarray):
    """For targets x (..., 2) seen from pi, pj (..., 2): a_i, a_j (..., 2, 2), b_i, b_j (..., 2)
    and whether the geometry is usable (lines meeting at >= the minimum angle, x not on a
    standing robot)."""
    pi, pj, x = np.broadcast_arrays(pi, pj, x)
    di, dj = x - pi, x - pj
    ri, rj = np.linalg.norm(di, axis=-1), np.linalg.norm(dj, axis=-1)
    ok = (ri > 1e-9) & (rj > 1e-9)
    ri_s, rj_s = np.where(ok, ri, 1.0), np.where(ok, rj, 1.0)
    ui, uj = di / ri_s[..., None], dj / rj_s[..., None]
    ni = np.stack([-ui[..., 1], ui[..., 0]], -1)
    nj = np.stack([-uj[..., 1], uj[..., 0]], -1)
    cross = np.abs(ui[..., 0] * uj[..., 1] - ui[..., 1] * uj[..., 0])
    ok &= cross >= math.sin(MIN_INTERSECTION_ANGLE)
    base = pj - pi
    d = np.linalg.norm(base, axis=-1)
    nb = np.stack([-base[..., 1], base[..., 0]], -1) / np.where(d > 0, d, 1.0)[..., None]
    normals = np.stack([ni, nj], -2)  # rows n_i^T, n_j^T
    n_inv = np.linalg.inv(np.where(ok[..., None, None], normals, np.eye(2)))
    # rows of [n_i^T dp_i + r_i dphi_i ; n_j^T dp_j + r_j dphi_j] in dp_i, dp_j, dtheta
    r = np.stack([ri, rj], -1)  # (..., 2)
    dbeta_dpi = -nb / np.where(d > 0, d, 1.0)[..., None]
    dbeta_dpj = nb / np.where(d > 0, d, 1.0)[..., None]
    rows_pi = np.stack([ni, np.zeros_like(ni)], -2) + r[..., :, None] * dbeta_dpi[..., None, :]
    rows_pj = np.stack([np.zeros_like(nj), nj], -2) + r[..., :, None] * dbeta_dpj[..., None, :]
    a_i = n_inv @ rows_pi
    a_j = n_inv @ rows_pj
    b_i = n_inv[..., :, 0] * ri[..., None]
    b_j = n_inv[..., :, 1] * rj[..., None]
    return a_i, a_j, b_i, b_j, ok


def _after(g: np.ndarray, m: int, i: int, j: int, a_i, a_j, b_i, b_j) -> np.ndarray:
    """The error gains (..., 6, K + 2) after robot m is triangulated from i and j.

    Every estimate's error is a linear function of the angle noises so far, e = g n (square-root
    form: the covariance sigma^2 g g^T stays positive semi-definite; propagating it directly
    loses it over long chains, whose errors are nearly common to the three robots)."""
    shape = a_i.shape[:-2]
    g = np.broadcast_to(g, shape + g.shape[-2:])
    out = np.concatenate([g, np.zeros(shape + (6, 2))], axis=-1)
    mover = a_i @ g[..., 2 * i : 2 * i + 2, :] + a_j @ g[..., 2 * j : 2 * j + 2, :]
    out[..., 2 * m : 2 * m + 2, :-2] = mover
    out[..., 2 * m : 2 * m + 2, -2] = b_i
    out[..., 2 * m : 2 * m + 2, -1] = b_j
    return out


def _mover_mse(g: np.ndarray, m: int, sigma: float) -> np.ndarray:
    return sigma**2 * np.sum(g[..., 2 * m : 2 * m + 2, :] ** 2, axis=(-2, -1))


def predict(the_plan: Plan, angle_sigma: float = ANGLE_SIGMA) -> np.ndarray:
    """The joint covariance (moves + 1, 6, 6) of the three robots' estimates before the first
    move and after each, to first order (x1, y1, x2, y2, x3, y3)."""
    at = the_plan.start.copy()
    g = np.zeros((6, 0))
    out = [np.zeros((6, 6))]
    for move in the_plan.steps:
        i, j = move.standing
        a_i, a_j, b_i, b_j, ok = _jacobians(at[i], at[j], move.target)
        if not ok:
            raise ValueError(f"robot {move.robot + 1}'s move cannot be triangulated")
        g = _after(g, move.robot, i, j, a_i, a_j, b_i, b_j)
        at[move.robot] = move.target
        out.append(angle_sigma**2 * g @ g.T)
    return np.array(out)


def predicted_goal_rms(the_plan: Plan, angle_sigma: float = ANGLE_SIGMA) -> float:
    """sqrt(trace) of the covariance of the robot that moved onto the goal: its RMS error."""
    cov = predict(the_plan, angle_sigma)[-1]
    m = the_plan.steps[-1].robot
    return float(math.sqrt(max(0.0, np.trace(cov[2 * m : 2 * m + 2, 2 * m : 2 * m + 2]))))


def _finish_cost(at: np.ndarray, g: np.ndarray, goal: np.ndarray, sigma: float):
    """For states at (..., 3, 2) with gains g (..., 6, K): the smallest predicted mean square
    error of a finishing move onto the goal, and which robot makes it."""
    best = np.full(at.shape[:-2], np.inf)
    who = np.zeros(at.shape[:-2], dtype=int)
    for m in range(3):
        i, j = [r for r in range(3) if r != m]
        a_i, a_j, b_i, b_j, ok = _jacobians(at[..., i, :], at[..., j, :], goal)
        cost = np.where(ok, _mover_mse(_after(g, m, i, j, a_i, a_j, b_i, b_j), m, sigma), np.inf)
        better = cost < best
        best, who = np.where(better, cost, best), np.where(better, m, who)
    return best, who


def plan_moves(
    start=START,
    goal=GOAL,
    angle_sigma: float = ANGLE_SIGMA,
    max_moves: int = 60,
    spacing: float = 0.25,
    reach: float = 4.0,
    half_width: float = 2.0,
) -> Plan:
    """A plan chosen move by move (see the module): candidate places on a ``spacing`` grid
    from ``reach`` / 2 behind the group's front to ``reach`` ahead of it, within
    ``half_width`` of the goal's x (2 m: twice the start's half-width; without a limit the best
    formation would spread as wide as the lines of sight allow)."""
    start = np.asarray(start, dtype=float)
    goal = np.asarray(goal, dtype=float)
    if (
        start.shape != (3, 2)
        or goal.shape != (2,)
        or not np.isfinite([*start.ravel(), *goal]).all()
    ):
        raise ValueError("start must be 3 finite (x, y) rows and goal a finite (x, y)")
    if not (math.isfinite(angle_sigma) and 0 < angle_sigma < math.radians(10)):
        raise ValueError(f"angle_sigma must lie in (0, 10 deg), got {angle_sigma}")
    check_count(max_moves, "max_moves", 1, MAX_MOVES)
    check_number(spacing, "spacing", 0.0, low_open=True, unit="m")
    check_number(reach, "reach (more than the spacing)", spacing, low_open=True, unit="m")
    check_number(half_width, "half_width", 0.0, low_open=True, unit="m")
    at, g = start.copy(), np.zeros((6, 0))
    steps: list[Move] = []
    half = float(half_width)
    while True:
        finish, who = _finish_cost(at, g, goal, angle_sigma)
        if len(steps) == max_moves - 1:
            break
        front = at[:, 1].max()
        xs = np.arange(goal[0] - half, goal[0] + half + 1e-9, spacing)
        ys = np.arange(front - reach / 2, min(front + reach, goal[1]) + 1e-9, spacing)
        cand = np.stack(np.meshgrid(xs, ys), -1).reshape(-1, 2)
        best = (float(finish), None)
        for m in range(3):
            i, j = [r for r in range(3) if r != m]
            a_i, a_j, b_i, b_j, ok = _jacobians(at[i], at[j], cand)
            gains_after = _after(g, m, i, j, a_i, a_j, b_i, b_j)
            states = np.broadcast_to(at, (len(cand), 3, 2)).copy()
            states[:, m] = cand
            cost, _ = _finish_cost(states, gains_after, goal, angle_sigma)
            cost = np.where(ok, cost, np.inf)
            k = int(np.argmin(cost))
            if cost[k] < best[0] - 1e-15:
                best = (float(cost[k]), (m, (i, j), cand[k], gains_after[k]))
        if best[1] is None:
            break
        m, pair, target, gains_after = best[1]
        steps.append(Move(m, target.copy(), pair))
        at[m], g = target, gains_after
    if not np.isfinite(finish):
        raise ValueError("no robot can be triangulated on the goal from where the others stand")
    m = int(who)
    pair = tuple(r for r in range(3) if r != m)
    steps.append(Move(m, goal.copy(), pair))
    return Plan(0, len(steps), float("nan"), start, steps)
