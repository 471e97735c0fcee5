# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Pure pursuit along a polyline of waypoints, with a stop at the last one.

The path-tracking rule is R. C. Coulter's, "Implementation of the Pure Pursuit Path Tracking
Algorithm", CMU-RI-TR-92-01 (Carnegie Mellon University, 1992): the vehicle drives the circular
arc through its own position that reaches a goal point on the path ahead of it. With the goal
point at (x_l, y_l) in the body frame (x_l forward, y_l left) and l its distance, the arc
tangent to the heading through both points has radius r = l^2 / (2 y_l) (Coulter's derivation,
his lateral offset x is y_l here), so

    curvature  gamma = 2 y_l / l^2,  l^2 = x_l^2 + y_l^2
    yaw rate   omega = v * gamma

The goal point is the point ``lookahead`` metres further along the path than the robot's
progress, or the last waypoint once less than ``lookahead`` of the path is left. The progress is
the path length up to the nearest path point among those at most 0.5 m behind the current
progress, and it never decreases (a leg that passes close to an earlier one does not pull the
robot back). A goal point behind the robot (x_l < 0) turns it on the spot
at 1 rad/s towards the goal point.

Speed: the route speed, capped so that the robot can still stop at the last waypoint when it
brakes at 0.8 of its acceleration limit a_max (constant deceleration a stops from v within
v^2 / (2 a); d is the straight distance to the last waypoint)

    v = min(v_route, sqrt(2 * 0.8 * a_max * d), v_cap)

where v_cap is the optional ``max_speed`` of :meth:`PurePursuit.command` (a speed limiter's
output, m/s; none by default). The cap bounds the forward speed only: a turn on the spot
towards a goal point behind the robot keeps its 1 rad/s, also under a 0 m/s limit.

The follower is done (and commands zero from then on) when the robot is within ``tolerance``
of the last waypoint with less than 0.5 m of the path left to go.
"""

from __future__ import annotations

import math

import numpy as np

from kiseki._support.real_numbers import check_number

__all__ = ["PurePursuit"]


class PurePursuit:
    """Follows a polyline: aims at the point `lookahead` metres ahead along the path, slows to
    stop at the last waypoint within its deceleration limit, and reports when it is there.

    ``progress`` is the distance travelled along the path (m) and ``cum[i]`` the distance of
    waypoint i from the first one, so ``progress >= cum[i]`` says waypoint i has been passed."""

    def __init__(
        self, waypoints, speed: float, lookahead: float, tolerance: float, max_accel: float
    ) -> None:
        pts = np.asarray(waypoints, dtype=float)
        # three numbers were numpy's "cannot reshape"; (n, 3) poses were read as pairs
        if pts.size % 2 or (pts.ndim >= 2 and pts.shape[-1] != 2):
            raise ValueError(f"a route's waypoints are (x, y) pairs, got shape {pts.shape}")
        pts = pts.reshape(-1, 2)
        if len(pts) < 2 or not np.isfinite(pts).all():
            raise ValueError("a route needs at least two finite waypoints")
        for name, value, unit in (
            ("route speed", speed, "m/s"),
            ("lookahead", lookahead, "m"),
            ("tolerance", tolerance, "m"),
            ("max_accel", max_accel, "m/s^2"),
        ):  # a NaN lookahead gave NaN yaw rates, a negative max_accel "math domain error"
            check_number(value, name, 0.0, low_open=True, unit=unit)
        seg = np.diff(pts, axis=0)
        self.lengths = np.hypot(seg[:, 0], seg[:, 1])
        if (self.lengths <= 0).any():
            raise ValueError("consecutive route waypoints must differ")
        self.points, self.cum = pts, np.concatenate([[0.0], np.cumsum(self.lengths)])
        self.speed, self.lookahead, self.tolerance, self.max_accel = (
            speed,
            lookahead,
            tolerance,
            max_accel,
        )
        self.progress = 0.0
        self.done = False

    def _point_at(self, s: float) -> np.ndarray:
        s = min(max(s, 0.0), self.cum[-1])
        i = min(int(np.searchsorted(self.cum, s, side="right")) - 1, len(self.lengths) - 1)
        f = (s - self.cum[i]) / self.lengths[i]
        return self.points[i] + f * (self.points[i + 1] - self.points[i])

    def _project(self, xy: np.ndarray) -> float:
        best, best_s = np.inf, self.progress
        for i in range(len(self.lengths)):
            a, b = self.points[i], self.points[i + 1]
            f = np.clip(np.dot(xy - a, b - a) / self.lengths[i] ** 2, 0.0, 1.0)
            s = self.cum[i] + f * self.lengths[i]
            d = np.hypot(*(a + f * (b - a) - xy))
            if d < best and s >= self.progress - 0.5:  # never jump back along the path
                best, best_s = d, s
        return max(self.progress, best_s)

    def command(self, pose, *, max_speed: float | None = None) -> tuple[float, float, float]:
        """(v_forward, v_left, yaw_rate) in the body frame; ``max_speed`` (m/s, finite and
        >= 0) caps the forward speed below the route speed and the braking cap."""
        if max_speed is not None:
            check_number(max_speed, "max_speed", 0.0, unit="m/s")
        x, y, th = (float(v) for v in pose)
        if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(th)):
            raise ValueError(f"pose must be three finite numbers (x, y, theta), got {tuple(pose)}")
        xy = np.array([x, y])
        goal = self.points[-1]
        dist_goal = float(np.hypot(*(goal - xy)))
        self.progress = self._project(xy)
        if self.done or (dist_goal < self.tolerance and self.cum[-1] - self.progress < 0.5):
            self.done = True
            return 0.0, 0.0, 0.0
        target = self._point_at(self.progress + self.lookahead)
        if self.cum[-1] - self.progress < self.lookahead:
            target = goal
        c, s = math.cos(th), math.sin(th)
        dx, dy = target - xy
        lx, ly = c * dx + s * dy, -s * dx + c * dy  # target in the body frame
        speed = min(self.speed, math.sqrt(2 * self.max_accel * 0.8 * dist_goal))
        if max_speed is not None:
            speed = min(speed, float(max_speed))
        curvature = 2.0 * ly / max(lx * lx + ly * ly, 1e-9)  # Coulter's gamma = 2 y_l / l^2
        if lx < 0:  # target behind: turn on the spot
            return 0.0, 0.0, math.copysign(1.0, ly)
        return speed, 0.0, speed * curvature
