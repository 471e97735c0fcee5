# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The benchmarks' clock: the best of several runs of a call (other work on the machine only
ever slows a run down, so the fastest is the closest to the call's own cost)."""

from __future__ import annotations

import time


def best_of(fn, repeats: int = 3) -> tuple[float, object]:
    """(the fastest of ``repeats`` runs of ``fn()`` in seconds, the last run's result)."""
    best, result = float("inf"), None
    for _ in range(repeats):
        start = time.perf_counter()
        result = fn()
        best = min(best, time.perf_counter() - start)
    return best, result
