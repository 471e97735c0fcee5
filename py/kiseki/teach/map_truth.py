# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""A taught map's departure from the ground truth of its height band (`taught_map_truth`): the
obstacles it erased and the open space it walled, over the cells the sensors could reach along
the route, with a one-cell shift forgiven and cell by cell. Split from :mod:`kiseki.metrics`
(the trajectory metrics), which answers its old names for one release."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["MapTruth", "taught_map_truth"]


@dataclass(frozen=True)
class MapTruth:
    """A taught map measured against the ground truth (`taught_map_truth`)."""

    # forgiving a one-cell shift: the taught cell and its 8 neighbours must all disagree
    erased_share: float  # obstacle cells in reach that the map marks free (with 8 neighbours)
    false_occupied_share: float  # visible free cells the map marks occupied (with 8 neighbours)
    obstacle_cells: int
    erased_cells: int
    visible_free_cells: int
    false_occupied_cells: int
    # cell by cell: the taught cell under the truth cell alone
    erased_share_cellwise: float  # obstacle cells in reach that the map marks free
    false_occupied_share_cellwise: float  # visible free cells the map marks occupied
    erased_cells_cellwise: int
    false_occupied_cells_cellwise: int

    def as_dict(self) -> dict:
        return {k: getattr(self, k) for k in self.__dataclass_fields__}


def _all_nine(mask: np.ndarray) -> np.ndarray:
    """True where a cell and its 8 neighbours are all True (False at the border)."""
    padded = np.pad(mask, 1, constant_values=False)
    out = np.ones_like(mask)
    h, w = mask.shape
    for dy in (0, 1, 2):
        for dx in (0, 1, 2):
            out &= padded[dy : dy + h, dx : dx + w]
    return out


def taught_map_truth(
    taught,
    truth,
    sensor_poses: np.ndarray,
    hfov,
    reach,
    min_range=0.0,
) -> MapTruth:
    """How far a taught map (free 0 / occupied 100 / unknown -1) departs from the truth grid
    of the same height band, over the cells the sensors could reach along the route.

    A truth cell is in reach when its centre lies within `reach` metres and +-hfov/2 of the
    heading of some sensor pose (n, 3: x, y, yaw in the world), at least `min_range` ahead of
    it along the heading (a depth camera measures nothing nearer than its minimum depth); it is
    visible when, besides, nothing occupied in the truth lies between that sensor and it (ray
    cast in the truth). `hfov`, `reach` and `min_range` are numbers or one value per pose
    (several sensors' poses measured together: a cell any of them reaches counts once).
    - erased share: of the truth's occupied cells in reach (seen or hidden), those that the
      taught map marks free together with all 8 neighbours of the taught cell under them;
    - false-occupied share: of the truth's free cells visible from the route, those that the
      taught map marks occupied together with all 8 neighbours.
    The 8 neighbours keep a one-cell shift (odometry, a thin leg beside a beam) from counting:
    what counts is free space where a wall is, or a wall where open space is. That forgiving
    measure also hides a wall one or two cells thick drawn into open space, so the same two
    shares are given cell by cell too (`*_cellwise`: the taught cell under the truth cell
    alone is free, or occupied).
    """
    poses = np.asarray(sensor_poses, dtype=np.float64)
    if poses.ndim != 2 or poses.shape[1] != 3 or len(poses) == 0 or not np.isfinite(poses).all():
        raise ValueError("sensor_poses: expected a non-empty finite (n, 3) array")
    n = len(poses)
    try:
        hfov, reach, min_range = (
            np.broadcast_to(np.asarray(v, dtype=np.float64), (n,)) for v in (hfov, reach, min_range)
        )
    except ValueError:
        raise ValueError("hfov, reach and min_range: a number or one value per pose") from None
    if not ((hfov > 0) & (hfov < 2 * np.pi)).all() or not (np.isfinite(reach) & (reach > 0)).all():
        raise ValueError("need 0 < hfov < 2 pi and a positive finite reach for every pose")
    if not (np.isfinite(min_range) & (min_range >= 0)).all():
        raise ValueError("min_range must be >= 0 and finite")
    cells = np.asarray(truth.cells)
    res = truth.resolution
    xs = truth.origin.x + (np.arange(truth.width) + 0.5) * res  # cell centres
    ys = truth.origin.y + (np.arange(truth.height) + 0.5) * res
    occupied, free = cells >= 65, cells == 0
    step = 0.25 * res / reach.max()  # rays a quarter cell apart at the farthest reach
    half = hfov.max() / 2
    angles = np.arange(-half, half + step, step)
    ranges = truth.cast_scans(poses, angles, max_range=float(reach.max() + res))
    in_reach = np.zeros(cells.shape, bool)
    visible = np.zeros(cells.shape, bool)
    for pose, beams, fov, far, near_limit in zip(
        poses, ranges, hfov, reach, min_range, strict=True
    ):
        # only the cells of the square around the sensor that holds its reach
        i0, i1 = np.searchsorted(xs, [pose[0] - far, pose[0] + far])
        j0, j1 = np.searchsorted(ys, [pose[1] - far, pose[1] + far])
        if i0 >= i1 or j0 >= j1:
            continue
        dx, dy = xs[None, i0:i1] - pose[0], ys[j0:j1, None] - pose[1]
        dist = np.hypot(dx, dy)
        bearing = (np.arctan2(dy, dx) - pose[2] + np.pi) % (2 * np.pi) - np.pi
        ahead = dist * np.cos(bearing)  # depth along the sensor's axis
        near = (dist <= far) & (np.abs(bearing) <= fov / 2) & (ahead >= near_limit)
        in_reach[j0:j1, i0:i1] |= near
        k = np.clip(np.rint((bearing[near] + half) / step).astype(int), 0, len(angles) - 1)
        window = visible[j0:j1, i0:i1]
        window[near] |= dist[near] < beams[k] - 0.5 * res
    taught_cells = np.asarray(taught.cells)
    ti = np.floor((xs - taught.origin.x) / taught.resolution).astype(int)[None, :]
    tj = np.floor((ys - taught.origin.y) / taught.resolution).astype(int)[:, None]
    ti, tj = np.broadcast_arrays(ti, tj)
    inside = (ti >= 0) & (ti < taught.width) & (tj >= 0) & (tj < taught.height)

    def under_truth(taught_mask: np.ndarray) -> np.ndarray:
        out = np.zeros(cells.shape, bool)  # cells outside the taught map: neither
        out[inside] = taught_mask[tj[inside], ti[inside]]
        return out

    taught_free, taught_occupied = taught_cells == 0, taught_cells >= 65
    obstacles = occupied & in_reach
    open_cells = free & visible
    n_obst, n_open = int(obstacles.sum()), int(open_cells.sum())
    counts = [
        int((obstacles & under_truth(_all_nine(taught_free))).sum()),
        int((open_cells & under_truth(_all_nine(taught_occupied))).sum()),
        int((obstacles & under_truth(taught_free)).sum()),
        int((open_cells & under_truth(taught_occupied)).sum()),
    ]
    erased, false_occ, erased_1, false_occ_1 = counts

    def share(k: int, n: int) -> float:
        return k / n if n else 0.0

    return MapTruth(
        share(erased, n_obst),
        share(false_occ, n_open),
        n_obst,
        erased,
        n_open,
        false_occ,
        share(erased_1, n_obst),
        share(false_occ_1, n_open),
        erased_1,
        false_occ_1,
    )
