# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The space observation model of the teaching-and-playback thesis (sec. 3.3), in C++
(``SpaceObservationModel``), and a straightforward numpy version of the same formula used as
the reference in tests and benchmarks.

Penetration ratio = 100 |free in L and occupied in m_i| / |occupied in m_i|, intrusion ratio =
100 |occupied in L and free in m_i| / |free in m_i|, both over cells inside L's field of view;
likelihood = exp(-pen^2 / (2 * 10^2)) * exp(-intr^2 / (2 * 130^2)). The thesis gives the ratios
without a unit; sigma 10 vs 130 only makes sense in percent (penetration costly, intrusion, which
unknown obstacles cause, cheap), so percent it is.

Occlusion-aware (proposal 1 of the thesis), the map the particle should observe: free map cells
its cell cannot see count as occupied. Visibility (``visibility_reference``, the C++ model's
``visible_from``): from the centre of the particle's cell, one straight segment to the centre of
every cell on the border of the span x span window around it. A segment sees the cells it passes
through, in order, up to and including the first occupied one. Where it passes exactly through a
cell corner it also sees the two cells touching that corner on either side, and it stops there
if both of them are occupied (a diagonal wall seals; one grazed corner does not). Cells outside
the map are never occupied.
"""

from __future__ import annotations

from itertools import groupby

import numpy as np

from kiseki._core import LocalMapBuilder, SpaceObservationModel
from kiseki._support.counts import check_count
from kiseki.grid import OccupancyGrid

__all__ = [
    "LocalMapBuilder",
    "SpaceObservationModel",
    "counts_reference",
    "likelihood_reference",
    "visibility_reference",
]


def visibility_reference(
    grid: OccupancyGrid, cell, span: int, occupied_threshold: int = 65
) -> np.ndarray:
    """The span x span window of map cells centred on ``cell`` (x, y), 1 where the centre cell
    sees it, else 0 (int8, [row, column]); the definition is in the module's docstring.

    Each segment is walked by its boundary crossings in order: with (di, dj) the border cell's
    offset, it crosses column boundaries at t = (2m + 1) / (2|di|), m < |di|, and row boundaries
    at t = (2n + 1) / (2|dj|), n < |dj| (t = 1 at the border cell's centre); a column and a row
    crossing at the same t are a corner. Exact in integers: times 2 |di| |dj| (a factor 0 taken
    as 1, for a segment along a row or a column), t is (2m + 1) |dj| and (2n + 1) |di|."""
    # the walk is about span^3 steps: 1,001 cells (50 m at 0.05 m) is past any local map
    span = check_count(span, "visibility_reference: span", 1, 1001)
    if not isinstance(grid, OccupancyGrid):
        raise ValueError(f"visibility_reference: grid must be an OccupancyGrid, got {grid!r}")
    cx, cy = (int(v) for v in cell)
    half = span // 2
    occupied = np.zeros((span, span), dtype=bool)
    x0, y0 = cx - half, cy - half
    xs0, ys0 = max(x0, 0), max(y0, 0)
    xs1, ys1 = min(x0 + span, grid.width), min(y0 + span, grid.height)
    if xs1 > xs0 and ys1 > ys0:
        cells = grid.cells[ys0:ys1, xs0:xs1]
        occupied[ys0 - y0 : ys1 - y0, xs0 - x0 : xs1 - x0] = cells >= occupied_threshold
    seen = np.zeros((span, span), dtype=np.int8)
    seen[half, half] = 1
    if occupied[half, half]:
        return seen
    border = [
        (di, dj)
        for dj in range(-half, half + 1)
        for di in range(-half, half + 1)
        if max(abs(di), abs(dj)) == half
    ]
    for di, dj in border:
        ai, aj = abs(di), abs(dj)
        sx, sy = (1 if di > 0 else -1), (1 if dj > 0 else -1)
        crossings = sorted(
            [((2 * m + 1) * max(aj, 1), "column") for m in range(ai)]
            + [((2 * n + 1) * max(ai, 1), "row") for n in range(aj)]
        )
        i = j = half
        for _, group in groupby(crossings, key=lambda c: c[0]):
            kinds = {kind for _, kind in group}
            if kinds == {"column", "row"}:  # through a corner
                sides = ((j, i + sx), (j + sy, i))
                for side in sides:
                    seen[side] = 1
                if all(occupied[side] for side in sides):
                    break
                i, j = i + sx, j + sy
            elif kinds == {"column"}:
                i += sx
            else:
                j += sy
            seen[j, i] = 1
            if occupied[j, i]:
                break
    return seen


def counts_reference(
    model: SpaceObservationModel, grid: OccupancyGrid, pose, occlusion_aware: bool = False
) -> tuple:
    """(penetrating, map_occupied, intruding, map_free) for one particle, in plain numpy: the
    local map rotated to the particle's heading bin (``model.rotated_local_map``) laid over the
    map at the particle's cell; occlusion-aware, free map cells the particle's cell cannot see
    (``visibility_reference``) count as occupied."""
    x, y, theta = (float(v) for v in pose)
    local = model.rotated_local_map(model.bin_of(theta)).cells
    span = local.shape[0]
    # the window cell: the one whose lower-left corner is the grid corner nearest the particle
    cx, cy = grid.world_to_cell(np.array([[x, y]]) + 0.5 * grid.resolution)[0]
    x0, y0 = cx - span // 2, cy - span // 2
    window = np.full((span, span), -1, dtype=np.int8)
    xs0, ys0 = max(x0, 0), max(y0, 0)
    xs1, ys1 = min(x0 + span, grid.width), min(y0 + span, grid.height)
    if xs1 > xs0 and ys1 > ys0:
        window[ys0 - y0 : ys1 - y0, xs0 - x0 : xs1 - x0] = grid.cells[ys0:ys1, xs0:xs1]
    view = local >= 0
    occupied, free = window >= 65, (window >= 0) & (window <= 19)
    if occlusion_aware:
        hidden = free & (visibility_reference(grid, (cx, cy), span) == 0)
        occupied, free = occupied | hidden, free & ~hidden
    m_occ = occupied & view
    m_free = free & view
    return (
        int(np.count_nonzero((local == 0) & m_occ)),
        int(m_occ.sum()),
        int(np.count_nonzero((local == 100) & m_free)),
        int(m_free.sum()),
    )


def likelihood_reference(
    model: SpaceObservationModel,
    grid: OccupancyGrid,
    poses: np.ndarray,
    sigma_penetration: float = 10.0,
    sigma_intrusion: float = 130.0,
) -> np.ndarray:
    """The same formula in plain numpy, particle by particle (see counts_reference)."""
    out = np.empty(len(poses))
    for k, pose in enumerate(np.asarray(poses, dtype=float)):
        pen, m_occ, intr, m_free = counts_reference(model, grid, pose)
        pen_ratio = 100.0 * pen / m_occ if m_occ else 0.0
        intr_ratio = 100.0 * intr / m_free if m_free else 0.0
        out[k] = np.exp(
            -0.5 * ((pen_ratio / sigma_penetration) ** 2 + (intr_ratio / sigma_intrusion) ** 2)
        )
    return out
