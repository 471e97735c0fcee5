# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What every speed limit of paper 004's comparison does with its output: a rate limit, and the
speed it starts from.

``AccelerationLimit``: the output moves towards the wanted limit by at most a_max * dt per
update, up and down alike (the robot can neither speed up nor brake faster than a_max), starting
from ``initial`` (0 m/s by default: the robot starts at rest). ``check_initial_speed``: that
start lies in [0, v_max]; ``check_top_speed``: v_max lies in (0, SPEED_LIMIT]."""

from __future__ import annotations

import numbers

from kiseki._support.real_numbers import check_number

__all__ = ["SPEED_LIMIT", "AccelerationLimit", "check_initial_speed", "check_top_speed"]

SPEED_LIMIT = 10.0
"""m/s: the most a limiter's v_max may be; faster than any robot that drives among people, which
the limits are for (and v_max^2 of 1e200 m/s overflowed the stopping distance)."""


class AccelerationLimit:
    """Rate limiter: each ``step`` moves ``value`` towards ``target`` by at most a_max * dt."""

    def __init__(self, a_max: float, initial: float = 0.0) -> None:
        self.a_max = check_number(a_max, "a_max", 0.0, low_open=True, unit="m/s^2")
        self.value = check_number(initial, "initial")

    def step(self, target: float, dt: float) -> float:
        """The new value after ``dt`` seconds of moving towards ``target`` (m/s)."""
        check_number(dt, "dt", 0.0, unit="s")
        check_number(target, "target")
        reach = self.a_max * dt
        self.value += min(reach, max(-reach, target - self.value))
        return self.value


def check_top_speed(name: str, v_max) -> None:
    """A limiter's v_max: a finite number in (0, SPEED_LIMIT] m/s."""
    check_number(v_max, name, 0.0, SPEED_LIMIT, low_open=True, unit="m/s")


def check_initial_speed(name: str, initial, v_max: float) -> None:
    """A limiter's starting speed lies in [0, v_max]: above it, the first limits exceeded the
    robot's maximum speed (they fall from there at a_max)."""
    if (
        isinstance(initial, bool)
        or not isinstance(initial, numbers.Real)
        or not 0 <= initial <= v_max
    ):
        raise ValueError(f"{name} must be a speed in [0, v_max = {v_max:g}] m/s, got {initial!r}")
