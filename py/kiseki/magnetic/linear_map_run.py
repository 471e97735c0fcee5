# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""A teaching run's samples for a linear magnetic map, read from a kiseki MCAP run log (the
output of ``kiseki sim run`` or of a teaching run): one sample per magnetometer message.

* travel distance s: the length of the odometry path (``/odom`` x, y) up to the reading's time,
  linear in time between odometry messages; heading: the odometry's theta at the nearest
  odometry message. The thesis builds its map during teaching from odometry (sec. 4.3.1), and
  playback compares its own odometry with it, so the ground truth is not used for s;
* the reading (x, y, z) of the ``kiseki.MagneticField`` message, G, sensor frame;
* g = (g_l, g_r) of the nearest laser scan in time
  (:func:`kiseki.magnetic.linear_map.geometric_features`), NaN without a scan topic;
* position: the ground-truth (x, y) at the reading's time (linear between poses), for
  evaluation only; NaN without a ground-truth topic.

The log is a data source like a recorded one: nothing here uses the simulator itself.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from kiseki.errors import LogFormatError
from kiseki.io.runlog import read_run
from kiseki.magnetic.linear_map import (
    NODE_SPACING,
    WINDOW_ANGLE,
    WINDOW_RANGE,
    LinearMagneticMap,
    build_linear_map,
    geometric_features,
)

__all__ = ["TeachingSamples", "linear_map_from_run", "teaching_samples"]


@dataclass(frozen=True)
class TeachingSamples:
    """One row per magnetometer reading (see the module text)."""

    times: np.ndarray  # (n,) s
    s: np.ndarray  # (n,) m, odometry travel distance
    readings: np.ndarray  # (n, 3) G, sensor frame
    heading: np.ndarray  # (n,) rad, odometry
    g: np.ndarray  # (n, 2) m, NaN: no obstacle or no scan
    position: np.ndarray  # (n, 2) m, ground truth, NaN: unknown


def _rows(run, topic: str, keys: tuple[str, ...]) -> tuple[np.ndarray, np.ndarray]:
    if topic not in run.topics():
        raise LogFormatError(f"{run.path}: no topic {topic!r} (topics: {sorted(run.topics())})")
    messages = run.messages(topic)
    if not messages:
        raise LogFormatError(f"{run.path}: no messages on {topic!r}")
    try:
        values = np.array([[m[k] for k in keys] for _, m in messages], dtype=np.float64)
    except (KeyError, TypeError, ValueError) as exc:
        needs = ", ".join(keys)
        raise LogFormatError(f"{run.path}: {topic!r} needs numbers {needs} ({exc})") from None
    return np.array([t for t, _ in messages], dtype=np.float64), values


def _nearest(times: np.ndarray, at: np.ndarray) -> np.ndarray:
    after = np.searchsorted(times, at).clip(0, len(times) - 1)
    before = (after - 1).clip(0, len(times) - 1)
    return np.where(np.abs(at - times[before]) <= np.abs(times[after] - at), before, after)


def teaching_samples(
    run_file: str | os.PathLike,
    mag_topic: str = "/mag",
    odom_topic: str = "/odom",
    scan_topic: str | None = "/scan",
    truth_topic: str | None = "/ground_truth",
    window_range: float = WINDOW_RANGE,
    window_angle: float = WINDOW_ANGLE,
) -> TeachingSamples:
    """The samples of the MCAP run ``run_file`` (see the module text). LogFormatError names the
    file and the missing or malformed topic."""

    run = read_run(run_file)
    t_mag, readings = _rows(run, mag_topic, ("x", "y", "z"))
    t_odom, odom = _rows(run, odom_topic, ("x", "y", "theta"))
    order = np.argsort(t_odom, kind="stable")
    t_odom, odom = t_odom[order], odom[order]
    travelled = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(odom[:, :2], axis=0).T))])
    s = np.interp(t_mag, t_odom, travelled)
    heading = odom[_nearest(t_odom, t_mag), 2]
    g = np.full((len(t_mag), 2), np.nan)
    if scan_topic is not None:
        scans = run.laser_scans(scan_topic, truth_topic=None, odom_topic=None)
        per_scan = geometric_features(
            scans.ranges, scans.angles, scans.max_range, window_range, window_angle
        )
        g = per_scan[_nearest(scans.times, t_mag)]
    position = np.full((len(t_mag), 2), np.nan)
    if truth_topic is not None:
        t_true, truth = run.poses(truth_topic)
        if len(t_true):
            position = np.column_stack(
                [np.interp(t_mag, t_true, truth[:, 0]), np.interp(t_mag, t_true, truth[:, 1])]
            )
    return TeachingSamples(t_mag, s, readings, heading, g, position)


def linear_map_from_run(
    run_file: str | os.PathLike,
    path_id: str,
    spacing: float = NODE_SPACING,
    window_range: float = WINDOW_RANGE,
    window_angle: float = WINDOW_ANGLE,
    provenance: Mapping[str, str] | None = None,
    **topics: str | None,
) -> LinearMagneticMap:
    """The linear magnetic map of a teaching run log, for the path ``path_id``
    (:func:`kiseki.magnetic.linear_map.path_identity` of the route's waypoints). ``topics``:
    ``mag_topic``, ``odom_topic``, ``scan_topic``, ``truth_topic`` as in
    :func:`teaching_samples`."""
    samples = teaching_samples(
        run_file, window_range=window_range, window_angle=window_angle, **topics
    )
    info = {"run": os.path.basename(os.fspath(run_file)), **(provenance or {})}
    return build_linear_map(
        samples.s,
        samples.readings,
        samples.heading,
        path_id=path_id,
        g=samples.g,
        position=samples.position,
        spacing=spacing,
        window=(window_range, window_angle),
        provenance=info,
    )
