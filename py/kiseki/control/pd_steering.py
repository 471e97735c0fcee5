# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""PD control of the angular velocity on a steering error, as the magnetic-navigation thesis
steers on its deviation vectors (``002_74cea16d239c028f.txt``, sec. 3.3.4: "the angular velocity
is PD-controlled so that each value of the deviation e becomes zero"; sec. 4.3.2: every
navigator "controls the angular velocity so that its deviation becomes zero").

Convention: a positive error means "turn left" (counter-clockwise, the world's z up), so
``w = kp u + kd du/dt`` with positive gains, clipped to +-``max_rate``."""

from __future__ import annotations

import math
import numbers

__all__ = ["PdSteering"]


def _positive(value: float, name: str, allow_zero: bool = False) -> float:
    ok = isinstance(value, numbers.Real) and not isinstance(value, bool) and math.isfinite(value)
    if not ok or value < 0 or (value == 0 and not allow_zero):
        need = ">= 0" if allow_zero else "> 0"
        raise ValueError(f"PdSteering: {name} must be a finite number {need}, got {value!r}")
    return float(value)


class PdSteering:
    """``update(u, dt)`` -> angular velocity rad/s for the scalar error u (rad, positive: turn
    left). The derivative is the difference quotient of u over dt; on the first call (and after
    :meth:`reset`) it is 0."""

    def __init__(self, kp: float, kd: float = 0.0, max_rate: float = 1.0) -> None:
        self.kp = _positive(kp, "kp")
        self.kd = _positive(kd, "kd", allow_zero=True)
        self.max_rate = _positive(max_rate, "max_rate")
        self._last: float | None = None

    def reset(self) -> None:
        self._last = None

    def update(self, u: float, dt: float) -> float:
        try:
            u = float(u)
        except (TypeError, ValueError):
            raise ValueError(f"PdSteering.update: the error must be a number, got {u!r}") from None
        if not math.isfinite(u):
            raise ValueError(f"PdSteering.update: the error must be finite, got {u!r}")
        dt = _positive(dt, "dt")
        derivative = 0.0 if self._last is None else (u - self._last) / dt
        self._last = float(u)
        w = self.kp * u + self.kd * derivative
        return max(-self.max_rate, min(self.max_rate, w))
