# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The Fuzzy Potential Method (FPM): a direction of motion and a speed from a goal and a scan.

Source: R. Tsuzaki and K. Yoshida, "Motion control based on fuzzy potential method for
autonomous mobile robot with omnidirectional vision", J. Robotics Society of Japan 21(6)
656-662, 2003; paper 004 (Yorozu, Moriguchi, Takahashi) takes its direction of motion from it.
The idea: every candidate direction psi gets a degree of membership in "good direction"; the
goal's membership attracts, each obstacle's membership repels, the two are combined with the
fuzzy AND, and the robot moves in the direction of the maximum at a speed proportional to it.
The original text was not available here; the shapes below are kiseki's choices where the
method as described leaves them open, each with its reason.

Candidate directions: psi_k = -pi + k * step, k = 0 .. n-1, n = round(2 pi / step) (the full
circle: an omnidirectional robot can move in any direction), in the frame of the scan.

Goal attraction (a triangle peaked at the goal direction psi_g):

    mu_g(psi) = max(0, 1 - |wrap(psi - psi_g)| / goal_half_width)

With the default half-width pi, mu_g falls linearly to 0 straight away from the goal, so every
direction keeps some attraction and the robot can go round an obstacle that blocks the goal.
The peak is 1: slowing down at the goal is the caller's (the navigator's stopping-distance cap).

Obstacle repulsion: every scan point i (a return shorter than ``max_range``; NaN, negative,
zero and no-return beams are ignored) at distance d_i in direction phi_i spans the collision
cone of a robot of half-width r = ``robot_radius`` + ``margin``: a robot centre moving along
psi passes the point closer than r exactly when |wrap(psi - phi_i)| < asin(r / d_i) (pi / 2
once d_i <= r). The
point's membership is rectangular over that cone -- every direction inside it leads to a
collision if held, none outside does, so there is no reason to grade it -- with a depth that
grows as the point gets closer:

    depth(d) = 1 at d <= stop_distance, 0 at d >= influence_distance, linear in between
    mu_o(psi) = max_i depth(d_i) * [|wrap(psi - phi_i)| <= asin(min(1, r / d_i))]

(the fuzzy OR of the obstacles is their maximum). The fuzzy AND of "towards the goal" and "not
towards an obstacle" is

    mu(psi) = min(mu_g(psi), 1 - mu_o(psi))

The direction is the grid direction of the maximum of mu. When several directions share the
maximum (within 1e-9), the robot takes the centre of the widest run of consecutive maximal
directions (a plateau; the circle wraps round); among equally wide plateaus, the one whose
centre is closest to the goal direction; if still tied, the one with the smaller centre angle
in [-pi, pi) (the right-hand side, clockwise): an arbitrary but fixed choice, so that
symmetric scenes give the same answer every time. A plateau of an even number of directions has
its centre between two grid directions (half a step off the grid). If every direction is
maximal the robot heads at the goal. The speed is mu(psi*) * v_max.

Parameters (``FuzzyPotentialConfig``), with units and defaults:
    v_max               0.5 m/s   the paper's robot.
    robot_radius        0.35 m    half the 0.70 m width of paper 004's robot (its w1).
    margin              0.10 m    clearance added to the half-width in the collision cones.
    stop_distance       0.50 m    obstacles at or below it repel fully (depth 1): the robot's
                                  half-width plus 0.15 m; v_max^2 / (2 a_max) = 0.25 m of
                                  braking fits inside 0.5 m from the centre.
    influence_distance  2.0 m     obstacles beyond it do not repel (half the 4 m laser range:
                                  further ones are for the speed limiter, not the heading).
    goal_half_width     pi rad    half-width of the goal triangle.
    step                1 deg     spacing of the candidate directions (rad internally).

Everything is numpy over (directions x points); there is no Python loop over beams or
directions. Distances are measured from the scan's origin: hand the method a scan expressed
about the robot's centre (``SpeedControlledNavigator`` does) for the clearances to mean what
they say.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from kiseki._support.field_types import check_field_types
from kiseki._support.real_numbers import check_number

__all__ = ["FuzzyPotentialConfig", "FuzzyPotentialMethod"]

_TIE = 1e-9


@dataclass(frozen=True)
class FuzzyPotentialConfig:
    """The FPM's parameters (see the module docstring for their meaning and units)."""

    v_max: float = 0.5
    robot_radius: float = 0.35
    margin: float = 0.10
    stop_distance: float = 0.50
    influence_distance: float = 2.0
    goal_half_width: float = math.pi
    step: float = math.radians(1.0)

    def __post_init__(self) -> None:
        check_field_types(self)
        for name, unit in (
            ("v_max", "m/s"),
            ("robot_radius", "m"),
            ("stop_distance", "m"),
            ("influence_distance", "m"),
            ("step", "rad"),
        ):
            check_number(
                getattr(self, name), f"FuzzyPotentialConfig.{name}", 0.0, low_open=True, unit=unit
            )
        check_number(self.margin, "FuzzyPotentialConfig.margin", 0.0, unit="m")
        if not self.influence_distance > self.stop_distance:
            raise ValueError(
                "FuzzyPotentialConfig.influence_distance must exceed stop_distance, got "
                f"{self.influence_distance!r} <= {self.stop_distance!r}"
            )
        if not (math.isfinite(self.goal_half_width) and 0 < self.goal_half_width <= math.pi):
            raise ValueError(
                "FuzzyPotentialConfig.goal_half_width must be in (0, pi], got "
                f"{self.goal_half_width!r}"
            )
        if not math.radians(0.01) <= self.step <= math.pi / 4:  # 36,000 directions at most
            raise ValueError(
                f"FuzzyPotentialConfig.step must be in [0.01 deg, pi/4] (rad), got {self.step!r}"
            )


def _wrap(a):
    return (np.asarray(a) + np.pi) % (2 * np.pi) - np.pi


class FuzzyPotentialMethod:
    """Direction and speed towards a goal among the obstacles of one scan (module docstring)."""

    def __init__(self, config: FuzzyPotentialConfig | None = None) -> None:
        self.config = config if config is not None else FuzzyPotentialConfig()
        n = int(round(2 * math.pi / self.config.step))
        self.directions = -math.pi + np.arange(n) * (2 * math.pi / n)

    def memberships(self, goal_xy, angles, ranges, max_range: float):
        """mu_g, mu_o and mu = min(mu_g, 1 - mu_o) over ``self.directions``, and psi_g."""
        goal, angles, ranges = _checked(goal_xy, angles, ranges, max_range)
        c = self.config
        psi_g = math.atan2(goal[1], goal[0])
        mu_g = np.maximum(0.0, 1.0 - np.abs(_wrap(self.directions - psi_g)) / c.goal_half_width)
        hit = np.isfinite(ranges) & (ranges < max_range) & (ranges < c.influence_distance)
        d, phi = ranges[hit], angles[hit]
        depth = np.clip((c.influence_distance - d) / (c.influence_distance - c.stop_distance), 0, 1)
        half = np.arcsin(np.minimum(1.0, (c.robot_radius + c.margin) / np.maximum(d, 1e-12)))
        inside = np.abs(_wrap(self.directions[:, None] - phi[None, :])) <= half[None, :]
        mu_o = np.max(np.where(inside, depth[None, :], 0.0), axis=1, initial=0.0)
        return mu_g, mu_o, np.minimum(mu_g, 1.0 - mu_o), psi_g

    def direction(self, goal_xy, angles, ranges, max_range: float) -> tuple[float, float]:
        """(heading in the scan's frame (rad, in [-pi, pi)), speed (m/s)) towards ``goal_xy``
        (m, in the scan's frame); ``angles``/``ranges`` the scan (rad, m), returns at or beyond
        ``max_range`` (m) and NaN ignored."""
        _, _, mu, psi_g = self.memberships(goal_xy, angles, ranges, max_range)
        best = float(mu.max())
        heading = _plateau_centre(self.directions, mu >= best - _TIE, psi_g)
        return heading, best * self.config.v_max


def _checked(goal_xy, angles, ranges, max_range):
    goal = np.asarray(goal_xy, dtype=float).reshape(-1)
    if goal.shape != (2,) or not np.isfinite(goal).all():
        raise ValueError(f"the goal must be two finite numbers (x, y), got {goal_xy!r}")
    if math.hypot(goal[0], goal[1]) == 0.0:
        raise ValueError("the goal coincides with the scan's origin: no direction towards it")
    angles = np.asarray(angles, dtype=float).reshape(-1)
    ranges = np.asarray(ranges, dtype=float).reshape(-1)
    if angles.size == 0:
        raise ValueError("the scan is empty")
    if angles.shape != ranges.shape:
        raise ValueError(f"{angles.size} angles but {ranges.size} ranges")
    if not np.isfinite(angles).all():
        raise ValueError("the scan's angles must be finite")
    check_number(max_range, "max_range", 0.0, low_open=True, unit="m")
    # kiseki's rule for readings (kiseki.scans): a negative or zero one is invalid, as NaN; it
    # counted as an obstacle at the robot, blocking half the directions
    ranges = np.where(ranges > 0, ranges, np.nan)
    return goal, angles, ranges


def _plateau_centre(directions: np.ndarray, is_max: np.ndarray, psi_g: float) -> float:
    """Centre of the widest run of True in the circular ``is_max`` (ties: closest to psi_g,
    then the smallest angle)."""
    n = directions.size
    step = 2 * math.pi / n
    if is_max.all():
        return float(directions[np.argmin(np.abs(_wrap(directions - psi_g)))])
    shift = int(np.flatnonzero(~is_max)[0])  # rotate so that the sequence starts outside a run
    rolled = np.roll(is_max, -shift).astype(np.int8)
    edges = np.diff(np.concatenate(([0], rolled, [0])))
    starts, stops = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    widths = stops - starts
    centres = _wrap(directions[0] + (shift + (starts + stops - 1) / 2.0) * step)
    wide = widths == widths.max()
    off = np.abs(_wrap(centres - psi_g))
    candidates = np.flatnonzero(wide & (off <= off[wide].min() + _TIE))
    return float(np.min(centres[candidates]))
