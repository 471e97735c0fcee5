# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The four navigators of the multi-navigator magnetic navigation (thesis
``002_74cea16d239c028f.txt``, sec. 4.3.2) and their arbitration by priority
(:class:`kiseki.control.PriorityArbiter`).

The robot is at node n of the linear map (found from its travel distance) with heading
theta_t, magnetometer reading m_t and geometric features g_t = (g_l,t, g_r,t). Each navigator
controls the angular velocity to bring its deviation to zero (positive: turn left):

* odometry, eq. 4.1: ``e_o = theta_n - theta_t``;
* geometric, eq. 4.2: ``e_g = (e_o, -g_l,n + g_l,t, g_r,n - g_r,t)``;
* magnetic, eq. 4.3: ``e_m = m_theta,n - m_theta,t``;
* magnetic and geometric, eq. 4.4: ``e_gm = (e_m, -g_l,n + g_l,t, g_r,n - g_r,t)``.

A side without an obstacle (g NaN at the node or now) is "not used" (sec. 4.3.2). The
components are summed with ``geometric_gain`` rad/m on the g terms (the thesis does not print
how they are combined) and PD-controlled (:class:`kiseki.control.PdSteering`).

Priorities (sec. 4.3.2, "Priority setting"): mag+geo > magnetic > geometric > odometry, fixed
values when valid, 0 otherwise. The magnetic ones are invalid when ``r_z = 1 - |m_z,n - m_z,t| /
dm_z,max < 0.998`` (eq. 4.5, dm_z,max = 1 G), the geometric ones when ``|g_n - g_t| > 1.0 m``
on a side (a dynamic obstacle); kiseki also counts as invalid a geometric navigator with no side
seen both at the node and now (nothing to correct with: Fig. 4.12's priorities drop "where no
geometric landmark exists") and a side seen at only one of the two (a change of the layout).
The odometry navigator is always valid. A navigator run alone (Fig. 4.9's single-navigator
runs) drives whatever its validity.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from kiseki._support.counts import check_count
from kiseki._support.real_numbers import check_number
from kiseki.control.arbitration import PriorityArbiter
from kiseki.control.pd_steering import PdSteering

__all__ = [
    "DMZ_MAX",
    "G_CHANGE_MAX",
    "NAVIGATORS",
    "PRIORITIES",
    "RZ_MIN",
    "MultiNavigator",
    "geometric_terms",
    "geometric_valid",
    "magnetic_valid",
    "r_z",
]

NAVIGATORS = ("magnetic-geometric", "magnetic", "geometric", "odometry")
PRIORITIES = {"magnetic-geometric": 4.0, "magnetic": 3.0, "geometric": 2.0, "odometry": 1.0}
RZ_MIN = 0.998
"""r_z below this disables the magnetic navigators (sec. 4.3.2)."""
DMZ_MAX = 1.0
"""G: dm_z,max of eq. 4.5."""
G_CHANGE_MAX = 1.0
"""m: |g_n - g_t| above this disables the geometric navigators (sec. 4.3.2)."""


def _wrap(a: float) -> float:
    return math.atan2(math.sin(a), math.cos(a))


def r_z(mz_node: float, mz_now: float, dmz_max: float = DMZ_MAX) -> float:
    """Eq. 4.5: ``1 - |m_z,n - m_z,t| / dm_z,max``."""
    a, b = check_number(mz_node, "r_z: m_z,n"), check_number(mz_now, "r_z: m_z,t")
    d = check_number(dmz_max, "r_z: dm_z,max", 0.0, low_open=True)
    return 1.0 - abs(a - b) / d


def magnetic_valid(mz_node: float, mz_now: float, threshold: float = RZ_MIN) -> bool:
    """The magnetic navigators' validity: r_z >= ``threshold`` (sec. 4.3.2)."""
    return r_z(mz_node, mz_now) >= threshold


def _pair(value: Any, name: str) -> np.ndarray:
    g = np.asarray(value, dtype=np.float64)
    if g.shape != (2,) or np.isinf(g).any():
        raise ValueError(f"{name} must be (g_l, g_r) in m (NaN: no obstacle), got {value!r}")
    return g


def geometric_terms(g_node: Any, g_now: Any) -> np.ndarray:
    """The g part of eqs. 4.2 / 4.4: ``(-g_l,n + g_l,t, g_r,n - g_r,t)``, NaN on a side not
    seen both at the node and now."""
    gn, gt = _pair(g_node, "g_n"), _pair(g_now, "g_t")
    return np.array([-gn[0] + gt[0], gn[1] - gt[1]])


def geometric_valid(g_node: Any, g_now: Any, max_change: float = G_CHANGE_MAX) -> bool:
    """Valid when some side is seen at the node and now, every such side changed by at most
    ``max_change`` m, and no side is seen at only one of the two (module text)."""
    gn, gt = _pair(g_node, "g_n"), _pair(g_now, "g_t")
    seen_n, seen_t = np.isfinite(gn), np.isfinite(gt)
    if np.any(seen_n != seen_t) or not np.any(seen_n):
        return False
    return bool(np.all(np.abs(gn[seen_n] - gt[seen_n]) <= max_change))


class MultiNavigator:
    """The multi-navigator system of sec. 4.3.2 over a linear map ``lmap``. ``navigators``:
    any of :data:`NAVIGATORS` (one alone: it always drives). :meth:`step` takes the node index,
    the heading estimate theta_t (rad), the reading (3,) G and g_t, and returns (navigator
    that drove, angular velocity rad/s); every navigator's PD state is updated each step.
    ``mz_limits`` (one per node, G): kiseki's gate (:func:`kiseki.magnetic.gates.gate_limits`)
    in place of the thesis' r_z >= 0.998.
    ``arbiter.history`` is the priority history of Fig. 4.12."""

    def __init__(
        self,
        lmap: Any,
        navigators: Sequence[str] = NAVIGATORS,
        heading_gain: float = 1.0,
        derivative_gain: float = 0.0,
        geometric_gain: float = 0.3,
        max_rate: float = 0.5,
        mz_limits: Any = None,
    ) -> None:
        names = tuple(navigators)
        bad = [n for n in names if n not in NAVIGATORS]
        if not names or bad or len(set(names)) != len(names):
            raise ValueError(
                f"MultiNavigator: navigators must be distinct names among {NAVIGATORS}, got"
                f" {list(navigators)!r}"
            )
        self.geometric_gain = check_number(geometric_gain, "MultiNavigator: geometric_gain", 0.0)
        self.lmap, self.names, self.alone = lmap, names, len(names) == 1
        self.mz_limits = None
        if mz_limits is not None:
            limits = np.asarray(mz_limits, dtype=np.float64)
            if limits.shape != (len(lmap),) or not np.all(np.isfinite(limits) & (limits > 0)):
                raise ValueError(
                    f"MultiNavigator: mz_limits must be {len(lmap)} finite numbers > 0 (one "
                    f"per node), got shape {limits.shape}"
                )
            self.mz_limits = limits
        self.steering = {n: PdSteering(heading_gain, derivative_gain, max_rate) for n in names}
        self.arbiter = PriorityArbiter({n: PRIORITIES[n] for n in names})

    def proposals(
        self, node: int, theta_t: float, reading: Any, g_t: Any
    ) -> dict[str, tuple[float, bool]]:
        """{navigator: (steering error u, valid)} at node ``node``."""
        node = check_count(node, "MultiNavigator: node", 0, len(self.lmap) - 1)  # True was 1
        m = np.asarray(reading, dtype=np.float64)
        if m.shape != (3,) or not np.all(np.isfinite(m)):
            raise ValueError(f"MultiNavigator: the reading must be 3 finite numbers, got {reading}")
        theta_t = check_number(theta_t, "MultiNavigator: theta_t")
        lm = self.lmap
        e_o = _wrap(float(lm.heading[node]) - theta_t)  # eq. 4.1
        e_m = _wrap(float(lm.m_theta[node]) - math.atan2(m[1], m[0]))  # eq. 4.3
        terms = geometric_terms(lm.g[node], g_t)
        g_part = self.geometric_gain * float(np.nansum(terms))
        if self.mz_limits is None:  # the thesis' gate, r_z >= 0.998 (eq. 4.5)
            mag_ok = magnetic_valid(float(lm.field[node, 2]), float(m[2]))
        else:  # kiseki's gate from the sensor's noise (kiseki.magnetic.gates)
            mag_ok = bool(abs(float(lm.field[node, 2]) - float(m[2])) <= self.mz_limits[node])
        geo_ok = geometric_valid(lm.g[node], g_t)
        table = {
            "odometry": (e_o, True),
            "geometric": (e_o + g_part, geo_ok),  # eq. 4.2
            "magnetic": (e_m, mag_ok),
            "magnetic-geometric": (e_m + g_part, mag_ok and geo_ok),  # eq. 4.4
        }
        return {n: (table[n][0], True if self.alone else table[n][1]) for n in self.names}

    def step(
        self, node: int, theta_t: float, reading: Any, g_t: Any, dt: float
    ) -> tuple[str | None, float]:
        proposals = self.proposals(node, theta_t, reading, g_t)
        rates = {n: self.steering[n].update(u, dt) for n, (u, _) in proposals.items()}
        winner, _ = self.arbiter.select({n: (rates[n], ok) for n, (_, ok) in proposals.items()})
        return winner, (0.0 if winner is None else rates[winner])
