# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Unknown obstacles added to a recorded log: the readings a laser would have returned had
objects that are not on the map stood in the world while the log was recorded.

This is how kiseki measures, on real data, what the teaching-and-playback thesis' space
observation model exists for (sec. 3.3: obstacles absent from the taught map must not make the
robot lost). The obstacles are static, in the world frame: discs (people-sized blobs) and
rectangles (boxes, carts) at any heading. A beam from the laser's pose at angle ``a`` is the ray
``p + t u``, ``u = (cos(theta + a), sin(theta + a))``; its new reading is the smaller of the
recorded one and the nearest ``t > 0`` at which it meets an obstacle:

* disc of centre ``c`` and radius ``r``: with ``d = c - p``, ``b = u . d`` and
  ``q = |d|^2 - r^2``, the ray enters at ``t = b - sqrt(b^2 - q)`` when ``b^2 >= q``;
* rectangle of centre ``c``, half sizes ``(h_x, h_y)`` and heading ``phi``: in its frame the ray
  is ``p' + t u'``; the slab method (Kay and Kajiya, SIGGRAPH 1986) gives the entry
  ``t = max over axes of min((+-h - p'_k) / u'_k)`` when it is below the exit.

A reading that was a no return (at ``max_range``) becomes a hit when an obstacle is nearer; an
invalid reading (NaN) stays invalid: why the sensor measured nothing is not known. The laser
must lie outside every obstacle (a log whose robot drove through one is refused), since a real
laser inside a box would see nothing of the world.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from kiseki.scans import LaserScans

__all__ = ["UnknownObstacles", "occlude_scans"]


@dataclass(frozen=True, eq=False)
class UnknownObstacles:
    """Static obstacles in the world frame: discs and rectangles (arrays may be empty)."""

    disc_centres: np.ndarray  # (D, 2) m
    disc_radii: np.ndarray  # (D,) m, > 0
    box_centres: np.ndarray  # (R, 2) m
    box_half_sizes: np.ndarray  # (R, 2) m, > 0 (half length along the box's x, half width)
    box_headings: np.ndarray  # (R,) rad

    def __post_init__(self) -> None:
        fields = {
            "disc_centres": (np.asarray(self.disc_centres, dtype=float).reshape(-1, 2)),
            "disc_radii": np.asarray(self.disc_radii, dtype=float).reshape(-1),
            "box_centres": np.asarray(self.box_centres, dtype=float).reshape(-1, 2),
            "box_half_sizes": np.asarray(self.box_half_sizes, dtype=float).reshape(-1, 2),
            "box_headings": np.asarray(self.box_headings, dtype=float).reshape(-1),
        }
        for name, value in fields.items():
            if not np.isfinite(value).all():
                raise ValueError(f"unknown obstacles: {name} must be finite")
            object.__setattr__(self, name, value)
        if len(fields["disc_radii"]) != len(fields["disc_centres"]):
            raise ValueError("unknown obstacles: one radius per disc centre is needed")
        if not (
            len(fields["box_half_sizes"])
            == len(fields["box_headings"])
            == len(fields["box_centres"])
        ):
            raise ValueError(
                "unknown obstacles: one half size and one heading per box centre are needed"
            )
        if (fields["disc_radii"] <= 0).any() or (fields["box_half_sizes"] <= 0).any():
            raise ValueError("unknown obstacles: radii and half sizes must be positive")

    @classmethod
    def none(cls) -> UnknownObstacles:
        return cls(np.zeros((0, 2)), np.zeros(0), np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0))

    def __len__(self) -> int:
        return len(self.disc_radii) + len(self.box_headings)

    def reach(self) -> np.ndarray:
        """(centres (K, 2), bounding radii (K,)) of every obstacle, discs first."""
        centres = np.vstack([self.disc_centres, self.box_centres])
        radii = np.concatenate([self.disc_radii, np.hypot(*self.box_half_sizes.T)])
        return centres, radii

    def contains(self, points: np.ndarray) -> np.ndarray:
        """(N,) bool: which of the points (N, 2) lie inside (or on) an obstacle."""
        p = np.asarray(points, dtype=float).reshape(-1, 2)
        inside = np.zeros(len(p), dtype=bool)
        for c, r in zip(self.disc_centres, self.disc_radii, strict=True):
            inside |= np.hypot(*(p - c).T) <= r
        for c, h, phi in zip(self.box_centres, self.box_half_sizes, self.box_headings, strict=True):
            local = (p - c) @ _rotation(phi)
            inside |= (np.abs(local[:, 0]) <= h[0]) & (np.abs(local[:, 1]) <= h[1])
        return inside


def _rotation(phi: float) -> np.ndarray:
    """Columns: the box's x and y axes in the world (so world @ R gives box coordinates)."""
    c, s = np.cos(phi), np.sin(phi)
    return np.array([[c, -s], [s, c]])


def _disc_hits(
    origin: np.ndarray, dirs: np.ndarray, centres: np.ndarray, radii: np.ndarray
) -> np.ndarray:
    """(B,) nearest entry distance of the rays origin + t dirs (B, 2) into the discs; inf: none."""
    if not len(radii):
        return np.full(len(dirs), np.inf)
    d = centres - origin  # (K, 2)
    b = dirs @ d.T  # (B, K)
    q = np.einsum("ij,ij->i", d, d) - radii**2  # (K,)
    disc = b * b - q
    with np.errstate(invalid="ignore"):
        t = b - np.sqrt(disc)
    t = np.where((disc >= 0) & (t > 0), t, np.inf)
    return t.min(axis=1)


def _box_hits(origin, dirs, centres, halves, headings) -> np.ndarray:
    """(B,) nearest entry distance of the rays into the rectangles (slab method); inf: none."""
    if not len(headings):
        return np.full(len(dirs), np.inf)
    c, s = np.cos(headings), np.sin(headings)  # (K,)
    rel = origin - centres  # (K, 2)
    px = rel[:, 0] * c + rel[:, 1] * s  # the origin in each box's frame
    py = -rel[:, 0] * s + rel[:, 1] * c
    ux = np.outer(dirs[:, 0], c) + np.outer(dirs[:, 1], s)  # (B, K)
    uy = -np.outer(dirs[:, 0], s) + np.outer(dirs[:, 1], c)
    with np.errstate(divide="ignore", invalid="ignore"):
        near, far = [], []
        for p, u, h in ((px, ux, halves[:, 0]), (py, uy, halves[:, 1])):
            t1, t2 = (-h - p) / u, (h - p) / u
            lo, hi = np.minimum(t1, t2), np.maximum(t1, t2)
            # a ray parallel to a slab: inside it for every t, or never
            parallel = u == 0
            inside = np.abs(p) <= h
            lo = np.where(parallel, np.where(inside, -np.inf, np.inf), lo)
            hi = np.where(parallel, np.where(inside, np.inf, -np.inf), hi)
            near.append(lo)
            far.append(hi)
    t_in = np.maximum(near[0], near[1])
    t_out = np.minimum(far[0], far[1])
    t = np.where((t_in <= t_out) & (t_in > 0), t_in, np.inf)
    return t.min(axis=1)


def occlude_scans(scans: LaserScans, obstacles: UnknownObstacles) -> tuple[LaserScans, float]:
    """The scans with every beam cut where it meets an obstacle (module docstring), and the
    share of the valid beams that were cut. The laser poses are the log's reference poses
    (``scans.poses``); a log without them, or whose laser lies inside an obstacle, is refused."""
    if not scans.has_reference_poses:
        raise ValueError("unknown obstacles: the log has no reference poses to place the laser")
    inside = obstacles.contains(scans.poses[:, :2])
    if inside.any():
        k = int(np.flatnonzero(inside)[0])
        raise ValueError(f"unknown obstacles: the laser of scan {k} lies inside an obstacle")
    ranges = np.array(scans.ranges, dtype=np.float32, copy=True)
    if not len(obstacles):
        return scans, 0.0
    centres, reach = obstacles.reach()
    nd = len(obstacles.disc_radii)
    cut = 0
    for k, (x, y, theta) in enumerate(scans.poses):
        origin = np.array([x, y])
        near = np.hypot(*(centres - origin).T) - reach < scans.max_range
        if not near.any():
            continue
        a = theta + scans.angles
        dirs = np.column_stack([np.cos(a), np.sin(a)])
        dn, bn = near[:nd], near[nd:]
        t = np.minimum(
            _disc_hits(origin, dirs, obstacles.disc_centres[dn], obstacles.disc_radii[dn]),
            _box_hits(
                origin,
                dirs,
                obstacles.box_centres[bn],
                obstacles.box_half_sizes[bn],
                obstacles.box_headings[bn],
            ),
        )
        row = ranges[k]
        hit = np.isfinite(row) & (t < row)
        row[hit] = t[hit].astype(np.float32)
        cut += int(hit.sum())
    valid = int(np.count_nonzero(np.isfinite(scans.ranges)))
    out = LaserScans(
        scans.times, scans.poses, scans.odometry, ranges, scans.angles, scans.max_range
    )
    return out, cut / valid if valid else 0.0
