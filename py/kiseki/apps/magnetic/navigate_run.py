# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Teaching and magnetic navigation on a simulated scene (thesis ``002_74cea16d239c028f.txt``,
ch. 3-4): the driver that wires the simulator (a data source) to the methods of
:mod:`kiseki.magnetic.rahok_navigation` and :mod:`kiseki.magnetic.navigators`.

* :func:`teach`: the route driven by hand (pure pursuit on the true pose, as a person drives the
  robot, sec. 3.3.2 / 4.3.1) on the scene's ``teach`` variant, and the linear map of it from the
  run's odometry and magnetometer (:func:`kiseki.magnetic.linear_map_from_run`). Rahok's
  identification vector needs the field of two paths parallel to the taught one ("the left and
  right field are also recorded by driving the robot by hand", sec. 3.3.2): kiseki drives the
  route shifted ``offset`` m to the left and to the right (1 m by default: the lines of Fig. 2.10
  at y = -1 and +1 m), each a teaching run of its own with its own odometry.
* :func:`navigate`: playback on the ``playback`` variant (the bicycle park moved, the road plate
  laid) steering with one method: ``rahok`` (ch. 3) or the ch. 4 navigators ``odometry``,
  ``geometric``, ``magnetic``, ``magnetic-geometric`` alone, or ``multi`` (all four by
  priority). ``travel`` chooses the travel-distance estimate: ``odometry`` (the odometry's path
  length; the default of the odometry-only baseline), ``peaks`` (corrected at the taught peaks,
  sec. 3.3.3; Rahok's default) or ``filter`` (the ch. 4 localization: the travel-distance particle
  filter of sec. 4.4.1, :class:`kiseki.magnetic.travel_distance.TravelDistanceLocalizer`, and the
  azimuth heading correction of sec. 4.4.2, :func:`~kiseki.magnetic.travel_distance.
  heading_from_map`; the default of the other ch. 4 methods). The heading theta_t of the ch. 4
  navigators is the odometry's, reset by sec. 4.4.2 when its gates hold (``filter`` only) and
  carried on by the odometry's turns after. The navigators see odometry, magnetometer and laser
  only; the true pose is
  logged for the cross-track error alone. Every method steers with the same PD gains
  (:data:`GAINS`); the ch. 4 navigators weigh the g terms by 0.3 rad/m (MultiNavigator's
  default), Rahok's w by :func:`kiseki.magnetic.rahok_navigation.weight_vector`'s defaults.
"""

from __future__ import annotations

import dataclasses
import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from kiseki._support.real_numbers import check_number
from kiseki.apps.magnetic.teach_checks import (
    OffsetCheck,
    check_magnetometer,
    check_route_length,
    check_taught_run,
)
from kiseki.control.pd_steering import PdSteering
from kiseki.core import derive_seed
from kiseki.magnetic.gates import gate_limits, reading_noise_sd
from kiseki.magnetic.linear_map import (
    LinearMagneticMap,
    geometric_features,
    path_identity,
)
from kiseki.magnetic.linear_map_run import linear_map_from_run
from kiseki.magnetic.navigators import DMZ_MAX, NAVIGATORS, RZ_MIN, MultiNavigator
from kiseki.magnetic.rahok_navigation import (
    PeakCorrection,
    RahokNavigator,
    identification_vector,
    moving_average,
    taught_peaks,
    weight_vector,
)
from kiseki.magnetic.travel_distance import TravelDistanceLocalizer, heading_from_map
from kiseki.sim.run import SimConfig, simulate
from kiseki.sim.scene import load_scene

__all__ = [
    "METHODS",
    "GATES",
    "TRAVEL",
    "NavigationResult",
    "TaughtMaps",
    "cross_track",
    "navigate",
    "teach",
]

METHODS = ("rahok", *NAVIGATORS, "multi")
TRAVEL = ("odometry", "peaks", "filter")
GATES = ("thesis", "sensor")
OFFSET = 1.0
"""m: the parallel paths' distance from the taught one (Fig. 2.10's y = -1 and +1 m)."""
GAINS = {"kp": 1.0, "kd": 0.5, "max_rate": 0.5}
"""PD gains of every method's steering (1/s, s, rad/s); the thesis prints none (sec. 3.3.4)."""
AVERAGE = 5
"""Readings averaged by Rahok's navigator before eq. 3.2 (0.3 m of travel; our choice)."""


@dataclass(frozen=True)
class TaughtMaps:
    """The taught path's map and the maps of its left and right parallel paths."""

    center: LinearMagneticMap
    left: LinearMagneticMap | None  # None: not taught (only Rahok's method needs them)
    right: LinearMagneticMap | None
    waypoints: np.ndarray  # (k, 2) the taught route


@dataclass(frozen=True)
class NavigationResult:
    method: str
    times: np.ndarray  # (n,) s
    truth: np.ndarray  # (n, 3) true (x, y, theta)
    travel: np.ndarray  # (n,) m, the navigator's travel distance
    cross_track: np.ndarray  # (n,) m, signed (left +) distance from the route
    along_track: np.ndarray  # (n,) m, true distance along the route
    travel_error: np.ndarray  # (n,) m, along the route: the map node at `travel` minus the truth
    drove: list  # (n,) the navigator that drove each step (None: none valid / rahok)
    corrections: list  # (peak s, d before, correction or None, window height) per peak
    heading_resets: int  # steps where sec. 4.4.2 reset the heading (travel = filter)
    reached_goal: bool
    navigators: tuple = ()  # the arbitrated navigators, highest priority first
    priorities: np.ndarray | None = None  # (n, navigators) effective priorities per step


def _shifted(points: np.ndarray, offset: float) -> np.ndarray:
    """The polyline moved ``offset`` m to its left (mitred corners)."""
    d = np.diff(points, axis=0)
    n = np.column_stack([-d[:, 1], d[:, 0]]) / np.linalg.norm(d, axis=1)[:, None]
    normals = np.vstack([n[:1], n[:-1] + n[1:], n[-1:]])
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    cos_half = np.vstack([[1.0], np.sum(n[:-1] * normals[1:-1], axis=1)[:, None], [1.0]])
    return points + offset * normals / cos_half.reshape(-1, 1)


def cross_track(points: np.ndarray, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(signed distance, left +, of each xy (n, 2) from the polyline ``points``; the distance
    along it of the nearest point)."""
    p = np.asarray(points, dtype=np.float64)
    q = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
    a, b = p[:-1], p[1:]
    ab = b - a
    length = np.linalg.norm(ab, axis=1)
    start = np.concatenate([[0.0], np.cumsum(length)])[:-1]
    u = np.clip(np.einsum("nkj,kj->nk", q[:, None, :] - a[None], ab) / length**2, 0.0, 1.0)
    near = a[None] + u[..., None] * ab[None]
    dist = np.linalg.norm(q[:, None, :] - near, axis=2)
    k = np.argmin(dist, axis=1)
    i = np.arange(len(q))
    rel = q - near[i, k]
    side = np.sign(ab[k, 0] * rel[:, 1] - ab[k, 1] * rel[:, 0])
    return side * dist[i, k], start[k] + u[i, k] * length[k]


def _scene_along(scene, offset: float):
    """The scene with its route and start moved ``offset`` m to the left."""
    points = np.asarray(scene.route["waypoints"], dtype=np.float64)
    moved = _shifted(points, offset)
    route = {**scene.route, "waypoints": moved.tolist()}
    robot = dict(scene.robot)
    x, y, yaw = robot.get("start", [0.0, 0.0, 0.0])
    normal = moved[0] - points[0]
    robot["start"] = [x + normal[0], y + normal[1], yaw]
    specs = [{**scene.robot_specs[0], "robot": robot, "route": route}]
    return dataclasses.replace(scene, robot=robot, route=route, robot_specs=specs)


def teach(
    scene_path: str | os.PathLike,
    out_dir: str | os.PathLike,
    seed: int = 0,
    offset: float = OFFSET,
    option: str = "offset",
) -> TaughtMaps:
    """Three teaching runs (taught path, left and right parallel paths) written to
    ``out_dir/teach_{center,left,right}.mcap``; returns their linear maps. ``option`` names
    the offset in the errors (``--offset`` on the command line)."""

    check_number(offset, "teach: offset", 0.0, low_open=True, unit="m")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    scene = load_scene(scene_path, "teach")
    if "waypoints" not in scene.route:
        raise ValueError(f"{scene_path}: the scene has no route to teach")
    check_magnetometer(scene, scene_path)
    waypoints = np.asarray(scene.route["waypoints"], dtype=np.float64)
    check_route_length(scene, scene_path, waypoints)
    offsets = OffsetCheck(scene, scene_path, offset, lambda d: _shifted(waypoints, d), option)
    offsets.before_runs()
    path_id = path_identity(waypoints)
    maps = {}
    for k, (name, shift) in enumerate((("center", 0.0), ("left", offset), ("right", -offset))):
        run = out / f"teach_{name}.mcap"
        here = scene if shift == 0.0 else _scene_along(scene, shift)
        summary = simulate(
            here, run, SimConfig(seed=derive_seed(seed, k)), overwrite=True, progress=False
        )
        # a run that did not reach the route's end maps part of it: refused, not a short map
        check_taught_run(summary, scene_path, name, offset, option)
        if name == "center":  # it reached its end: what blocks a parallel path is the offset
            offsets.after_route()
        maps[name] = linear_map_from_run(run, path_id, provenance={"path": name})
    if len(maps["center"]) < 2:
        n = len(maps["center"])
        raise ValueError(
            f"{scene_path}: the route gives {n} node{'' if n == 1 else 's'} of the linear map "
            f"(one every {maps['center'].spacing:g} m): too short to navigate"
        )
    return TaughtMaps(maps["center"], maps["left"], maps["right"], waypoints)


def rahok_vectors(maps: TaughtMaps, smooth: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """s (eq. 3.1) and w per node of the taught map. The three maps are averaged over
    ``smooth`` m before eq. 3.1 (our choice: a node averages under two readings of 0.01 G
    noise, so the 0.01 G threshold would otherwise flag the noise)."""
    c = maps.center
    if maps.left is None or maps.right is None:
        raise ValueError("Rahok's method needs the maps of the left and right parallel paths")
    cells = max(1, int(round(smooth / c.spacing)))
    fields = [moving_average(m.at(c.s).field, cells) for m in (c, maps.left, maps.right)]
    s_vec = identification_vector(*fields)
    return s_vec, weight_vector(s_vec, c.m_theta, c.spacing)


class _Controller:
    """simulate()'s controller: feeds odometry, magnetometer and laser to one method."""

    def __init__(
        self,
        method: str,
        maps: TaughtMaps,
        travel: str,
        dt: float,
        speed: float,
        gates: str,
        navigators: tuple[str, ...] = NAVIGATORS,
        gate_scale: float = 1.0,
    ):
        lmap = maps.center
        self.lmap, self.method, self.dt, self.speed = lmap, method, dt, speed
        peaks = taught_peaks(lmap.s, lmap.field[:, 2])
        self.peaks = PeakCorrection(peaks, lmap.spacing) if travel == "peaks" else None
        self.filter = None
        if travel == "filter":
            self.filter = TravelDistanceLocalizer(lmap, start=float(lmap.s[0]))
        self._since, self._offset, self.resets = 0.0, 0.0, 0
        if method == "rahok":
            s_vec, w_vec = rahok_vectors(maps)
            self.rahok = RahokNavigator(
                lmap, s_vec, w_vec, PdSteering(**GAINS), self.peaks, speed, AVERAGE
            )
        else:
            names = navigators if method == "multi" else (method,)
            limits = None
            if gates == "sensor":
                limits = gate_limits(reading_noise_sd(lmap.field[:, 2], lmap.count), lmap.count)
            if gate_scale != 1.0:  # the gate's limit times gate_scale (an experiment's control)
                thesis = np.full(len(lmap), (1.0 - RZ_MIN) * DMZ_MAX)  # eq. 4.5 as a limit
                limits = gate_scale * (thesis if limits is None else limits)
            self.multi = MultiNavigator(
                lmap, names, GAINS["kp"], GAINS["kd"], max_rate=GAINS["max_rate"], mz_limits=limits
            )
        self.d = float(lmap.s[0])
        self.done = False
        self._odom = None
        self._reading = None
        self._new = False
        self.log: dict[str, list] = {"t": [], "truth": [], "d": [], "drove": [], "p": []}

    def observe(self, t, odometry, readings) -> None:
        x, y, theta = odometry
        last = self._odom or (x, y)
        self._travelled = math.hypot(x - last[0], y - last[1])
        self._odom, self.theta = (x, y), theta
        self._new = False
        if readings:
            when, value = next(iter(readings.values()))
            self._new = abs(when - t) < 1e-9
            self._reading = value

    def _track(self, new) -> None:
        """Travel distance (and, with the filter, the heading offset) after this step."""
        self._since += self._travelled
        if self.filter is None:
            self.d += self._travelled
            if new is not None and self.peaks is not None:
                self.d += self.peaks.update(self.d, float(new[2]))
            return
        if new is None:
            return

        self.d = self.filter.step(self._since, float(new[2]))  # sec. 4.4.1
        self._since = 0.0
        fix = heading_from_map(self.lmap, self.d, self.theta + self._offset, new)  # sec. 4.4.2
        if fix.applied:
            self._offset = fix.theta - self.theta
            self.resets += 1

    def command(self, t, pose, scans):
        self.log["t"].append(t)
        self.log["truth"].append(pose)
        new = self._reading if self._new else None
        if self.method == "rahok":
            v, w = self.rahok.step(self._travelled, new, self.dt)
            self.d, self.done, drove = self.rahok.d, self.rahok.done, None
        else:
            self._track(new)
            self.done = self.d >= self.lmap.s[-1]
            g_t = np.full(2, np.nan)
            if scans:
                _, angles, ranges, max_range = next(iter(scans.values()))
                g_t = geometric_features(ranges, angles, max_range, *self.lmap.window)
            drove, w = None, 0.0
            if self._reading is not None and not self.done:
                node = int(self.lmap.index(self.d))
                theta_t = math.remainder(self.theta + self._offset, math.tau)
                drove, w = self.multi.step(node, theta_t, self._reading, g_t, self.dt)
            v = 0.0 if self.done else self.speed
        self.log["d"].append(self.d)
        self.log["drove"].append(drove)
        if self.method != "rahok":
            arbiter = self.multi.arbiter
            fresh = drove is not None
            self.log["p"].append(
                arbiter.last_priorities() if fresh else 0 * arbiter.last_priorities()
            )
        return v, 0.0, w


def navigate(
    scene_path: str | os.PathLike,
    maps: TaughtMaps,
    method: str,
    out: str | os.PathLike,
    seed: int = 1,
    travel: str | None = None,
    gates: str = "thesis",
    *,
    variant: str = "playback",
    navigators: tuple[str, ...] = NAVIGATORS,
    gate_scale: float = 1.0,
) -> NavigationResult:
    """Playback of the taught route with ``method`` (one of :data:`METHODS`) on the scene's
    ``variant`` (``playback``: the day after teaching); the run is written to the MCAP file
    ``out``. ``gates``: the magnetic navigators' validity, "thesis" (r_z >= 0.998) or "sensor"
    (kiseki's rule, :mod:`kiseki.magnetic.gates`, the noise read from the taught map), its limit
    times ``gate_scale``. ``navigators``: the ones the multi-navigator system arbitrates."""
    if gates not in GATES:
        raise ValueError(f"navigate: gates must be one of {', '.join(GATES)}, got {gates!r}")
    if not navigators or not set(navigators) <= set(NAVIGATORS):
        raise ValueError(
            f"navigate: navigators must be some of {', '.join(NAVIGATORS)}, got {navigators!r}"
        )
    check_number(gate_scale, "navigate: gate_scale", 0.0, low_open=True)

    if method not in METHODS:
        raise ValueError(f"navigate: method must be one of {', '.join(METHODS)}, got {method!r}")
    if travel is None:
        travel = {"rahok": "peaks", "odometry": "odometry"}.get(method, "filter")
    if travel not in TRAVEL or (method == "rahok" and travel == "filter"):
        raise ValueError(
            f"navigate: travel must be one of {', '.join(TRAVEL)} (rahok: not filter), got"
            f" {travel!r}"
        )
    if not isinstance(maps, TaughtMaps):
        raise ValueError(
            f"navigate: maps must be TaughtMaps (see teach), got {type(maps).__name__}"
        )
    scene = load_scene(scene_path, variant)
    check_magnetometer(scene, scene_path)
    if path_identity(scene.route["waypoints"]) != maps.center.path_id:
        raise ValueError(f"{scene_path}: the maps were taught on another path")
    config = SimConfig(seed=seed, max_duration=3.0 * maps.center.s[-1] / scene.route["speed"])
    speed = float(scene.route["speed"])
    controller = _Controller(
        method, maps, travel, config.dt, speed, gates, tuple(navigators), float(gate_scale)
    )
    summary = simulate(scene, out, config, controller=controller, overwrite=True, progress=False)
    log = controller.log
    truth = np.array(log["truth"], dtype=np.float64).reshape(-1, 3)
    xt, along = cross_track(maps.waypoints, truth[:, :2])
    travel = np.array(log["d"])
    nodes = maps.center.position[maps.center.index(travel)]
    _, node_along = cross_track(maps.waypoints, nodes)
    return NavigationResult(
        method,
        np.array(log["t"]),
        truth,
        travel,
        xt,
        along,
        node_along - along,
        log["drove"],
        list(controller.peaks.log) if controller.peaks is not None else [],
        controller.resets,
        summary.reached_goal,
        () if method == "rahok" else controller.multi.arbiter.names,
        np.array(log["p"]) if log["p"] else None,
    )
