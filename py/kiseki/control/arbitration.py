# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Arbitration between navigators by priority, as in the multi-navigator system of the
magnetic-navigation thesis (``002_74cea16d239c028f.txt``, sec. 4.3.2, Fig. 4.1): every navigator
proposes a command each step and says whether the sensor data it uses is valid; a navigator's
priority is its fixed value when valid and 0 otherwise, and "the command of the navigator with
the highest priority is the command actually used". The arbiter keeps, step by step, which
navigator drove and every navigator's effective priority (Fig. 4.12's "priority history").

Generic: the navigators (and what "valid" means for each) live with the method that defines
them; this module knows only names, priorities and opaque commands.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from kiseki._support.real_numbers import check_number

__all__ = ["PriorityArbiter"]


class PriorityArbiter:
    """Picks, each step, the command of the valid navigator with the highest fixed priority.

    ``priorities``: {navigator name: priority}, priorities finite, > 0 (0 is the thesis'
    "disabled") and distinct (so the choice never depends on order). :meth:`select` takes
    {name: (command, valid)} for every navigator and returns (name, command) of the winner, or
    (None, None) when no navigator is valid (the caller decides what to do then, e.g. stop).
    ``history`` holds the winner's name (None: none valid) per step, ``priority_history()`` the
    effective priorities (fixed value if valid, else 0) per step and navigator."""

    def __init__(self, priorities: Mapping[str, float]) -> None:
        if not isinstance(priorities, Mapping) or not priorities:
            raise ValueError("PriorityArbiter: priorities must be a non-empty {name: priority}")
        for name, value in priorities.items():
            if not isinstance(name, str) or not name:
                raise ValueError(f"PriorityArbiter: a navigator name must be text, got {name!r}")
            check_number(value, f"PriorityArbiter: priority of {name!r}", 0.0, low_open=True)
        values = list(priorities.values())
        if len(set(values)) != len(values):
            raise ValueError(
                f"PriorityArbiter: priorities must be distinct, got {dict(priorities)}"
            )
        self.names: tuple[str, ...] = tuple(sorted(priorities, key=priorities.get, reverse=True))
        self.priorities: dict[str, float] = {n: float(priorities[n]) for n in self.names}
        self.history: list[str | None] = []
        self._effective: list[list[float]] = []

    def select(self, proposals: Mapping[str, tuple[Any, bool]]) -> tuple[str | None, Any]:
        """The winner of one step (see the class text); logs it."""
        if not isinstance(proposals, Mapping):
            raise ValueError("PriorityArbiter.select: proposals must be {name: (command, valid)}")
        unknown = sorted(set(proposals) - set(self.names))
        missing = [n for n in self.names if n not in proposals]
        if unknown or missing:
            raise ValueError(
                f"PriorityArbiter.select: proposals must name every navigator exactly:"
                f" unknown {unknown}, missing {missing}"
            )
        effective, winner, command = [], None, None
        for name in self.names:  # highest priority first
            entry = proposals[name]
            if not (isinstance(entry, tuple) and len(entry) == 2):
                raise ValueError(
                    f"PriorityArbiter.select: {name!r} must give (command, valid), got {entry!r}"
                )
            valid = entry[1]
            if not isinstance(valid, bool | np.bool_):
                raise ValueError(
                    f"PriorityArbiter.select: validity of {name!r} must be a bool, got {valid!r}"
                )
            effective.append(self.priorities[name] if valid else 0.0)
            if valid and winner is None:
                winner, command = name, entry[0]
        self.history.append(winner)
        self._effective.append(effective)
        return winner, command

    def priority_history(self) -> np.ndarray:
        """(steps, navigators) effective priorities, columns in the order of ``names``."""
        return np.array(self._effective, dtype=np.float64).reshape(-1, len(self.names))

    def last_priorities(self) -> np.ndarray:
        """The effective priorities of the latest step (zeros before the first)."""
        row = self._effective[-1] if self._effective else [0.0] * len(self.names)
        return np.array(row, dtype=np.float64)

    def shares(self) -> dict[str | None, float]:
        """The fraction of steps each navigator drove (None: no valid navigator)."""
        n = max(len(self.history), 1)
        keys: list[str | None] = [*self.names, None]
        return {k: sum(1 for h in self.history if h == k) / n for k in keys}
