# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The simulator's collisions, logged velocities, controller hook and pedestrians, against
hand-computed motion: the omni robot (0.70 m square, a_max 0.5 m/s^2, v_max 0.5 m/s, dt 0.1 s)
reaches 0.05 k m/s after k steps and moves 0.1 v per step (0.275 m in the first ten)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
import yaml

from kiseki.io.runlog import read_run
from kiseki.sim.pedestrians import Pedestrian
from kiseki.sim.run import SimConfig, simulate
from kiseki.sim.scene import load_scene


def scene_file(tmp_path, wall: bool = True, pedestrians=None):
    """An open floor, the omni robot at the origin heading +x, its laser 0.2 m ahead; with
    `wall`, a wall whose face is the plane x = 2.0 (faces on 0.05 m cell edges)."""
    doc = {
        "name": "collide",
        "bounds": {"min": [-1.0, -2.0, -0.1], "max": [4.0, 2.0, 2.1]},
        "floor": True,
        "objects": [{"type": "wall", "from": [2.05, -2.0], "to": [2.05, 2.0], "height": 2.0}]
        if wall
        else [{"type": "box", "center": [3.8, 1.8], "size": [0.1, 0.1, 0.5]}],
        "robot": {"type": "omni", "start": [0.0, 0.0, 0.0]},
        "sensors": [{"type": "laser", "preset": "speed_lrf", "name": "scan",
                     "mount": [0.2, 0.0, 0.3, 0.0]}],
    }  # fmt: skip
    if pedestrians:
        doc["pedestrians"] = pedestrians
    path = tmp_path / "collide.yaml"
    path.write_text(yaml.safe_dump(doc))
    return load_scene(path)


def test_driving_into_a_wall_ends_the_run_at_the_contact(tmp_path):
    # front edge 0.35 -> the face 2.0: 1.65 m; 0.275 m in 1.0 s, then 0.05 m per step:
    # 27.5 steps more, exact contact at 3.75 s, found at the end of step 38 (t = 3.8 s) with
    # the front at 0.35 + 0.275 + 28 * 0.05 = 2.025 m
    scene = scene_file(tmp_path)
    out = tmp_path / "run.mcap"
    summary = simulate(
        scene, out, SimConfig(duration=6.0), np.array([[0.0, 0.5, 0.0, 0.0]]), progress=False
    )
    c = summary.collision
    assert c is not None and (c.robot, c.hit) == ("robot", "obstacle")
    assert c.t == pytest.approx(3.8) and summary.sim_seconds == pytest.approx(3.8)
    assert summary.steps == 38 and not summary.reached_goal
    assert summary.final_pose[0] == pytest.approx(2.025 - 0.35, abs=1e-9)
    assert 2.0 <= c.contact[0] <= 2.025 + 1e-9 and abs(c.contact[1]) < 1e-9
    run = read_run(out)
    ((t, msg),) = run.messages("/collision")
    assert t == pytest.approx(3.8) and msg["hit"] == "obstacle" and msg["robot"] == "robot"
    assert msg["contact"] == pytest.approx(list(c.contact))
    times, poses = run.poses("/ground_truth")
    assert times[-1] == pytest.approx(3.8) and poses[-2, 0] + 0.35 < 2.0  # free one step before


def test_a_run_that_touches_nothing_records_no_collision(tmp_path):
    script = np.array([[0.0, 0.5, 0.0, 0.0], [2.0, 0.0, 0.0, 0.0]])  # stops 0.9 m short
    summary = simulate(scene_file(tmp_path), tmp_path / "r.mcap", SimConfig(duration=4.0),
                       script, progress=False)  # fmt: skip
    assert summary.collision is None and summary.steps == 40
    assert "/collision" not in read_run(tmp_path / "r.mcap").topics()


def test_cmd_vel_is_the_script_and_velocity_the_limited_ramp(tmp_path):
    script = np.array([[0.0, 0.8, 0.0, 0.0], [1.5, 0.0, 0.5, 0.0]])
    simulate(scene_file(tmp_path), tmp_path / "v.mcap", SimConfig(duration=3.0), script,
             progress=False)  # fmt: skip
    run = read_run(tmp_path / "v.mcap")
    t_cmd, cmd = run.velocities("/cmd_vel")
    t_vel, vel = run.velocities("/velocity")
    np.testing.assert_allclose(t_cmd, np.arange(30) * 0.1, atol=1e-9)
    np.testing.assert_allclose(t_vel, t_cmd)
    np.testing.assert_allclose(cmd, np.where((t_cmd < 1.5 - 1e-9)[:, None], [0.8, 0, 0],
                                             [0, 0.5, 0]), atol=1e-12)  # fmt: skip
    # by hand: +0.05 m/s per step up to v_max 0.5 (the 0.8 command is cut to 0.5); then the
    # change towards (0, 0.5) is the direction (-1, 1)/sqrt(2), 0.05 m/s per step
    k = np.arange(30)
    m = k - 14
    vx = np.where(k < 15, np.minimum(0.05 * (k + 1), 0.5), np.maximum(0.5 - 0.05 * m / 2**0.5, 0))
    vy = np.where(k < 15, 0.0, np.minimum(0.05 * m / 2**0.5, 0.5))
    np.testing.assert_allclose(vel, np.column_stack([vx, vy, np.zeros(30)]), atol=1e-12)
    assert np.hypot(vel[:, 0], vel[:, 1]).max() <= 0.5 + 1e-12
    assert np.linalg.norm(np.diff(vel[:, :2], axis=0), axis=1).max() <= 0.05 + 1e-12


class Forward:
    """Drives +x at 0.3 m/s until x >= 1.0, then commands a stop and is done."""

    def __init__(self) -> None:
        self.done, self.calls = False, []

    def command(self, t, pose, scans):
        self.calls.append((t, pose, scans))
        if pose[0] >= 1.0:
            self.done = True
            return 0.0, 0.0, 0.0
        return 0.3, 0.0, 0.0


def test_a_controller_drives_the_robot_and_sees_the_scans(tmp_path):
    scene = scene_file(tmp_path)
    ctrl = Forward()
    summary = simulate(scene, tmp_path / "c.mcap", SimConfig(), controller=ctrl, progress=False)
    # by hand: 0.105 m in six steps to 0.3 m/s, then 0.03 m per step: x = 1.005 after step 36;
    # the stop command (0.25 m/s after one step) adds 0.025 m; the run ends at step 37
    assert summary.reached_goal and summary.collision is None and summary.steps == 37
    assert summary.final_pose[0] == pytest.approx(1.03, abs=1e-9)
    t, pose, scans = ctrl.calls[0]
    assert t == 0.0 and pose == (0.0, 0.0, 0.0) and set(scans) == {"scan"}
    sensor, angles, ranges, max_range = scans["scan"]
    np.testing.assert_allclose(sensor, [0.2, 0.0, 0.0])
    assert angles.shape == ranges.shape == (683,) and max_range == 4.0
    assert ranges[np.argmin(np.abs(angles))] == pytest.approx(1.8, abs=0.02)  # the wall
    with pytest.raises(ValueError, match="collide.yaml"):
        simulate(scene, tmp_path / "x.mcap", SimConfig(), np.array([[0.0, 0.1, 0, 0]]),
                 controller=Forward(), progress=False)  # fmt: skip


def test_a_crossing_pedestrian_appears_in_the_scan(tmp_path):
    # walks up x = 1.2 at 1 m/s from y = -1.5: in front of the laser (x = 0.2) at t = 1.5 s,
    # its near edge at x = 0.95, 0.75 m away; before and after, the wall at 1.8 m
    walker = {"name": "p1", "start": [1.2, -1.5], "velocity": [0.0, 1.0]}
    scene = scene_file(tmp_path, pedestrians=[walker])
    simulate(scene, tmp_path / "p.mcap", SimConfig(duration=3.0),
             np.array([[0.0, 0.0, 0.0, 0.0]]), progress=False)  # fmt: skip
    run = read_run(tmp_path / "p.mcap")
    scans = run.laser_scans("/scan")
    ahead = np.argmin(np.abs(scans.angles))
    assert scans.ranges[0, ahead] == pytest.approx(1.8, abs=0.02)
    assert scans.ranges[15, ahead] == pytest.approx(0.75, abs=0.03)
    assert scans.ranges[30, ahead] == pytest.approx(1.8, abs=0.02)
    t, msg = run.messages("/pedestrians")[15]
    assert t == pytest.approx(1.5) and msg["names"] == ["p1"]
    assert msg["positions"][0] == pytest.approx([1.2, 0.0], abs=1e-9)
    # the grid is restored after each scan: the scene's map has no pedestrian
    assert (run.grid("/map").cells == 100).sum() == (
        scene.ground_truth(0.28, 0.32).cells == 100
    ).sum()


def test_driving_into_a_standing_pedestrian_collides_at_the_expected_time(tmp_path):
    # the disc's edge at x = 1.25, the front at 0.35: 0.9 m; 0.275 m in 1.0 s, then 12.5 steps:
    # exact contact at 2.25 s, found at the end of step 23 (front at 1.275 m)
    walker = {"name": "nurse", "start": [1.5, 0.0], "velocity": [0.0, 0.0], "radius": 0.25}
    scene = scene_file(tmp_path, wall=False, pedestrians=[walker])
    summary = simulate(scene, tmp_path / "n.mcap", SimConfig(duration=5.0),
                       np.array([[0.0, 0.5, 0.0, 0.0]]), progress=False)  # fmt: skip
    c = summary.collision
    assert (c.robot, c.hit) == ("robot", "nurse") and c.t == pytest.approx(2.3)
    assert c.contact == pytest.approx((1.275, 0.0), abs=1e-9)
    # the same pedestrian walking away out of the path at 1 m/s from t = 0 is never hit
    away = dataclasses.replace(scene.pedestrians[0], velocity=(0.0, 1.0))
    scene.pedestrians = [away]
    assert simulate(scene, tmp_path / "m.mcap", SimConfig(duration=5.0),
                    np.array([[0.0, 0.5, 0.0, 0.0]]), progress=False).collision is None  # fmt: skip


def test_pedestrian_timing_stop_and_validation(tmp_path):
    p = Pedestrian("p", (1.0, 2.0), (0.6, 0.8), start_time=2.0, stop_after=3.0)
    assert p.position(1.0) == (1.0, 2.0)  # stands until its start time
    assert p.position(3.0) == pytest.approx((1.6, 2.8))  # 1 s at 1 m/s
    assert p.position(10.0) == pytest.approx((1.0 + 1.8, 2.0 + 2.4))  # stopped after 3 m
    later = dataclasses.replace(p, start_time=4.0)
    assert later.position(3.0) == (1.0, 2.0)
    with pytest.raises(ValueError, match="start_time"):
        dataclasses.replace(p, start_time=-1.0)
    with pytest.raises(ValueError, match=r"collide.yaml: pedestrians\[0\]"):
        scene_file(tmp_path, pedestrians=[{"name": "q", "start": [0, 0], "velocity": [1]}])
    with pytest.raises(ValueError, match="collide.yaml: pedestrians"):
        scene_file(tmp_path, pedestrians=[{"name": "q", "start": [0, 0], "velocity": [1, 0],
                                           "speed": 2}])  # fmt: skip
    assert math.isclose(p.radius, 0.25)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"radius": 0.0}, "radius must be a finite number > 0 m, got 0.0"),
        ({"start_time": -1.0}, "start_time must be a finite number >= 0 s, got -1.0"),
        ({"stop_after": float("nan")}, "stop_after must be a finite number >= 0 m, got nan"),
        ({"radius": True}, "radius must be a finite number > 0 m, got True"),
        ({"start": (0.0, float("inf"))}, "start[1] must be a finite number, got inf"),
        ({"velocity": (1.0,)}, "velocity must be 2 finite numbers, got [1.0]"),
    ],
)
def test_a_pedestrian_names_its_bad_number(change, message):
    p = Pedestrian("p", (1.0, 2.0), (0.6, 0.8))
    with pytest.raises(ValueError) as e:
        dataclasses.replace(p, **change)
    assert str(e.value) == message
