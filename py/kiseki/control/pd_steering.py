# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""PD control of the angular velocity on a steering error, as the magnetic-navigation thesis
steers on its deviation vectors (``002_74cea16d239c028f.txt``, sec. 3.3.4: "the angular velocity
is PD-controlled so that each value of the deviation e becomes zero"; sec. 4.3.2: every
navigator "controls the angular velocity so that its deviation becomes zero").

Convention: a positive error means "turn left" (counter-clockwise, the world's z up), so
``w = kp u + kd du/dt`` with positive gains, clipped to +-``max_rate``."""

from __future__ import annotations

from kiseki._support.real_numbers import check_number

__all__ = ["PdSteering"]


class PdSteering:
    """``update(u, dt)`` -> angular velocity rad/s for the scalar error u (rad, positive: turn
    left). The derivative is the difference quotient of u over dt; on the first call (and after
    :meth:`reset`) it is 0."""

    def __init__(self, kp: float, kd: float = 0.0, max_rate: float = 1.0) -> None:
        self.kp = check_number(kp, "PdSteering: kp", 0.0, low_open=True)
        self.kd = check_number(kd, "PdSteering: kd", 0.0)
        self.max_rate = check_number(
            max_rate, "PdSteering: max_rate", 0.0, low_open=True, unit="rad/s"
        )
        self._last: float | None = None

    def reset(self) -> None:
        self._last = None

    def update(self, u: float, dt: float) -> float:
        u = check_number(u, "PdSteering.update: the error")
        dt = check_number(dt, "PdSteering: dt", 0.0, low_open=True, unit="s")
        derivative = 0.0 if self._last is None else (u - self._last) / dt
        self._last = u
        w = self.kp * u + self.kd * derivative
        return max(-self.max_rate, min(self.max_rate, w))
