# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Trajectory metrics with evo's definitions (Grupp, evo, 2017): absolute pose error (APE),
relative pose error (RPE), trajectory alignment (Umeyama 1991), the stop-position error
of a route's goal, and a taught map's departure from the ground truth (`taught_map_truth`).

Poses are (n, 3) planar rows (x, y, theta) or (n, 4, 4) homogeneous matrices; planar poses are
lifted to SE(3) with z = 0. Error statistics are those evo prints (rmse, mean, median, std with
ddof = 0, min, max, sse).
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

import numpy as np

from kiseki._support.counts import check_count

__all__ = [
    "ErrorStatistics",
    "MapTruth",
    "StopError",
    "align_trajectory",
    "ape",
    "area_under_roc",
    "as_se3",
    "rpe",
    "stop_error",
    "taught_map_truth",
    "umeyama_alignment",
    "wilson_interval",
]

RELATIONS = ("translation", "rotation_deg", "rotation_rad", "full")
ALIGNMENTS = ("none", "se3", "sim3", "scale", "origin")


@dataclass(frozen=True)
class ErrorStatistics:
    errors: np.ndarray
    rmse: float
    mean: float
    median: float
    std: float
    min: float
    max: float
    sse: float

    @classmethod
    def of(cls, errors: np.ndarray) -> ErrorStatistics:
        e = np.asarray(errors, dtype=float)
        if e.size == 0:
            raise ValueError("no pose pairs to compute an error from")
        return cls(
            e,
            float(np.sqrt(np.mean(e**2))),
            float(e.mean()),
            float(np.median(e)),
            float(e.std()),
            float(e.min()),
            float(e.max()),
            float(np.sum(e**2)),
        )


def as_se3(poses: np.ndarray) -> np.ndarray:
    """(n, 3) planar poses or (n, 4, 4) matrices -> (n, 4, 4) matrices (checked, finite)."""
    p = np.asarray(poses, dtype=float)
    if p.ndim == 2 and p.shape[1] == 3:
        out = np.tile(np.eye(4), (len(p), 1, 1))
        c, s = np.cos(p[:, 2]), np.sin(p[:, 2])
        out[:, 0, 0], out[:, 0, 1], out[:, 1, 0], out[:, 1, 1] = c, -s, s, c
        out[:, 0, 3], out[:, 1, 3] = p[:, 0], p[:, 1]
        if not np.isfinite(out).all():
            raise ValueError("poses contain NaN or infinite values")
        return out  # built here: rigid by construction
    if not (p.ndim == 3 and p.shape[1:] == (4, 4)):
        raise ValueError(f"poses must have shape (n, 3) or (n, 4, 4), got {p.shape}")
    if not np.isfinite(p).all():
        raise ValueError("poses contain NaN or infinite values")
    # rigid motions (all ones gave a rotation error of 180 deg), to 1e-2: poses written with 4
    # decimals, or chained in float32, are rotations too
    r = p[:, :3, :3]
    off = np.abs(np.einsum("nji,njk->nik", r, r) - np.eye(3)).max(axis=(1, 2))
    bad = (off > 1e-2) | (np.linalg.det(r) <= 0) | (np.abs(p[:, 3] - [0, 0, 0, 1]).max(axis=1) > 0)
    if bad.any():
        raise ValueError(
            f"pose {int(np.argmax(bad))} is not a rigid motion (a rotation, and a last row 0 0 0 1)"
        )
    return p


def _pair(est, ref) -> tuple[np.ndarray, np.ndarray]:
    e, r = as_se3(est), as_se3(ref)
    if len(e) != len(r):
        raise ValueError(f"estimate has {len(e)} poses, reference {len(r)}: associate them first")
    if len(e) == 0:
        raise ValueError("empty trajectories")
    return e, r


def _inv(t: np.ndarray) -> np.ndarray:
    out = np.zeros_like(t)
    rt = np.swapaxes(t[..., :3, :3], -1, -2)
    out[..., :3, :3] = rt
    out[..., :3, 3] = -np.einsum("...ij,...j->...i", rt, t[..., :3, 3])
    out[..., 3, 3] = 1.0
    return out


def umeyama_alignment(src: np.ndarray, dst: np.ndarray, with_scale: bool = False):
    """Least-squares (R, t, s) with dst ~ s R src + t (Umeyama 1991); src, dst are (n, d)."""
    src, dst = np.asarray(src, dtype=float), np.asarray(dst, dtype=float)  # lists were refused
    if src.shape != dst.shape or src.ndim != 2 or len(src) < 2 or not np.isfinite(src + dst).all():
        raise ValueError("alignment needs two finite (n, d) point sets of the same shape, n >= 2")
    mu_s, mu_d = src.mean(axis=0), dst.mean(axis=0)
    xs, xd = src - mu_s, dst - mu_d
    cov = xd.T @ xs / len(src)
    u, d, vt = np.linalg.svd(cov)
    sign = np.eye(src.shape[1])
    if np.linalg.det(u) * np.linalg.det(vt) < 0:
        sign[-1, -1] = -1
    rot = u @ sign @ vt
    var = np.mean(np.sum(xs**2, axis=1))
    if with_scale and not var > 0:  # the scale was NaN (or inf): every error NaN
        raise ValueError(
            "the estimate's positions (src) are all the same: no scale can be estimated"
        )
    scale = float(np.trace(np.diag(d) @ sign) / var) if with_scale else 1.0
    return rot, mu_d - scale * rot @ mu_s, scale


def align_trajectory(est, ref, alignment: str = "se3") -> np.ndarray:
    """The estimate moved onto the reference: 'se3' (rotation + translation), 'sim3' (and
    scale), 'scale' (scale only), 'origin' (first poses made equal) or 'none'."""
    if alignment not in ALIGNMENTS:
        raise ValueError(f"alignment must be one of {', '.join(ALIGNMENTS)}, got {alignment!r}")
    e, r = _pair(est, ref)
    if alignment == "none":
        return e
    if alignment == "origin":
        return (r[0] @ _inv(e[0]))[None] @ e
    rot, t, s = umeyama_alignment(e[:, :3, 3], r[:, :3, 3], with_scale=alignment != "se3")
    out = e.copy()
    if alignment == "scale":
        out[:, :3, 3] *= s
        return out
    out[:, :3, 3] *= s
    transform = np.eye(4)
    transform[:3, :3], transform[:3, 3] = rot, t
    return transform[None] @ out


def _errors(e: np.ndarray, relation: str) -> np.ndarray:
    if relation == "translation":
        return np.linalg.norm(e[:, :3, 3], axis=1)
    if relation == "full":
        return np.linalg.norm(e - np.eye(4), axis=(1, 2))
    rot = e[:, :3, :3]
    # angle = atan2(sin, cos) from the skew part and the trace: accurate near 0 and pi
    skew = np.stack(
        [rot[:, 2, 1] - rot[:, 1, 2], rot[:, 0, 2] - rot[:, 2, 0], rot[:, 1, 0] - rot[:, 0, 1]],
        axis=1,
    )
    cos = (np.trace(rot, axis1=1, axis2=2) - 1.0) / 2.0
    angle = np.arctan2(np.linalg.norm(skew, axis=1) / 2.0, cos)
    return np.degrees(angle) if relation == "rotation_deg" else angle


def ape(est, ref, relation: str = "translation", alignment: str = "none") -> ErrorStatistics:
    """Absolute pose error: per pose E_i = ref_i^-1 est_i (after alignment)."""
    if relation not in RELATIONS:
        raise ValueError(f"relation must be one of {', '.join(RELATIONS)}, got {relation!r}")
    e = align_trajectory(est, ref, alignment)
    r = as_se3(ref)
    if relation == "translation":  # evo: the difference of the positions
        return ErrorStatistics.of(np.linalg.norm(e[:, :3, 3] - r[:, :3, 3], axis=1))
    return ErrorStatistics.of(_errors(_inv(r) @ e, relation))


def rpe(
    est, ref, delta: int = 1, relation: str = "translation", all_pairs: bool = False
) -> ErrorStatistics:
    """Relative pose error over pose pairs `delta` frames apart: E = (ref_i^-1 ref_j)^-1
    (est_i^-1 est_j). Without all_pairs the pairs do not overlap (evo's default)."""
    if relation not in RELATIONS:
        raise ValueError(f"relation must be one of {', '.join(RELATIONS)}, got {relation!r}")
    delta = check_count(delta, "delta", 1, note="frames")
    e, r = _pair(est, ref)
    n = len(e)
    if all_pairs:
        i = np.arange(0, n - delta)
        j = i + delta
    else:
        ids = np.arange(0, n, delta)
        i, j = ids[:-1], ids[1:]
    rel_ref = _inv(r[i]) @ r[j]
    rel_est = _inv(e[i]) @ e[j]
    return ErrorStatistics.of(_errors(_inv(rel_ref) @ rel_est, relation))


@dataclass(frozen=True)
class StopError:
    """Where a robot stopped relative to its goal, in the goal's frame."""

    along: float  # metres along the goal heading (positive: overshoot)
    across: float  # metres to the left of the goal heading
    distance: float
    heading_deg: float

    def within(self, tolerance: float = 0.1) -> bool:
        return self.distance <= tolerance


def stop_error(stop, goal) -> StopError:
    """Stop pose (x, y, theta) relative to the goal pose (x, y, theta)."""
    s, g = np.asarray(stop, dtype=float), np.asarray(goal, dtype=float)
    if s.shape != (3,) or g.shape != (3,) or not (np.isfinite(s).all() and np.isfinite(g).all()):
        raise ValueError("stop and goal must be finite (x, y, theta) triples")
    dx, dy = s[:2] - g[:2]
    c, si = np.cos(g[2]), np.sin(g[2])
    heading = np.degrees(np.arctan2(np.sin(s[2] - g[2]), np.cos(s[2] - g[2])))
    return StopError(c * dx + si * dy, -si * dx + c * dy, float(np.hypot(dx, dy)), float(heading))


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


def wilson_interval(k: int, n: int, z: float = 1.96) -> tuple[float, float]:
    """The Wilson score interval of a share k/n (95 % with z = 1.96; E. B. Wilson, JASA 22,
    1927); (NaN, NaN) when n is 0."""
    counts = all(isinstance(v, numbers.Integral) and not isinstance(v, bool) for v in (k, n))
    if not (counts and 0 <= k <= n <= 2**53 and isinstance(z, numbers.Real) and 0 < z < math.inf):
        raise ValueError(  # 5 of 3: "math domain error"; n = -3: an interval; 10**400: overflow
            f"wilson_interval: need counts 0 <= k <= n <= 2**53 and z > 0, got {k!r}, {n!r}, {z!r}"
        )
    if n == 0:
        return (math.nan, math.nan)
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return (max(0.0, centre - half), min(1.0, centre + half))


def area_under_roc(score, positive) -> float:
    """Area under the ROC curve of ``score`` for the boolean ``positive``: the probability that
    a positive scores above a negative, ties counted half (the Mann-Whitney U statistic over
    n_pos n_neg). NaN when either class is empty."""
    labels = np.asarray(positive)  # 'no' and 'yes' were both read as True
    if not (
        labels.dtype.kind == "b" or (labels.dtype.kind == "i" and np.isin(labels, (0, 1)).all())
    ):
        raise ValueError(
            f"area_under_roc: labels must be booleans (or 0 and 1), got {labels.dtype}"
        )
    score, positive = np.asarray(score, dtype=float), labels.astype(bool)
    if score.shape != positive.shape or not np.isfinite(score).all():
        raise ValueError("area_under_roc: need finite scores, one per label")
    pos, neg = np.sort(score[positive]), np.sort(score[~positive])
    if len(pos) == 0 or len(neg) == 0:
        return float("nan")
    below = np.searchsorted(neg, pos, side="left")
    ties = np.searchsorted(neg, pos, side="right") - below
    return float((below + 0.5 * ties).sum() / (len(pos) * len(neg)))
