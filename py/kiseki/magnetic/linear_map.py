# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The linear magnetic map of the magnetic-navigation thesis (``002_74cea16d239c028f.txt``,
sec. 3.2.2, 3.3.2 and Table 4.1): the field recorded along a taught path as a list of nodes
indexed by travel distance, "without loops, as a linear list".

Each node k stands for travel distance ``s_k = (k0 + k) * spacing`` (spacing 0.1 m, "the
recording interval is 10 cm; several readings within 10 cm are averaged", sec. 3.3.2): the
samples whose travel distance rounds to it (``floor(s / spacing + 0.5)``) are averaged, giving

* ``field``: (mx, my, mz) in G in the sensor frame (x forward, y right, z down, sec. 3.3.1);
* ``m_theta``: the azimuth of the horizontal field in the sensor frame,
  ``m_theta = atan2(m_y, m_x)`` (sec. 2.5, "the azimuth in the plane parallel to the ground";
  with it the place-only azimuth is ``theta_m = theta - m_theta``, eq. 4.12);
* ``heading``: the robot's heading theta when it passed the node (Table 4.1);
* ``g = (g_l, g_r)``: the geometric features of sec. 4.3.2 (Fig. 4.2), see
  :func:`geometric_features`; NaN where no obstacle was in the window ("not used");
* ``count``: how many samples the node averages; 0 marks a node that no sample reached (the
  robot moved more than 0.1 m between two readings), whose values are interpolated linearly in
  s between its neighbours;
* ``position``: the mean reference position (x, y) of the node's samples (ground truth in a
  simulation), for evaluation only; NaN when unknown.

Angles (m_theta, heading) are averaged and interpolated as unit vectors. The travel distance
and heading are the teaching run's odometry, as the thesis does ("the travel distance and the
heading are the odometry's estimates, used as they are", sec. 4.3.1): playback compares its own
odometry with them. ``path_id`` names the path the map belongs to (:func:`path_identity`).
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np

from kiseki._support.real_arrays import real_array
from kiseki._support.real_numbers import check_number

__all__ = [
    "MAX_NODES",
    "NODE_SPACING",
    "WINDOW_ANGLE",
    "WINDOW_RANGE",
    "LinearMagneticMap",
    "NodeValues",
    "build_linear_map",
    "geometric_features",
    "path_identity",
]

NODE_SPACING = 0.1
"""m between nodes (thesis sec. 3.3.2)."""
WINDOW_RANGE = 10.0
"""m: reach r of the left and right laser windows. The thesis (sec. 4.3.2, Fig. 4.2) names a
range r and an angle alpha without values; 10 m covers the walls of a path 2-8 m wide."""
WINDOW_ANGLE = math.radians(60.0)
"""rad: full width alpha of each window, centred on +90 deg (left) and -90 deg (right) of the
laser's x axis; our choice (the thesis gives no value)."""

MAX_NODES = 10_000_000
"""Nodes of one map: 1,000 km at 0.1 m, about 0.9 GB (11 numbers a node); the file format's too."""

_SHA1_HEX = 40


def path_identity(points: Any) -> str:
    """SHA-1 (40 hex digits) naming a path by its (n, 2) points in metres: the taught route's
    waypoints (a scene's ``route.waypoints``) or a walk's node positions. The points are
    rounded to whole millimetres and hashed as little-endian int64 with their count, so the
    same route read from YAML or from numbers gives the same identity."""
    p = np.asarray(points, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 2 or p.shape[0] < 1:
        raise ValueError(f"path_identity: expected (n, 2) points with n >= 1, got {p.shape}")
    if not np.all(np.isfinite(p)):
        raise ValueError("path_identity: the points hold NaN or infinity")
    if not np.all(np.abs(p) <= 1e9):  # in mm past int64 (1e17 and 2e17 m had one identity)
        raise ValueError("path_identity: the points lie beyond +-1e9 m")
    mm = np.rint(p * 1000.0).astype("<i8")
    digest = hashlib.sha1(usedforsecurity=False)
    digest.update(np.int64(len(mm)).astype("<i8").tobytes())
    digest.update(mm.tobytes())
    return digest.hexdigest()


def geometric_features(
    ranges: Any,
    angles: Any,
    max_range: float,
    window_range: float = WINDOW_RANGE,
    window_angle: float = WINDOW_ANGLE,
) -> np.ndarray:
    """(g_l, g_r) per scan (thesis sec. 4.3.2): the smallest perpendicular distance
    ``range * |sin(angle)|`` to the laser's x axis of the returns in the left window (beam
    angles within ``window_angle / 2`` of +90 deg, counter-clockwise) and the right window
    (around -90 deg) no farther than ``window_range``. Readings >= ``max_range``, zero or
    non-finite are no return. NaN where a window holds no return. ``ranges`` (N, B) or (B,),
    ``angles`` (B,) rad; returns (N, 2) (or (2,))."""
    r = np.asarray(ranges, dtype=np.float64)
    single = r.ndim == 1
    r = r.reshape(1, -1) if single else r
    a = np.asarray(angles, dtype=np.float64)
    if r.ndim != 2 or a.ndim != 1 or r.shape[1] != a.shape[0]:
        raise ValueError(f"geometric_features: ranges {r.shape} do not match angles {a.shape}")
    if a.size == 0:  # NaN features, as if the windows had seen no return
        raise ValueError("geometric_features: the scan has no beams")
    if not np.all(np.isfinite(a)):
        raise ValueError("geometric_features: the beam angles hold NaN or infinity")
    for name, value in (("max_range", max_range), ("window_range", window_range)):
        check_number(value, f"geometric_features: {name}", 0.0, low_open=True, unit="m")
    check_number(
        window_angle, "geometric_features: window_angle", 0.0, math.pi, low_open=True, unit="rad"
    )
    wrapped = np.angle(np.exp(1j * a))
    half = window_angle / 2
    with np.errstate(invalid="ignore"):
        hit = np.isfinite(r) & (r > 0) & (r < max_range) & (r <= window_range)
    lateral = np.where(hit, np.abs(r * np.sin(wrapped)), np.inf)
    out = np.empty((r.shape[0], 2))
    for col, centre in enumerate((math.pi / 2, -math.pi / 2)):
        inside = np.abs(wrapped - centre) <= half + 1e-12
        best = lateral[:, inside].min(axis=1) if inside.any() else np.full(r.shape[0], np.inf)
        out[:, col] = np.where(np.isfinite(best), best, np.nan)
    return out[0] if single else out


class NodeValues(NamedTuple):
    """The map's values at some travel distances (see :meth:`LinearMagneticMap.at`)."""

    field: np.ndarray  # (k, 3) G
    m_theta: np.ndarray  # (k,) rad
    heading: np.ndarray  # (k,) rad
    g: np.ndarray  # (k, 2) m, NaN: no obstacle


@dataclass(frozen=True, eq=False)
class LinearMagneticMap:
    """Nodes every ``spacing`` m of travel (see the module text). Build with
    :func:`build_linear_map`; save and load with :mod:`kiseki.magnetic.linear_map_folder`."""

    spacing: float
    path_id: str
    s: np.ndarray  # (n,) m
    field: np.ndarray  # (n, 3) G, sensor frame
    m_theta: np.ndarray  # (n,) rad
    heading: np.ndarray  # (n,) rad
    g: np.ndarray  # (n, 2) m
    count: np.ndarray  # (n,) samples averaged; 0 = interpolated
    position: np.ndarray  # (n, 2) m, NaN = unknown
    window: tuple[float, float] = (WINDOW_RANGE, WINDOW_ANGLE)  # (r m, alpha rad) of g
    provenance: Mapping[str, str] = field(default_factory=dict)

    def __len__(self) -> int:
        return int(self.s.shape[0])

    def _distances(self, s: Any) -> np.ndarray:
        q = np.asarray(s, dtype=np.float64)
        if not np.all(np.isfinite(q)):
            raise ValueError("linear magnetic map: the travel distances asked hold NaN")
        return q

    def index(self, s: Any) -> np.ndarray | int:
        """The nearest node's index for travel distance(s) s, clamped to the map's ends."""
        q = self._distances(s)
        # clamped before the cast: 1e20 m cast to int64 wrapped to a negative index, node 0
        u = np.clip((q - self.s[0]) / self.spacing + 0.5, 0.0, len(self) - 1.0)
        k = np.floor(u).astype(np.int64)
        return int(k) if k.ndim == 0 else k

    def at(self, s: Any) -> NodeValues:
        """The values at travel distance(s) s, linear between nodes (angles as unit vectors),
        the end node's values beyond the ends; g is NaN next to a node without obstacle."""
        q = np.atleast_1d(self._distances(s))
        u = np.clip((q - self.s[0]) / self.spacing, 0.0, len(self) - 1.0)
        k = np.minimum(np.floor(u).astype(np.int64), len(self) - 1)
        k1 = np.minimum(k + 1, len(self) - 1)
        f = (u - k)[:, None]

        def lerp(a: np.ndarray) -> np.ndarray:
            a2 = a.reshape(len(self), -1)
            return (a2[k] * (1 - f) + a2[k1] * f).reshape((len(q), *a.shape[1:]))

        def angle(a: np.ndarray) -> np.ndarray:
            return np.arctan2(lerp(np.sin(a)), lerp(np.cos(a)))

        return NodeValues(lerp(self.field), angle(self.m_theta), angle(self.heading), lerp(self.g))


def _array(value: Any, name: str, shape: tuple, allow_nan: bool = False) -> np.ndarray:
    a = np.asarray(real_array(value, f"linear magnetic map: {name}"), dtype=np.float64)
    pairs = zip(a.shape, shape, strict=False)
    if a.ndim != len(shape) or any(e is not None and e != n for n, e in pairs):
        want = tuple("n" if e is None else e for e in shape)
        raise ValueError(f"linear magnetic map: {name} has shape {a.shape}, expected {want}")
    bad = np.isinf(a) if allow_nan else ~np.isfinite(a)
    if bad.any():
        i = int(np.argwhere(bad)[0][0])
        what = "infinity" if allow_nan else "NaN or infinity"
        raise ValueError(f"linear magnetic map: {name}[{i}] holds {what}")
    return a


def _fill_empty(values: np.ndarray, count: np.ndarray) -> np.ndarray:
    """Linear interpolation in node index of the rows of nodes without samples."""
    full = count > 0
    if full.all():
        return values
    x = np.arange(len(count))
    v2 = values.reshape(len(count), -1).copy()
    for c in range(v2.shape[1]):
        v2[~full, c] = np.interp(x[~full], x[full], v2[full, c])
    return v2.reshape(values.shape)


def build_linear_map(
    s: Any,
    readings: Any,
    heading: Any,
    *,
    path_id: str,
    g: Any = None,
    position: Any = None,
    spacing: float = NODE_SPACING,
    tolerance: float = 1e-6,
    window: tuple[float, float] = (WINDOW_RANGE, WINDOW_ANGLE),
    provenance: Mapping[str, str] | None = None,
) -> LinearMagneticMap:
    """The map of a teaching run's n samples: travel distance ``s`` (n,) m, non-decreasing (a
    step back of more than ``tolerance`` m is refused), magnetometer ``readings`` (n, 3) G in
    the sensor frame, odometry ``heading`` (n,) rad, optional geometric features ``g`` (n, 2)
    (NaN: no obstacle) and reference ``position`` (n, 2). ``path_id``: 40 hex digits
    (:func:`path_identity`). ValueError names the first bad sample."""
    spacing = check_number(spacing, "linear magnetic map: spacing", 0.0, low_open=True, unit="m")
    check_number(tolerance, "linear magnetic map: tolerance", 0.0, unit="m")
    try:  # a float was "'float' object is not subscriptable", (-1, 0) taken
        reach, width = (float(v) for v in window)
    except (TypeError, ValueError):
        reach = width = math.nan
    if not (0 < reach < math.inf and 0 < width <= math.pi):
        raise ValueError(
            "linear magnetic map: window must be (range m > 0, full angle in (0, pi] rad), as "
            f"geometric_features takes it, got {window!r}"
        )
    if not (isinstance(path_id, str) and len(path_id) == _SHA1_HEX):
        raise ValueError(f"linear magnetic map: path_id must be 40 hex digits, got {path_id!r}")
    if any(ch not in "0123456789abcdef" for ch in path_id):
        raise ValueError(f"linear magnetic map: path_id must be 40 hex digits, got {path_id!r}")
    s = _array(s, "s", (None,))
    n = s.shape[0]
    if n == 0:
        raise ValueError("linear magnetic map: no samples (an empty teaching run)")
    m = _array(readings, "readings", (n, 3))
    th = _array(heading, "heading", (n,))
    gg = np.full((n, 2), np.nan) if g is None else _array(g, "g", (n, 2), allow_nan=True)
    pos = (
        np.full((n, 2), np.nan) if position is None else _array(position, "position", (n, 2), True)
    )
    step = np.diff(s)
    if n > 1 and step.min() < -tolerance:
        i = int(np.argmin(step)) + 1
        raise ValueError(
            f"linear magnetic map: s is not monotonic: s[{i}] = {s[i]:.6g} m is"
            f" {-step[i - 1]:.3g} m before s[{i - 1}] (tolerance {tolerance} m)"
        )
    # counted in floats first: s of 1e300 m overflowed the int64 node indices (numpy's
    # "'list' argument must have no negative elements")
    span = np.floor(s.max() / spacing + 0.5) - np.floor(s.min() / spacing + 0.5)
    if not span < MAX_NODES:
        raise ValueError(
            f"linear magnetic map: {span + 1:.10g} nodes is over the limit of {MAX_NODES:,}"
        )
    idx = np.floor(s / spacing + 0.5).astype(np.int64)
    k0 = int(idx.min())
    bins = idx - k0
    nodes = int(bins.max()) + 1
    count = np.bincount(bins, minlength=nodes)
    seen = np.maximum(count, 1)

    def mean(v: np.ndarray) -> np.ndarray:
        return np.bincount(bins, weights=v, minlength=nodes) / seen

    def nan_mean(v: np.ndarray) -> np.ndarray:
        ok = np.isfinite(v)
        k = np.bincount(bins[ok], minlength=nodes)
        total = np.bincount(bins[ok], weights=v[ok], minlength=nodes)
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(k > 0, total / np.maximum(k, 1), np.nan)

    field_mean = np.column_stack([mean(m[:, c]) for c in range(3)])
    m_theta = np.arctan2(m[:, 1], m[:, 0])  # thesis sec. 2.5 / eq. 4.12
    units = {
        "mt": np.column_stack([mean(np.cos(m_theta)), mean(np.sin(m_theta))]),
        "th": np.column_stack([mean(np.cos(th)), mean(np.sin(th))]),
    }
    field_mean = _fill_empty(field_mean, count)
    units = {k: _fill_empty(v, count) for k, v in units.items()}
    g_mean = _fill_empty(np.column_stack([nan_mean(gg[:, c]) for c in range(2)]), count)
    p_mean = _fill_empty(np.column_stack([nan_mean(pos[:, c]) for c in range(2)]), count)
    return LinearMagneticMap(
        spacing=float(spacing),
        path_id=path_id,
        s=(k0 + np.arange(nodes)) * float(spacing),
        field=field_mean,
        m_theta=np.arctan2(units["mt"][:, 1], units["mt"][:, 0]),
        heading=np.arctan2(units["th"][:, 1], units["th"][:, 0]),
        g=g_mean,
        count=count.astype(np.int64),
        position=p_mean,
        window=(reach, width),
        provenance=dict(provenance or {}),
    )
