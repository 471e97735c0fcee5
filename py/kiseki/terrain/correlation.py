# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The correlation search of paper 003 (sec. 6, eq. 4): the previous local map, seen from a
candidate centre (x_v, y_v, z_v), makes a virtual S-DEM r_v (eq. 3); its cost against the
current S-DEM is

    d = sum over the cells with data in both of (r_v - r_cur)^2 cos(phi),

minimised over a grid of candidates: the paper's x 0..70 cm, y -50..50 cm, z -30..30 cm in
2 cm steps (56,916 candidates). The attitude change comes from the gyro and is not searched.

``cost="sum"`` (the default) is eq. 4 as printed. ``cost="mean"`` is kiseki's named variant: it
divides the sum by the sum of the weights cos(phi). Why a variant: a sum rewards a candidate for
sharing fewer cells (fewer terms, a smaller sum), so in a corridor, where the candidates further
along share fewer cells, the printed sum's minimum slides along it (terrain-corridor reports both).
A candidate sharing fewer than ``min_overlap`` cells is not scored (+inf). The C++ core does the
work on every core (``kiseki/terrain/correlation_search.hpp``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from kiseki import _core
from kiseki._support.counts import check_count
from kiseki._support.options import THREAD_LIMIT
from kiseki._support.schema import INT32_MAX
from kiseki.terrain.sdem import SphereElevationMap

__all__ = ["PAPER_SEARCH", "SearchGrid", "SearchResult", "correlation_search", "search_grid"]

SearchGrid = _core.TranslationGrid


def search_grid(
    x: tuple[float, float] = (0.0, 0.70),
    y: tuple[float, float] = (-0.50, 0.50),
    z: tuple[float, float] = (-0.30, 0.30),
    step: float = 0.02,
) -> SearchGrid:
    """The candidates (metres, previous sensor frame); the paper's by default. Raises
    ValueError for a step <= 0 (a grid of zero steps), an inverted axis or NaN."""
    g = _core.TranslationGrid()
    try:
        g.x_min, g.x_max = (float(v) for v in x)
        g.y_min, g.y_max = (float(v) for v in y)
        g.z_min, g.z_max = (float(v) for v in z)
        g.step = float(step)
    except (TypeError, ValueError) as e:
        raise ValueError(f"search grid: expected pairs of numbers and a step, {e}") from None
    g.validate()
    return g


PAPER_SEARCH = search_grid()
"""The paper's 36 x 51 x 31 = 56,916 candidates."""


@dataclass(frozen=True)
class SearchResult:
    """The best candidate (m), its cost and shared cells, how many candidates were scored, and
    (exhaustive search) the cost surface (nx, ny, nz), +inf where not scored."""

    translation: np.ndarray
    cost: float
    overlap: int
    evaluated: int
    method: str
    costs: np.ndarray | None = None

    @property
    def found(self) -> bool:
        return math.isfinite(self.cost)


def correlation_search(
    previous: SphereElevationMap,
    current: SphereElevationMap,
    rotation: Any = None,
    grid: SearchGrid | None = None,
    method: Literal["exhaustive", "coarse-to-fine"] = "exhaustive",
    cost: Literal["sum", "mean"] = "sum",
    min_overlap: int = 50,
    threads: int = 0,
) -> SearchResult:
    """The motion (x, y, z) from the previous S-DEM to the current one (previous sensor frame).
    rotation: the current sensor's attitude in the previous sensor's frame (R_prev^T R_cur,
    from the gyro); None: unchanged. cost: eq. 4 as printed (``sum``) or kiseki's ``mean``.
    Raises ValueError for an empty map, a bad grid, a NaN attitude or an unknown method."""
    for name, m in (("previous", previous), ("current", current)):
        if not isinstance(m, SphereElevationMap):
            raise TypeError(f"correlation search: {name} must be a SphereElevationMap")
        if m.valid_cells == 0:
            raise ValueError(f"correlation search: the {name} S-DEM is empty")
    if method not in ("exhaustive", "coarse-to-fine"):
        raise ValueError(f"method must be 'exhaustive' or 'coarse-to-fine', got {method!r}")
    min_overlap = check_count(min_overlap, "min_overlap", 1, INT32_MAX)
    threads = check_count(threads, "threads", 0, THREAD_LIMIT, "0 = every core")
    grid = PAPER_SEARCH if grid is None else grid
    if not isinstance(grid, _core.TranslationGrid):
        raise TypeError("correlation search: grid must be a SearchGrid (search_grid())")
    grid.validate()
    points, _ = previous.to_points()
    search = _core.CorrelationSearch(points, current, rotation, cost, min_overlap, threads)
    if method == "exhaustive":
        r = search.exhaustive(grid)
        costs = np.asarray(r["costs"]).reshape(grid.shape)
    else:
        r = search.coarse_to_fine(grid)
        costs = None
    return SearchResult(
        np.asarray(r["translation"]), float(r["cost"]), int(r["overlap"]), int(r["evaluated"]),
        method, costs,
    )  # fmt: skip
