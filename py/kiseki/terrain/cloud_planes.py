# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Plane removal on a user's own 3-D cloud (``kiseki terrain planes CLOUD``; paper 003's item
"real geometry"): read a PCD file or a text file of ``x y z`` lines (optionally ``.bz2``), find
the planes and say which points they take.

* ``"pcl"`` (the design card's choice): PCL's normal-plane RANSAC of
  :mod:`kiseki.terrain.plane_removal` on the 3-D points. A cloud larger than ``max_points`` is
  fitted on a seeded random subset of that size (PCL's RANSAC costs about iterations x points
  per plane: office1.pcd's 254,456 points took 124 s, the 20,000 subset 9 s with the extension,
  on two loaded cores; ``min_inliers`` counts subset points). Every point of the full cloud
  then joins plane k when its nearest subset point is an inlier of plane k and it lies within
  ``distance`` of the plane, so a box on the floor stays (its nearest subset points are not
  floor inliers).
* ``"hough"`` (the paper's): lines per tilt scan need the cloud as one sensor saw it: an S-DEM
  of 1 deg cells over the whole sphere (theta -180..180, phi -90..90 deg, reach beyond the
  farthest point) centred on the sensor's origin. The origin is PCD's VIEWPOINT translation;
  a text file has none, so (0, 0, 0) is assumed; ``origin`` replaces either. For octomap's
  scan.dat the floor lies at z = -0.035 m, so (0, 0, 0) is on the floor, below the laser:
  Hough finds 11 lines and keeps 82 % from there, 50 lines and 58 % from (0, 0, 0.5).
  The S-DEM keeps the nearest point of a cell; a cloud point is removed when its cell's point was
  removed and it lies within the Hough inlier distance of the least-squares plane through the
  nearest points of that cell and its removed neighbours. Hough finds lines, not planes: no
  coefficients are given. The paper's parameters (a line needs 30 cells of 1 deg in one tilt
  scan) suit a wide laser sweep; a camera's cloud (about 57 x 43 deg) gives few such lines.
"""

from __future__ import annotations

import io
import math
import os
import struct
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from kiseki import _core
from kiseki._support.counts import check_count
from kiseki._support.inputs import GIB, MIB, check_input, describe_bytes, read_input
from kiseki._support.numbers_text import is_number, parse_float
from kiseki.core import check_seed
from kiseki.terrain.plane_removal import HoughParams, PclParams, remove_planes
from kiseki.terrain.sdem import sdem_from_points, sphere_grid

__all__ = [
    "CLOUD_METHODS",
    "MAX_PCD_BYTES",
    "MAX_TEXT_CLOUD_BYTES",
    "Cloud",
    "CloudPlanes",
    "cloud_planes",
    "parse_origin",
    "read_cloud",
]

CLOUD_METHODS = ("pcl", "hough")
MAX_PCD_BYTES = 1 * GIB
"""A PCD file, and the points of a binary_compressed one, hold at most this: 64 million points of
x y z rgb; reading takes about 3 times the points' size (office1.pcd: 4 MB of points, 12 MB)."""
MAX_TEXT_CLOUD_BYTES = 256 * MIB
"""A text cloud (after bunzip2) holds at most this: reading takes about 6 times the text's size
(the rubble scan ``scan.dat.bz2``: 2.3 MB of text, 14 MB)."""
MAX_POINTS = 20_000


@dataclass(frozen=True)
class Cloud:
    """Finite points (n, 3), the sensor's origin, how many non-finite points were dropped."""

    points: np.ndarray
    origin: np.ndarray
    dropped: int
    path: str


@dataclass(frozen=True)
class CloudPlanes:
    """label (n,): -1 kept, k >= 0 the plane (PCL) or 0 (Hough: no plane identity) that took the
    point; planes (k, 4) as a x + b y + c z + d = 0, unit normal; inliers (k,) in the full cloud;
    fitted: how many points the planes were fitted on."""

    label: np.ndarray
    planes: np.ndarray
    inliers: np.ndarray
    method: str
    fitted: int
    lines: int = 0
    extra: dict = field(default_factory=dict)

    @property
    def removed(self) -> np.ndarray:
        return self.label >= 0

    @property
    def kept_share(self) -> float:
        return float(np.mean(self.label < 0)) if len(self.label) else 0.0


def _pcd_viewpoint(path: Path) -> np.ndarray:
    """The VIEWPOINT translation of a PCD header, (0, 0, 0) when the header has none. Raises
    ValueError when it has one that is not seven finite numbers (tx ty tz qw qx qy qz), or
    whose translation lies beyond +-ORIGIN_LIMIT."""
    with open(path, "rb") as f:
        head = f.read(4096).split(b"\nDATA", 1)[0]
    for line in head.decode("latin-1").splitlines():
        words = line.split()
        if words and words[0] == "VIEWPOINT":
            try:
                values = np.array([parse_float(w) for w in words[1:]])
            except ValueError:
                values = np.array([])
            if len(values) != 7 or not np.all(np.isfinite(values)):
                raise ValueError(f"VIEWPOINT {' '.join(words[1:])!r} is not 7 finite numbers")
            if not np.all(np.abs(values[:3]) <= ORIGIN_LIMIT):  # as --origin: 1e300 overflows
                raise ValueError(
                    f"VIEWPOINT {' '.join(words[1:4])!r}: the sensor lies beyond "
                    f"+-{ORIGIN_LIMIT:g} m"
                )
            return values[:3]
    return np.zeros(3)


def _is_pcd(path: Path) -> bool:
    if path.suffix.lower() == ".pcd":
        return True
    with open(path, "rb") as f:
        start = f.read(64).lstrip()
    return start.startswith((b"# .PCD", b"VERSION", b"FIELDS"))


class _CloudError(ValueError):
    """A text cloud's read refused by :func:`kiseki._support.inputs.read_input`."""


def _check_pcd_size(path: Path) -> None:
    """A binary_compressed PCD states the size its points decompress to (the reader decompresses
    exactly that much or fails): refused past MAX_PCD_BYTES before it is read (ValueError)."""
    with open(path, "rb") as f:
        head = f.read(64 * 1024)
    for marker in (b"\nDATA binary_compressed\n", b"\nDATA binary_compressed\r\n"):
        at = head.find(marker)
        if at >= 0 and at + len(marker) + 8 <= len(head):
            _, size = struct.unpack_from("<II", head, at + len(marker))
            if size > MAX_PCD_BYTES:
                raise ValueError(
                    f"{path}: decompresses to more than {describe_bytes(MAX_PCD_BYTES)} "
                    "(kiseki's limit for PCD files)"
                )


def _read_text(path: Path) -> np.ndarray:
    unzip = "bz2" if path.suffix.lower() == ".bz2" else None
    rows: list[list[float]] = []
    try:
        data = read_input(path, "text clouds", MAX_TEXT_CLOUD_BYTES, _CloudError, unzip)
        text = data.decode("utf-8")
    except _CloudError as err:
        raise ValueError(f"CLOUD {err}") from None
    except (UnicodeDecodeError, OSError) as err:
        raise ValueError(
            f"CLOUD {path}: not a point cloud (neither a PCD file nor text of 'x y z' lines: {err})"
        ) from None
    if not any(w and not w.startswith("#") for w in map(str.strip, text.splitlines())):
        return np.zeros((0, 3))
    try:  # numpy's C parser first; the slow loop only to name a bad line
        table = np.loadtxt(io.StringIO(text), dtype=float, comments="#", ndmin=2)
        if table.shape[1] == 3:
            return table
    except ValueError:
        pass
    for number, line in enumerate(text.splitlines(), start=1):
        words = line.split()
        if not words or words[0].startswith("#"):
            continue
        bad = [w for w in words if not is_number(w)]
        if len(words) != 3 or bad:
            why = f" ({bad[0][:20]!r} is not a number)" if bad else ""
            raise ValueError(
                f"CLOUD {path} line {number}: expected three numbers 'x y z', "
                f"got {line.strip()[:60]!r}{why}"
            )
        rows.append([float(w) for w in words])
    return np.asarray(rows, dtype=float).reshape(-1, 3)


ORIGIN_LIMIT: float = _core.PCL_COORDINATE_LIMIT
"""m: the largest coordinate of a cloud's points and of its sensor (a sensor 1,000 km from its
cloud's frame is a typo; beyond it PCL's float search overflows)."""


def parse_origin(text: str) -> np.ndarray:
    """``"x,y,z"`` (metres) as a finite 3-vector within +-ORIGIN_LIMIT; ValueError otherwise
    (1e300 overflowed later into a message about the S-DEM's range, naming no option)."""
    try:
        origin = np.array([parse_float(v.strip()) for v in str(text).split(",")])
    except ValueError:
        origin = np.zeros(0)
    if origin.shape != (3,) or not np.all(np.abs(origin) <= ORIGIN_LIMIT):
        raise ValueError(
            f"--origin must be three numbers x,y,z within +-{ORIGIN_LIMIT:g} m, got {text!r}"
        )
    return origin


def read_cloud(path: str | os.PathLike, origin: str | None = None) -> Cloud:
    """A PCD file (ascii, binary or binary_compressed), or text of ``x y z`` lines (``#``
    comments and blank lines skipped; ``.bz2`` decompressed). ``origin`` ("x,y,z") replaces the
    sensor's origin (PCD's VIEWPOINT, else 0,0,0). Raises ValueError naming the file (and line)
    for a missing file, a file that is not a cloud, and a cloud with no finite point."""
    given = None if origin is None else parse_origin(origin)
    path = Path(path)
    try:
        check_input(path)
        pcd = path.is_file() and _is_pcd(path)
        if pcd:
            check_input(path, "PCD files", MAX_PCD_BYTES)
            _check_pcd_size(path)
    except ValueError as err:
        raise ValueError(f"CLOUD {err}") from None
    if not path.is_file():
        raise ValueError(f"CLOUD {path}: no such file")
    if pcd:
        try:
            points, _, _, dropped = _core.read_pcd(str(path))
        except (RuntimeError, ValueError) as err:
            raise ValueError(f"CLOUD {path}: not a readable PCD file ({err})") from None
        try:  # a VIEWPOINT that the given origin replaces is not read
            origin = _pcd_viewpoint(path) if given is None else given
        except ValueError as err:
            raise ValueError(f"CLOUD {path}: {err} (or give the origin)") from None
    else:
        raw = _read_text(path)
        finite = np.all(np.isfinite(raw), axis=1)
        points, dropped, origin = raw[finite], int(np.sum(~finite)), np.zeros(3)
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    if len(points) == 0:
        what = f"all {dropped} points are NaN or infinite" if dropped else "it holds no point"
        raise ValueError(f"CLOUD {path}: empty cloud ({what})")
    far = np.abs(points).max(axis=1) > ORIGIN_LIMIT
    if far.any():  # PCL holds points as float: its search aborted the process from 1e39 m
        k = int(np.argmax(far))
        raise ValueError(
            f"CLOUD {path}: point {k + 1} of the finite ones, {points[k].tolist()}, lies beyond "
            f"+-{ORIGIN_LIMIT:g} m"
        )
    return Cloud(points, origin if given is None else given, int(dropped), str(path))


def _pcl(points: np.ndarray, params: PclParams, seed: int, max_points: int) -> CloudPlanes:
    n = len(points)
    rng = np.random.default_rng(seed)
    subset = np.sort(rng.choice(n, max_points, replace=False)) if n > max_points else None
    fit = points if subset is None else points[subset]
    mask, planes, _ = _core.remove_planes_pcl(fit, params.core(), seed)
    sub_label = np.full(len(fit), -1)
    for k, plane in enumerate(planes):  # the planes' inliers, in the order PCL took them
        near = mask & (sub_label < 0) & (np.abs(fit @ plane[:3] + plane[3]) <= params.distance)
        sub_label[near] = k
    sub_label[mask & (sub_label < 0)] = _closest_plane(fit[mask & (sub_label < 0)], planes)
    if subset is None:
        label = sub_label
    else:
        from scipy.spatial import cKDTree  # here: scipy is slow to load, and rarely needed

        _, nearest = cKDTree(fit).query(points, k=1)
        label = sub_label[nearest]
        idx = np.flatnonzero(label >= 0)
        own = planes[label[idx]]
        dist = np.abs(np.einsum("ij,ij->i", points[idx], own[:, :3]) + own[:, 3])
        label[idx[dist > params.distance]] = -1
    inliers = np.bincount(label[label >= 0], minlength=len(planes))[: len(planes)]
    return CloudPlanes(label, np.asarray(planes).reshape(-1, 4), inliers, "pcl", len(fit))


def _closest_plane(points: np.ndarray, planes: np.ndarray) -> np.ndarray:
    if len(points) == 0:
        return np.zeros(0, dtype=int)
    dist = np.abs(points @ planes[:, :3].T + planes[:, 3])
    return np.argmin(dist, axis=1)


def _hough(points: np.ndarray, origin: np.ndarray, params: HoughParams) -> CloudPlanes:
    local = points - origin
    reach = float(np.max(np.linalg.norm(local, axis=1)))
    grid = sphere_grid((-180.0, 180.0), (-90.0, 90.0), 1.0, max(1.01 * reach + 0.01, 0.1))
    sdem = sdem_from_points(local, grid=grid)
    widest = int((np.asarray(sdem.ranges) > 0).sum(axis=1).max())  # cells of one tilt scan
    if widest < params.min_votes:  # no line can get its votes: nothing will be removed
        where = ", ".join(f"{v:g}" for v in origin)
        warnings.warn(
            f"seen from the origin ({where}), the cloud spans at most {widest} cells of one tilt "
            f"scan, fewer than the {params.min_votes} a Hough line needs: no plane can be found "
            "(is the origin the sensor's position?)",
            stacklevel=3,
        )
        # the Hough's result without its accumulators, which span the far points' range (1.7 km
        # of 3 cm bins took 39 s; 10 km was refused as 'rho_step is too small')
        result = remove_planes(sdem, "none")
    else:
        result = remove_planes(sdem, "hough", hough=params)
    x, y, z = local.T
    r = np.linalg.norm(local, axis=1)
    step = math.radians(grid.step_deg)
    row = np.floor((np.arctan2(z, x) - math.radians(grid.theta_min_deg)) / step + 0.5)
    col = np.floor((np.arctan2(y, np.hypot(x, z)) - math.radians(grid.phi_min_deg)) / step + 0.5)
    inside = (row >= 0) & (row < grid.rows) & (col >= 0) & (col < grid.cols) & (r > 0)
    cell = np.where(inside, row * grid.cols + col, 0).astype(np.int64)
    removed = result.removed.reshape(grid.rows, grid.cols)
    centre, normal, flat = _local_planes(local, r, cell, inside, removed)
    gone = inside & removed.reshape(-1)[cell] & flat[cell]
    dist = np.abs(np.einsum("ij,ij->i", local - centre[cell], normal[cell]))
    gone &= dist <= params.inlier_distance
    label = np.where(gone, 0, -1)
    extra = {"sdem_cells": int(sdem.valid_cells), "removed_cells": int(removed.sum())}
    return CloudPlanes(label, np.zeros((0, 4)), np.zeros(0, dtype=int), "hough",
                       int(sdem.valid_cells), lines=result.found, extra=extra)  # fmt: skip


def _local_planes(local, r, cell, inside, removed):
    """Per removed cell, the least-squares plane through the nearest points (the S-DEM's own)
    of it and its removed 8-neighbours: a cloud point of the cell is on the Hough's plane when
    it is within the inlier distance of it. flat: the cell has >= 3 such points not on a line."""
    rows, cols = removed.shape
    idx = np.flatnonzero(inside)
    order = idx[np.lexsort((r[idx], cell[idx]))]
    first = order[np.r_[True, cell[order][1:] != cell[order][:-1]]]
    flat_rep = np.full((rows * cols, 3), np.nan)
    flat_rep[cell[first]] = local[first]
    rep = np.full((rows + 2, cols + 2, 3), np.nan)  # padded: the border has no neighbours
    rep[1:-1, 1:-1] = flat_rep.reshape(rows, cols, 3)
    ok = np.zeros((rows + 2, cols + 2), dtype=bool)
    ok[1:-1, 1:-1] = removed & np.all(np.isfinite(rep[1:-1, 1:-1]), axis=2)
    nb = [(i, j) for i in (0, 1, 2) for j in (0, 1, 2)]
    stack = np.stack([rep[i : i + rows, j : j + cols] for i, j in nb], axis=2)
    use = np.stack([ok[i : i + rows, j : j + cols] for i, j in nb], axis=2)
    count = use.sum(axis=2)
    pts = np.where(use[..., None], stack, 0.0)
    centre = pts.sum(axis=2) / np.maximum(count, 1)[..., None]
    dev = np.where(use[..., None], stack - centre[:, :, None, :], 0.0)
    cov = np.einsum("rcki,rckj->rcij", dev, dev)
    values, vectors = np.linalg.eigh(cov)
    normal = vectors[..., :, 0]
    flat = (count >= 3) & (values[..., 1] > 1e-3 * np.maximum(values[..., 2], 1e-12))
    flat &= removed
    return centre.reshape(-1, 3), normal.reshape(-1, 3), flat.reshape(-1)


def cloud_planes(
    cloud: Cloud,
    method: str = "pcl",
    seed: int = 0,
    max_points: int = MAX_POINTS,
    pcl: PclParams | None = None,
    hough: HoughParams | None = None,
) -> CloudPlanes:
    """The planes of ``cloud`` by ``method`` ("pcl" or "hough", see the module). Raises
    ValueError for an unknown method, a bad seed or ``max_points`` < 100."""
    if method not in CLOUD_METHODS:
        raise ValueError(f"--method must be one of {CLOUD_METHODS}, got {method!r}")
    seed = check_seed(seed, "--seed")
    max_points = check_count(max_points, "--max-points", 100)
    if method == "pcl":
        return _pcl(cloud.points, pcl or PclParams(), seed, max_points)
    return _hough(cloud.points, cloud.origin, hough or HoughParams())
