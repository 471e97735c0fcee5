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
"""

from __future__ import annotations

import numpy as np

from kiseki._core import LocalMapBuilder, SpaceObservationModel
from kiseki.core import Pose2
from kiseki.grid import OccupancyGrid

__all__ = ["LocalMapBuilder", "SpaceObservationModel", "counts_reference", "likelihood_reference"]


def counts_reference(
    model: SpaceObservationModel, grid: OccupancyGrid, pose, occlusion_aware: bool = False
) -> tuple:
    """(penetrating, map_occupied, intruding, map_free) for one particle, in plain numpy: the
    local map rotated to the particle's heading bin (``model.rotated_local_map``) laid over the
    map at the particle's cell; occlusion-aware, free map cells the particle's cell cannot see
    (``model.visible_from``) count as occupied."""
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
        hidden = free & (model.visible_from(Pose2(x, y, theta)).cells == 0)
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
