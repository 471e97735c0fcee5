# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Trajectory metrics with evo's definitions (Grupp, evo, 2017): absolute pose error (APE),
relative pose error (RPE), trajectory alignment (Umeyama 1991), the stop-position error
of a route's goal, and the intervals and ROC area the experiments report shares and scores
with. A taught map's departure from the ground truth is :mod:`kiseki.teach.map_truth`'s.

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
from kiseki._support.moved import moved_names
from kiseki._support.real_arrays import real_array
from kiseki._support.real_numbers import check_number

__all__ = [
    "ErrorStatistics",
    "StopError",
    "align_trajectory",
    "ape",
    "area_under_roc",
    "as_se3",
    "rpe",
    "stop_error",
    "umeyama_alignment",
    "wilson_interval",
]

# moved by the split of the taught map's truth (answered for one release, with a warning)
__getattr__ = moved_names(
    __name__, dict.fromkeys(("MapTruth", "taught_map_truth"), "kiseki.teach.map_truth")
)

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
        """The statistics of ``errors``. ``sse`` is inf once the sum of squares passes the
        largest double (errors of about 1e154 and more); ``rmse`` and ``std`` stay finite for
        finite errors (computed on the errors scaled by the largest where the squares overflow,
        as they were computed before elsewhere); ``mean`` is inf when the sum of the errors
        passes the largest double."""
        e = np.asarray(errors, dtype=float)
        if e.size == 0:
            raise ValueError("no pose pairs to compute an error from")
        with np.errstate(over="ignore", invalid="ignore"):  # an error of inf: its std NaN
            squares = e**2
            rmse, std = float(np.sqrt(np.mean(squares))), float(e.std())
            if not (math.isfinite(rmse) and math.isfinite(std)) and np.isfinite(e).all():
                scale = float(np.abs(e).max())
                rmse = scale * float(np.sqrt(np.mean((e / scale) ** 2)))
                std = scale * float((e / scale).std())
            return cls(
                e,
                rmse,
                float(e.mean()),
                float(np.median(e)),
                std,
                float(e.min()),
                float(e.max()),
                float(np.sum(squares)),
            )


def as_se3(poses: np.ndarray) -> np.ndarray:
    """(n, 3) planar poses or (n, 4, 4) matrices -> (n, 4, 4) matrices (checked, finite)."""
    p = np.asarray(real_array(poses, "poses"), dtype=float)  # complex lost its imaginary part
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


def _lengths(rows: np.ndarray) -> np.ndarray:
    """Euclidean length of each row of ``rows`` (n, k), as np.linalg.norm gives it; where the
    squares overflow (components of about 1e154 and more), of the row scaled by its largest
    component, so that a finite row has a finite length unless the length itself passes the
    largest double (1e200 m was an error of inf m)."""
    with np.errstate(over="ignore"):
        out = np.linalg.norm(rows, axis=1)
        over = np.isinf(out) & np.isfinite(rows).all(axis=1)
        if over.any():
            big = rows[over]
            scale = np.abs(big).max(axis=1)
            out[over] = scale * np.linalg.norm(big / scale[:, None], axis=1)
    return out


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
        return _lengths(e[:, :3, 3])
    if relation == "full":  # the Frobenius norm: the length of the 16 entries
        return _lengths((e - np.eye(4)).reshape(len(e), 16))
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
        return ErrorStatistics.of(_lengths(e[:, :3, 3] - r[:, :3, 3]))
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


def wilson_interval(k: int, n: int, z: float = 1.96) -> tuple[float, float]:
    """The Wilson score interval of a share k/n (95 % with z = 1.96; E. B. Wilson, JASA 22,
    1927); (NaN, NaN) when n is 0."""
    counts = all(isinstance(v, numbers.Integral) and not isinstance(v, bool) for v in (k, n))
    if not (counts and 0 <= k <= n <= 2**53):
        raise ValueError(  # 5 of 3: "math domain error"; n = -3: an interval; 10**400: overflow
            f"wilson_interval: need counts 0 <= k <= n <= 2**53, got {k!r}, {n!r}"
        )
    check_number(z, "wilson_interval: z", 0.0, low_open=True)
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
