# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The movement plans of the cooperative positioning loop of Hirose, Nagata and Kurazume
(sec. 2, Fig. 1): three robots take turns; at each move one robot drives to a planned point while
the other two stand and triangulate it. This module holds the plans (which robot moves where,
which two measure it); :mod:`kiseki.coop.simulation` runs them with noisy angles.

**The two movement forms.** The paper's drawings (Figs. 3, 4) are not in its text; it says only
that advancing one unit along y takes 2 moves in form 1 and 1 in form 2, and that each form has
a representative angle. kiseki's reading, with both forms starting from the paper's positions
(robots at (-1, 0), (1, 0) and, behind them, (0, -1)) and ending with a move onto the goal:

* **Form 1, pair and scout** (2 moves per unit). Two robots stand side by side, half-width w
  apart from their centre; the third, behind them, moves to the apex ahead of them where both
  see it at the representative angle theta from their baseline (theta_1 = theta_2 = theta, the
  case of the paper's sec. 3.1; the unit is that apex height h = w tan(theta)). Then the pair
  robot nearer to where it goes moves up beside the scout, 2 w to the side, so that the scout
  and it form the next pair (the centre of the pair moving by w to one side and back the next
  time); the pair robot left behind is the next scout. The first apex is over the start's
  baseline (w = 1 m); the others are spaced evenly to reach the goal, with w = h / tan(theta).
  An odd number of moves (A, B, ..., A): the last is the scout's, to the goal. The joiner is
  seen by the scout along the new pair's line and by the robot left behind from 3 w to the
  side: the two lines of sight meet at atan(tan(theta) / 3), 25 deg at theta = 55 deg.
* **Form 1, crossing** (``reading="crossing"``, a second reading of the same drawing-less
  text): as pair and scout, but the pair robot *farther* from the joiner's place crosses over
  to it, so the robot left behind stands under the new pair's centre (w to the side of the
  joiner's place, h behind): every triangulation then has its lines of sight meet at the
  representative angle theta, and the next scout goes straight up the centre line. This is the
  reading in which, as the paper says of each form, one angle represents every measurement.
* **Form 2, leapfrog** (1 move per unit). The robots stand on a zigzag of points on two rails
  x = +-w, one unit s apart along y; at each move the rearmost robot jumps over the other two to
  the next point ahead. Each measured triangle is isosceles: the standing robot on the mover's
  rail, 2 s behind, sees the mover and the other standing robot at the representative angle
  theta (tan(theta) = 2 w / s), and so does the mover. s = distance / n; the last point is the
  goal.

The number of moves n and the representative angle are independent in both forms: the
formation's width follows from them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from kiseki._support.counts import check_count
from kiseki._support.moved import moved_names
from kiseki._support.real_numbers import check_number

#: The paper's simulation (sec. 4): start positions, goal, angle noise.
START = np.array([[-1.0, 0.0], [1.0, 0.0], [0.0, -1.0]])
GOAL = np.array([0.0, 10.0])
ANGLE_SIGMA = math.radians(0.1)
FORMS = (1, 2)
FORM1_READINGS = ("pair-scout", "crossing")
"""kiseki's readings of form 1 (see the module): the first is the one run by default."""

# moved by the split of the noisy runs (answered for one release, with a warning)
__getattr__ = moved_names(
    __name__,
    dict.fromkeys(("CoopRun", "CoopRun3D", "simulate", "simulate_3d"), "kiseki.coop.simulation"),
)


@dataclass(frozen=True)
class Move:
    """One step: ``robot`` drives to ``target`` while ``standing`` (two robots) measure it."""

    robot: int
    target: np.ndarray
    standing: tuple[int, int]


@dataclass(frozen=True)
class Plan:
    form: int  # 1 or 2; 0: chosen by the planner (kiseki.coop.planner)
    moves: int
    angle: float  # rad, the representative angle (NaN for the planner's)
    start: np.ndarray = field(repr=False)
    steps: list[Move] = field(repr=False)
    reading: str = ""  # form 1's reading (FORM1_READINGS); "" for form 2 and the planner

    def sight_angles(self) -> np.ndarray:
        """(moves,) the angle (rad, 0..pi/2) at which the two standing robots' lines of sight
        meet at each move's target: small angles make weak triangles."""
        at = self.nominal_positions()
        out = []
        for k, m in enumerate(self.steps):
            u, v = (m.target - at[k][i] for i in m.standing)
            c = abs(float(u @ v)) / (float(np.hypot(*u)) * float(np.hypot(*v)))
            out.append(math.acos(min(1.0, c)))
        return np.array(out)

    def nominal_positions(self) -> np.ndarray:
        """(moves + 1, 3, 2): every robot's planned position before the first move and after
        each move."""
        at = self.start.copy()
        out = [at.copy()]
        for m in self.steps:
            at[m.robot] = m.target
            out.append(at.copy())
        return np.array(out)


def _check_places(start, goal) -> tuple[np.ndarray, np.ndarray]:
    try:
        start = np.asarray(start, dtype=float)
        goal = np.asarray(goal, dtype=float)
    except (TypeError, ValueError):
        raise ValueError("start and goal must be numbers") from None
    if start.shape != (3, 2) or not np.isfinite(start).all():
        raise ValueError(f"start: expected 3 finite (x, y) rows, got shape {start.shape}")
    if goal.shape != (2,) or not np.isfinite(goal).all():
        raise ValueError(f"goal: expected a finite (x, y), got {goal!r}")
    if not goal[1] > start[:, 1].max():
        raise ValueError("the goal must lie ahead (greater y) of every start position")
    return start, goal


def paper_angle(form: int, moves: int, start=START, goal=GOAL) -> float:
    """The representative angle (rad) when the formation keeps the start's width, as in the
    paper's simulation, where the number of moves alone sets the geometry: form 1, tan(theta)
    = h / w with h = distance / ((moves + 1) / 2); form 2, tan(theta) = 2 w / s with s =
    distance / moves (w: half the start's baseline, 1 m)."""
    start, goal = _check_places(start, goal)
    if form not in FORMS:
        raise ValueError(f"form must be 1 or 2, got {form!r}")
    moves = check_count(moves, "moves", 1)
    order = np.argsort(start[:, 1])
    w = abs(start[order[1], 0] - start[order[2], 0]) / 2
    if form == 1:
        level = start[order[1:], 1].mean()
        return math.atan((goal[1] - level) / ((moves + 1) // 2) / w)
    return math.atan(2 * w / ((goal[1] - start[:, 1].max()) / moves))


MAX_MOVES = 1000  # the most moves a plan takes


def _check(form: int, moves: int, angle: float) -> None:
    if form not in FORMS:
        raise ValueError(f"form must be 1 or 2, got {form!r}")
    if form == 1 and moves % 2 == 0:
        raise ValueError(
            f"form 1 takes an odd number of moves (scout, pair, ..., scout), got {moves}"
        )
    check_number(angle, "the representative angle", unit="rad")  # True was 1 rad (57 deg)
    if not math.radians(5) <= angle <= math.radians(85):
        raise ValueError(
            f"the representative angle must lie in 5..85 deg, got {math.degrees(angle)}"
        )


def plan(
    form: int,
    moves: int,
    angle: float | None = None,
    start=START,
    goal=GOAL,
    reading: str = FORM1_READINGS[0],
) -> Plan:
    """The planned moves of a form (see the module) from ``start`` (3 x 2, the paper's by
    default) to ``goal`` in ``moves`` moves at the representative ``angle`` (rad; None: the
    formation keeps the start's width and the angle follows from ``moves``, ``paper_angle``);
    ``reading``: form 1's reading (FORM1_READINGS; form 2 has one)."""
    start, goal = _check_places(start, goal)
    if reading not in FORM1_READINGS:
        raise ValueError(f"reading must be one of {', '.join(FORM1_READINGS)}, got {reading!r}")
    moves = check_count(moves, "moves", 1, MAX_MOVES)  # the Plan holds Python's int
    if angle is None:
        angle = paper_angle(form, moves, start, goal)
        odd = form == 2 or moves % 2 == 1  # form 1's rule on the moves is said first (_check)
        if form in FORMS and odd and not math.radians(5) <= angle <= math.radians(85):
            raise ValueError(  # it read as if an angle given were out of range
                f"form {form} keeping the start's width to the goal ({goal[0]:g}, {goal[1]:g}) "
                f"in {moves} move{'s' if moves > 1 else ''} stands at "
                f"{math.degrees(angle):.3g} deg, out of the representative angle's 5..85 deg: "
                "move the goal, change the moves or give the angle"
            )
    _check(form, moves, angle)
    if form == 2:
        return Plan(form, moves, angle, start, _form2(moves, angle, start, goal))
    crossing = reading == "crossing"
    return Plan(form, moves, angle, start, _form1(moves, angle, start, goal, crossing), reading)


def _form1(
    moves: int, angle: float, start: np.ndarray, goal: np.ndarray, crossing: bool
) -> list[Move]:
    pair = [int(i) for i in np.argsort(start[:, 1])[1:]]  # the two ahead; the third scouts
    scout = int(np.argmin(start[:, 1]))
    pos = start.copy()
    level = float(pos[pair, 1].mean())
    centre = float(pos[pair, 0].mean())  # the start's pair is centred on the goal's x
    width = abs(pos[pair[0], 0] - pos[pair[1], 0]) / 2
    apexes = (moves + 1) // 2
    first = width * math.tan(angle)
    if apexes > 1 and level + first >= goal[1]:
        raise ValueError(
            f"at {math.degrees(angle):.0f} deg the first apex over the start's baseline is "
            "already past the goal: use a smaller angle or fewer moves"
        )
    rise = first if apexes == 1 else (goal[1] - level - first) / (apexes - 1)
    steps: list[Move] = []
    turn = 1.0  # the side the joiner takes when the scout is on the centre line: +, -, +, ...
    for k in range(apexes):
        h = first if k == 0 else rise
        target = np.array([centre, level + h]) if k < apexes - 1 else goal.copy()
        steps.append(Move(scout, target, (pair[0], pair[1])))
        pos[scout] = target
        if k == apexes - 1:
            break
        level += h
        width = rise / math.tan(angle)
        if abs(target[0] - goal[0]) < 1e-12:  # the scout on the centre line: alternate sides
            side, turn = turn, -turn
        else:  # off it: the pair's centre goes back to the line
            side = -math.copysign(1.0, target[0] - goal[0])
        joiner_at = np.array([target[0] + 2 * width * side, level])
        near = min(pair, key=lambda i: float(np.hypot(*(pos[i] - joiner_at))))
        joiner = (pair[0] if near == pair[1] else pair[1]) if crossing else near
        left = pair[0] if joiner == pair[1] else pair[1]
        steps.append(Move(joiner, joiner_at, (scout, left)))
        pos[joiner] = joiner_at
        pair, scout = [scout, joiner], left
        centre = float(target[0] + width * side)
    return steps


def _form2(moves: int, angle: float, start: np.ndarray, goal: np.ndarray) -> list[Move]:
    pos = start.copy()
    base = float(pos[:, 1].max())
    s = (goal[1] - base) / moves
    w = s * math.tan(angle) / 2
    order = [int(i) for i in np.argsort(pos[:, 1], kind="stable")]  # rearmost first
    steps: list[Move] = []
    for j in range(1, moves + 1):
        mover = order[0]
        target = (
            goal.copy() if j == moves else np.array([goal[0] + (w if j % 2 else -w), base + j * s])
        )
        steps.append(Move(mover, target, (order[1], order[2])))
        pos[mover] = target
        order = [order[1], order[2], mover]
    return steps
