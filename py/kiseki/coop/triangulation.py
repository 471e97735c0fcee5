# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Triangulation of a moving robot from the bearings that standing robots measure (Hirose,
Nagata and Kurazume, "Cooperative positioning method by multi-robots", sec. 3), in 2-D and, with
elevation angles, in 3-D; with its first-order covariance. The solver is C++ (kiseki._core);
its header, ``kiseki/coop/triangulation.hpp``, gives the equations.

The paper's own closed forms are here too (``paper_position``, ``paper_error``), for its
symmetric case: robots 1 and 2 on the x axis, d either side of the origin, measuring theta1 and
theta2, the angle at each between the other standing robot and robot 3 (Fig. 2). Two misprints,
found by testing the formulas against each other:

* eqs. 1-2 hold with robot 1 at (-d, 0) and robot 2 at (d, 0); the text gives the opposite order,
  with which eq. 1 yields -x;
* eq. 3 as printed, dx = d (sin 2th2 dth1 + sin 2th1 dth2) / sin^2(th1 + th2), has the sign of
  its first term wrong: the derivative of eq. 1 is dx = d (-sin 2th2 dth1 + sin 2th1 dth2) /
  sin^2(th1 + th2). Only the corrected form agrees with sec. 3.2, where opposite errors
  (dth1 = -dth2) cause the cross-track (x) error; as printed they would cause none. Eq. 4 is as
  printed.
"""

from __future__ import annotations

import math

import numpy as np

from kiseki import _core
from kiseki._support.real_numbers import check_number

#: Lines of sight meeting at less than this (rad) cannot fix a position (a ValueError).
MIN_INTERSECTION_ANGLE: float = _core.TRIANGULATION_MIN_ANGLE


def triangulate(
    standing_positions,
    bearings,
    elevations=None,
    bearing_sigma: float | None = None,
    elevation_sigma: float | None = None,
    min_intersection_angle: float = MIN_INTERSECTION_ANGLE,
):
    """The moving robot's position from n >= 2 standing robots and their bearings.

    ``standing_positions``: (n, 2), or (n, 3) with ``elevations``; ``bearings`` (n,) in radians in
    the world frame (counter-clockwise from +x); ``elevations`` (n,) in radians above the
    horizontal. More than two robots: the weighted least-squares point of the lines of sight.
    Returns the position, shape (2,) or (3,); with ``bearing_sigma`` (rad, the SD of each
    bearing; ``elevation_sigma`` defaults to it) returns ``(position, covariance)``.

    Raises ValueError naming the geometry when the bearings cannot fix a position: fewer than
    two robots, coincident robots, lines of sight meeting at less than
    ``min_intersection_angle`` (nearly parallel: theta1 + theta2 near 0 or pi), a bearing
    pointing away from where the others meet, or a non-finite value.
    """
    for name, value in (("bearing_sigma", bearing_sigma), ("elevation_sigma", elevation_sigma)):
        # an SD of 1e300 rad gave a NaN and infinite covariance; beyond pi a bearing says nothing
        if value is not None:
            check_number(value, name, 0.0, math.pi, unit="rad")
    if elevation_sigma is not None and bearing_sigma is None:  # was ignored: a position only
        raise ValueError(
            f"elevation_sigma ({elevation_sigma!r}) needs bearing_sigma, which is None: the "
            "covariance is returned only with bearing_sigma"
        )
    sigma = 0.0 if bearing_sigma is None else float(bearing_sigma)
    try:
        points = np.asarray(standing_positions, dtype=float)
    except (TypeError, ValueError) as error:
        raise ValueError(f"standing_positions: expected numbers ({error})") from None
    origin = _first_robot(points)
    if elevations is None:
        if points.ndim != 2 or points.shape[1] != 2:
            raise ValueError(
                f"standing_positions: expected shape (n, 2) (or (n, 3) with elevations), got "
                f"{points.shape}"
            )
        position, covariance, _ranges, _angle = _core.triangulate_2d(
            points - origin, bearings, sigma, float(min_intersection_angle)
        )
    else:
        if points.ndim != 2 or points.shape[1] != 3:
            raise ValueError(
                f"standing_positions: expected shape (n, 3) with elevations, got {points.shape}"
            )
        position, covariance, _ranges, _angle = _core.triangulate_3d(
            points - origin,
            bearings,
            elevations,
            sigma,
            0.0 if elevation_sigma is None else float(elevation_sigma),
            float(min_intersection_angle),
        )
    position = position + origin
    if bearing_sigma is None:
        return position
    return position, covariance


def _first_robot(points: np.ndarray) -> np.ndarray | float:
    """Where the first standing robot is: the solver works on positions relative to it. Its test
    for coincident robots, closer than 1e-9 (1 + |position|) m, took robots 1 m apart 1e9 m
    from the origin for one. 0 when a position is not finite or beyond 1e300 m (the solver
    names those, or any difference would overflow)."""
    if points.ndim != 2 or points.size == 0 or not np.abs(points).max() < 1e300:
        return 0.0
    return points[0].copy()


def _check_angles(theta1: float, theta2: float) -> None:
    check_number(theta1, "theta1", unit="rad")
    check_number(theta2, "theta2", unit="rad")
    if not (0 < theta1 < math.pi and 0 < theta2 < math.pi and theta1 + theta2 < math.pi):
        raise ValueError(
            f"theta1 = {theta1:.4g} and theta2 = {theta2:.4g} rad must be interior angles of a "
            "triangle (each in (0, pi), their sum below pi)"
        )
    if abs(math.sin(theta1 + theta2)) < math.sin(MIN_INTERSECTION_ANGLE):
        raise ValueError(
            f"theta1 + theta2 = {theta1 + theta2:.4g} rad is near 0 or pi: the lines of sight are "
            "nearly parallel"
        )


def _check_d(d: float) -> None:
    # a NaN d gave (NaN, NaN), a negative one swapped the robots without a word
    check_number(d, "d (robots 1 and 2 at -d and d)", 0.0, low_open=True, unit="m")


def paper_position(d: float, theta1: float, theta2: float) -> np.ndarray:
    """Eqs. 1-2: robot 3's (x, y) from robot 1 at (-d, 0) and robot 2 at (d, 0)."""
    _check_d(d)
    _check_angles(theta1, theta2)
    t1, t2 = math.tan(theta1), math.tan(theta2)
    return np.array([d * (-t1 + t2) / (t1 + t2), 2 * d * t1 * t2 / (t1 + t2)])


def paper_error(
    d: float, theta1: float, theta2: float, dtheta1: float, dtheta2: float
) -> np.ndarray:
    """Eqs. 3-4 (eq. 3's first sign corrected, see the module): (dx, dy) for small angle
    errors dtheta1, dtheta2."""
    _check_d(d)
    _check_angles(theta1, theta2)
    check_number(dtheta1, "dtheta1", unit="rad")  # NaN gave NaN
    check_number(dtheta2, "dtheta2", unit="rad")
    s2 = math.sin(theta1 + theta2) ** 2
    dx = d * (-math.sin(2 * theta2) * dtheta1 + math.sin(2 * theta1) * dtheta2) / s2
    dy = 2 * d * (math.sin(theta2) ** 2 * dtheta1 + math.sin(theta1) ** 2 * dtheta2) / s2
    return np.array([dx, dy])
