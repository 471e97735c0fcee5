# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The rubble paper's tilting laser against closed forms: the tilt sign (theta < 0 looks down),
a 6-DOF sensor pose (set per move, or from the terrain) and a mount with roll, the gyro's drift
statistics, and the median of three sweeps."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from kiseki import _core
from kiseki.io.runlog import read_run
from kiseki.sim.gyro import Gyro, error_sd
from kiseki.sim.pose6 import PAPER_MOVES, Pose6, attitude, pose_matrix, terrain_pose
from kiseki.sim.primitives import BoxList
from kiseki.sim.run import SimConfig, simulate
from kiseki.sim.scene import load_scene
from kiseki.sim.sensors import Mount
from kiseki.sim.setup import build_robot, build_sensors
from kiseki.sim.tilting_laser import TiltingLaser, TiltingLaserParams, median_of_sweeps

WORLDS = Path(__file__).resolve().parents[3] / "data" / "worlds"
EXACT = {"noise_sd": 0.0, "gyro_sd_deg": 0.0, "gyro_bias_sd_deg_s": 0.0, "gyro_arw_deg_rt_s": 0.0}


def room(ceiling: float | None = None) -> _core.BoxWorld:
    """A floor whose top is z = 0 and, if given, a ceiling whose underside is z = ceiling."""
    boxes = BoxList.empty()
    boxes.add([0.0, 0.0, -0.05], [80.0, 80.0, 0.1])
    if ceiling is not None:
        boxes.add([0.0, 0.0, ceiling + 0.05], [80.0, 80.0, 0.1])
    return _core.BoxWorld(*boxes.arrays())


def expected_ranges(params, rot: np.ndarray, height: float, ceiling: float | None) -> np.ndarray:
    """Closed form: the ray of (theta, phi) has the vertical component dz = (row 3 of rot) .
    (cos th cos ph, sin ph, sin th cos ph); it meets the floor at height / -dz when dz < 0 and
    the ceiling at (ceiling - height) / dz when dz > 0; NaN from the usable range on."""
    tilt, scan = params.grid()
    th, ph = np.meshgrid(tilt, scan, indexing="ij")
    a, b, c = rot[2]
    dz = a * np.cos(th) * np.cos(ph) + b * np.sin(ph) + c * np.sin(th) * np.cos(ph)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.where(dz < -1e-12, height / -dz, np.inf)
        if ceiling is not None:
            r = np.where(dz > 1e-12, (ceiling - height) / dz, r)
    return np.where(r < params.usable_range, r, np.nan)


def compare(got: np.ndarray, want: np.ndarray, usable: float) -> None:
    edge = np.abs(np.nan_to_num(want, nan=usable) - usable) < 1e-3  # at the 5 m cut
    assert np.array_equal(np.isnan(got) | edge, np.isnan(want) | edge)
    np.testing.assert_allclose(got[~edge], want[~edge], atol=1e-6)


# ------------------------------------------------------------------------------ 1. tilt sign


def test_negative_tilt_looks_down_floor_and_ceiling_at_closed_form_ranges():
    params = TiltingLaserParams(**EXACT)
    laser, h, ceiling = TiltingLaser(params, seed=0), 0.5, 2.0
    ranges, _ = laser.scan(room(ceiling), pose_matrix(0.0, 0.0, h, 0.0, 0.0, 0.0))
    compare(ranges, expected_ranges(params, np.eye(3), h, ceiling), params.usable_range)
    tilt, scan = params.grid()
    row = lambda deg: int(np.argmin(np.abs(np.degrees(tilt) - deg)))  # noqa: E731
    j0 = int(np.argmin(np.abs(scan)))
    # Fig. 11's cut at theta = -17 deg crosses the floor: h / sin 17 deg ahead, and across phi
    assert ranges[row(-17), j0] == pytest.approx(h / math.sin(math.radians(17)), abs=1e-9)
    assert np.isfinite(ranges[row(-17)]).sum() > 100
    assert ranges[row(-90), j0] == pytest.approx(h, abs=1e-9)  # straight down
    assert ranges[row(-120), j0] == pytest.approx(h / math.sin(math.radians(60)), abs=1e-9)
    assert ranges[row(30), j0] == pytest.approx((ceiling - h) / 0.5, abs=1e-9)  # up in front
    floor_rows = np.isfinite(ranges[:, j0]) & (np.degrees(tilt) < 0)
    assert floor_rows.sum() == 115  # -120..-6 deg: h / sin 6 deg = 4.78 m < 5 m < h / sin 5


def test_eq_two_as_printed_is_the_opposite_sign():
    params = TiltingLaserParams(**EXACT, tilt_down="positive")
    ranges, _ = TiltingLaser(params, 0).scan(room(), pose_matrix(0.0, 0.0, 0.5, 0.0, 0.0, 0.0))
    flip = np.diag([1.0, 1.0, -1.0])  # z = -r sin th cos ph
    compare(ranges, expected_ranges(params, flip, 0.5, None), params.usable_range)
    tilt, _ = params.grid()
    assert np.isnan(ranges[np.argmin(np.abs(np.degrees(tilt) + 17))]).all()  # -17: no floor


# ------------------------------------------------------------------------------ 2. 6-DOF pose


@pytest.mark.parametrize(
    "robot, mount",
    [
        (PAPER_MOVES["A"], Mount(0.2, 0.0, 0.5)),  # the paper's environment A move
        (PAPER_MOVES["B"], Mount(0.2, 0.1, 0.4, 10.0, 5.0, 3.0)),
        (Pose6(), Mount(0.0, 0.0, 0.6, 0.0, 0.0, 20.0)),  # a mount rolled 20 deg
    ],
)
def test_level_floor_from_a_tilted_sensor(robot, mount):
    params = TiltingLaserParams(**EXACT)
    sensor = mount.world(robot.values)

    # closed form, built here without the code's matrices: R = Rz Ry Rx of the robot, then the
    # mount's; the sensor's height is the robot's z plus the rotated mount offset
    def rot(yaw, pitch, roll):
        cy, sy, cp, sp, cr, sr = (f(a) for a in (yaw, pitch, roll) for f in (math.cos, math.sin))
        return np.array(
            [
                [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                [-sp, cp * sr, cp * cr],
            ]
        )

    body = rot(robot.yaw, robot.pitch, robot.roll)
    fixed = rot(*(math.radians(a) for a in (mount.yaw_deg, mount.pitch_deg, mount.roll_deg)))
    height = robot.z + body[2] @ [mount.x, mount.y, mount.z]
    assert sensor[2, 3] == pytest.approx(height, abs=1e-12)
    ranges, gyro = TiltingLaser(params, 1).scan(room(), sensor)
    compare(ranges, expected_ranges(params, body @ fixed, height, None), params.usable_range)
    np.testing.assert_allclose(pose_matrix(0, 0, 0, *gyro)[:3, :3], body @ fixed, atol=1e-12)


def test_pitch_shifts_the_tilt():
    # pure pitch p: dz = cos ph sin(th - p), so the pitched sweep's row th is the level sweep's
    # row th - p (1 deg steps; p = -10 deg, the paper's nose-up pitch: each row looks 10 deg up)
    params = TiltingLaserParams(**EXACT)
    level, _ = TiltingLaser(params, 0).scan(room(), pose_matrix(0, 0, 0.5, 0, 0, 0))
    nose_up, _ = TiltingLaser(params, 0).scan(room(), pose_matrix(0, 0, 0.5, 0, -0.1745329252, 0))
    np.testing.assert_allclose(nose_up[:-10], level[10:], atol=1e-6)


@pytest.mark.parametrize("heading_deg", [0.0, 35.0, 90.0, 200.0])
def test_terrain_pose_on_a_slope(heading_deg):
    alpha, slope_yaw = math.radians(12.0), math.radians(25.0)  # grade 12 deg rising along 25 deg
    boxes = BoxList.empty()
    center, thickness = np.array([1.0, 2.0, 0.4]), 0.2
    boxes.add(center, [6.0, 6.0, thickness], slope_yaw, -alpha)
    world = _core.BoxWorld(*boxes.arrays())
    yaw = slope_yaw + math.radians(heading_deg)
    pose = terrain_pose(world, 1.3, 1.8, yaw, 0.6, 0.4, from_z=3.0)
    d = yaw - slope_yaw
    t = math.tan(alpha)
    assert pose.pitch == pytest.approx(-math.atan(t * math.cos(d)), abs=1e-9)
    assert pose.roll == pytest.approx(
        math.atan2(-t * math.sin(d), math.sqrt(1 + (t * math.cos(d)) ** 2)), abs=1e-9
    )
    normal = np.array(
        [
            -math.sin(alpha) * math.cos(slope_yaw),
            -math.sin(alpha) * math.sin(slope_yaw),
            math.cos(alpha),
        ]
    )
    top = center + normal * thickness / 2
    z = top[2] - (normal[0] * (1.3 - top[0]) + normal[1] * (1.8 - top[1])) / normal[2]
    assert pose.z == pytest.approx(z, abs=1e-9)
    np.testing.assert_allclose(pose.matrix()[:3, 2], normal, atol=1e-9)  # body z = normal


def test_pose_checks_its_input():
    with pytest.raises(ValueError, match="finite"):
        Pose6(0.0, 0.0, math.nan)
    with pytest.raises(ValueError, match="no ground"):
        terrain_pose(room(), 100.0, 0.0, 0.0, 0.6, 0.4, from_z=1.0)
    with pytest.raises(ValueError, match="robot_pose"):
        Mount().world([0.0, 0.0, 0.0, 0.0])
    np.testing.assert_allclose(attitude(PAPER_MOVES["B"].matrix()), PAPER_MOVES["B"].values[3:])


# ------------------------------------------------------------------------------ 3. gyro drift


def test_gyro_error_statistics_match_the_closed_form():
    s, b, n, times, seeds = 0.5, 0.01, 0.005, (0.0, 30.0, 100.0, 400.0), 3000
    errors = np.array(
        [
            [np.degrees(g.read(np.zeros(3), t)) for t in times]
            for g in (Gyro(s, b, n, k) for k in range(seeds))
        ]
    )  # (seeds, times, 3)
    for i, t in enumerate(times):
        sd = error_sd(t, s, b, n)
        e = errors[:, i].ravel()
        assert abs(e.mean()) < 4 * sd / math.sqrt(e.size)
        assert e.std() == pytest.approx(sd, rel=4 / math.sqrt(2 * e.size))
    assert error_sd(400.0, s, b, n) == pytest.approx(math.sqrt(0.25 + 16 + 0.01))


def test_gyro_drift_parts():
    bias_only = [Gyro(0.0, 0.02, 0.0, k) for k in range(2000)]
    e = np.array([np.degrees(g.read(np.zeros(3), 50.0)) for g in bias_only])
    np.testing.assert_allclose(e / 50.0, [g.bias_deg_s for g in bias_only], atol=1e-12)
    assert e.std() == pytest.approx(0.02 * 50.0, rel=0.05)
    walk = [Gyro(0.0, 0.0, 0.1, k) for k in range(2000)]
    first = np.array([g.error_deg(20.0) for g in walk])
    later = np.array([g.error_deg(120.0) for g in walk])
    inc = (later - first).ravel()  # independent increments: var N^2 (t2 - t1)
    assert inc.std() == pytest.approx(0.1 * math.sqrt(100.0), rel=0.05)
    assert abs(np.corrcoef(first.ravel(), inc)[0, 1]) < 0.05


def test_gyro_is_seeded_and_time_goes_forward():
    a, b = Gyro(seed=5), Gyro(seed=5)
    assert np.array_equal(a.read([0.1, 0.2, 0.3], 10.0), b.read([0.1, 0.2, 0.3], 10.0))
    assert not np.array_equal(
        Gyro(seed=6).read([0, 0, 0], 10.0), Gyro(seed=5).read([0, 0, 0], 10.0)
    )
    with pytest.raises(ValueError, match="time must not go back"):
        a.read([0, 0, 0], 5.0)
    with pytest.raises(ValueError, match="bias_sd_deg_s"):
        Gyro(bias_sd_deg_s=-1.0)
    with pytest.raises(ValueError, match="true attitude"):
        a.read([0, math.nan, 0], 11.0)


# ----------------------------------------------------------------------------- 4. median of 3


def test_median_of_three_sweeps_against_numpy():
    params = TiltingLaserParams(noise_sd=0.2, step_deg=2.0)  # noisy: cells cross the 5 m cut
    pose = pose_matrix(0.0, 0.0, 0.5, 0.0, 0.0, 0.0)
    sweeps = TiltingLaser(params, 9).sweeps(room(2.0), pose)
    ranges, _ = TiltingLaser(params, 9).scan(room(2.0), pose)
    missing = np.isnan(sweeps).sum(axis=0)
    assert {0, 1, 2, 3} <= set(np.unique(missing).tolist())  # every case occurs
    want = np.full(ranges.shape, np.nan)
    for idx in np.argwhere(missing <= 1):
        cell = sweeps[(slice(None), *idx)]
        want[tuple(idx)] = np.median(cell[np.isfinite(cell)])
    np.testing.assert_array_equal(ranges, want)
    again, _ = TiltingLaser(params, 9).scan(room(2.0), pose)
    np.testing.assert_array_equal(again, ranges)  # deterministic for a seed
    with pytest.raises(ValueError, match="at least one sweep"):
        median_of_sweeps(np.zeros((0, 3)))


def test_sweeps_must_be_odd():
    with pytest.raises(ValueError, match="sweeps must be odd"):
        TiltingLaserParams(sweeps=2)


# --------------------------------------------------------------------------- the scene's keys


def _rubble(tmp_path, **keys):
    doc = yaml.safe_load((WORLDS / "rubble_a.yaml").read_text())
    doc["sensors"][0].update(keys)
    path = tmp_path / "rubble.yaml"
    path.write_text(yaml.safe_dump(doc))
    scene = load_scene(path)
    return build_sensors(scene, build_robot(scene, 0), 0, 0.1)


def test_scene_sets_mount_roll_and_the_new_parameters(tmp_path):
    params = {"sweeps": 1, "gyro_bias_sd_deg_s": 0.002, "tilt_down": "positive"}
    (tilt,) = _rubble(tmp_path, roll=-4.0, pitch=3.0, params=params)
    assert tilt.mount == Mount(0.2, 0.0, 0.5, 0.0, 3.0, -4.0)
    p = tilt.device.params
    assert (p.sweeps, p.gyro_bias_sd_deg_s, p.tilt_down, p.gyro_arw_deg_rt_s) == (
        1, 0.002, "positive", 0.005,
    )  # fmt: skip
    for bad, message in (
        ({"sweeps": 4}, r"sensors\[0\]\.params: sweeps must be odd"),
        ({"tilt_down": "up"}, r"sensors\[0\]\.params\.tilt_down"),
        ({"gyro_arw_deg_rt_s": -1.0}, r"sensors\[0\]\.params\.gyro_arw_deg_rt_s"),
    ):
        with pytest.raises(ValueError, match=rf"rubble\.yaml: {message}"):
            _rubble(tmp_path, params=bad)


def test_the_simulated_sweep_rests_on_the_terrain(tmp_path):
    # a low ramp (3 cm over 2 m, under the 5 cm the planar robot drives over) under the start
    rise, length, thick = 0.03, 2.0, 0.01
    doc = {
        "name": "ramp",
        "bounds": {"min": [0, 0, -0.1], "max": [4, 4, 2]},
        "floor": True,
        "objects": [
            {
                "type": "slope",
                "center": [2, 2],
                "size": [length, 1.5],
                "rise": rise,
                "thickness": thick,
            },
        ],  # fmt: skip
        "robot": {"type": "diff_drive", "start": [2.0, 2.0, 0.0]},
        "sensors": [{"type": "tilting_laser", "name": "tilt", "mount": [0.2, 0.0, 0.5]}],
        "route": {"waypoints": [[2, 2], [2.5, 2]], "speed": 0.2},
    }
    (tmp_path / "ramp.yaml").write_text(yaml.safe_dump(doc))
    scene, out = load_scene(tmp_path / "ramp.yaml"), tmp_path / "run.mcap"
    simulate(scene, out, SimConfig(1.0, seed=2), progress=False)
    ((_, message),) = read_run(out).messages("/tilt")
    sensor = np.array(message["sensor_pose"]).reshape(4, 4)
    alpha = math.atan2(rise, length)  # nose up: pitch -alpha
    np.testing.assert_allclose(attitude(sensor), [0.0, -alpha, 0.0], atol=1e-9)
    ground = rise / 2 + thick / (2 * math.cos(alpha))  # the ramp's top under the centre
    height = ground + 0.2 * math.sin(alpha) + 0.5 * math.cos(alpha)
    ahead = 0.2 * math.cos(alpha) - 0.5 * math.sin(alpha)
    np.testing.assert_allclose(sensor[:3, 3], [2.0 + ahead, 2.0, height], atol=1e-9)
