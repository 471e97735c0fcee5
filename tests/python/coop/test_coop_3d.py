# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Cooperative positioning in 3-D: on uneven ground against the planar case, and the
simulated scene's form-2 turns, whose recorded bearings triangulate the moving robot."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kiseki.coop import START, plan, simulate, simulate_3d, triangulate


def _wavy(x, y):
    return 0.5 * np.sin(2 * np.pi * x / 4.0) * np.cos(2 * np.pi * y / 4.0)


def test_three_d_on_uneven_ground() -> None:
    p = plan(2, 7)
    exact = simulate_3d(p, _wavy, 5, angle_sigma=0.0, elevation_sigma=0.0)
    assert exact.goal_errors.max() < 1e-9
    assert exact.truth[-1, p.steps[-1].robot, 2] == pytest.approx(_wavy(0.0, 10.0) + 0.5)
    # flat ground: the horizontal error is the planar one (elevations add range information)
    flat = simulate_3d(p, lambda x, y: np.zeros_like(x), 3000, seed=3)
    planar = simulate(p, 3000, seed=3).goal_errors.mean()
    horizontal = np.hypot(*flat.goal_offsets[:, :2].T).mean()
    assert 0.75 * planar < horizontal <= 1.05 * planar
    wavy = simulate_3d(p, _wavy, 3000, seed=3)
    assert np.abs(wavy.goal_offsets[:, 2]).mean() < 0.2 * horizontal  # height from elevations
    with pytest.raises(ValueError, match="ground"):
        simulate_3d(p, lambda x, y: np.zeros(3))
    with pytest.raises(ValueError, match="marker_height"):
        simulate_3d(p, _wavy, marker_height=-1.0)


# --- the turns in the simulator ---


def test_the_scene_takes_the_turns_of_form_2_and_its_bearings_triangulate(tmp_path) -> None:
    from kiseki.io.runlog import read_run
    from kiseki.sim.run import SimConfig
    from kiseki.sim.run import simulate as run_scene
    from kiseki.sim.scene import load_scene

    root = __import__("pathlib").Path(__file__).resolve().parents[3]
    scene = load_scene(root / "data" / "worlds" / "coop_three_robots.yaml")
    names = ["r1", "r2", "r3"]
    # the scene says what it is: kiseki.coop.plan(2, 7) from the paper's start, goal (0, 10)
    p = plan(2, 7)
    starts = np.array([spec["robot"]["start"][:2] for spec in scene.robot_specs], dtype=float)
    np.testing.assert_allclose(starts, START)
    assert scene.turns["goal"] == (0.0, 10.0)
    assert [m for m, _ in scene.turns["moves"]] == [names[s.robot] for s in p.steps]
    np.testing.assert_allclose([to for _, to in scene.turns["moves"]], [s.target for s in p.steps],
                               atol=1e-4)  # fmt: skip
    # the paper's robots are points (the scene's point_robots): the plan drives the 0.70 m
    # bodies through each other, and they do not collide
    config = SimConfig(seed=3)
    summary = run_scene(scene, tmp_path / "coop.mcap", config, progress=False)
    assert summary.reached_goal
    run = read_run(tmp_path / "coop.mcap")

    def track(name: str) -> np.ndarray:
        return np.array(
            [
                [m["pose"]["position"]["x"], m["pose"]["position"]["y"]]
                for _, m in run.messages(f"/{name}/ground_truth")
            ]
        )

    truth = {n: track(n) for n in names}
    times = np.array([t for t, _ in run.messages("/r1/ground_truth")])
    bearings = {n: run.messages(f"/{n}/bearings") for n in names}
    events = run.messages("/turns")
    assert [e["event"] for _, e in events] == ["start", "arrived"] * 7
    errors = []
    for (t0, start), (t1, arrived) in zip(events[0::2], events[1::2], strict=True):
        k0, k1 = int(np.searchsorted(times, t0)), int(np.searchsorted(times, t1))
        mover = arrived["robot"]
        for n in names:  # one robot drives at a time
            moved = np.linalg.norm(truth[n][k1] - truth[n][k0])
            assert (moved > 1.0) if n == mover else (moved < 1e-9), (start, n)
        assert np.linalg.norm(truth[mover][k1] - arrived["to"]) < 0.15
        # the standing robots' logged bearings, turned into the paper's angles, triangulate it
        i, j = [n for n in names if n != mover]
        world = []
        for a, b in ((i, j), (j, i)):
            msg = bearings[a][k1][1]
            rel = dict(zip(msg["targets"], msg["bearings"], strict=True))
            angle = rel[mover] - rel[b]  # between the other standing robot and the mover
            base = truth[b][k1] - truth[a][k1]
            world.append(math.atan2(base[1], base[0]) + angle)
        found = triangulate(np.stack([truth[i][k1], truth[j][k1]]), world)
        errors.append(np.linalg.norm(found - truth[mover][k1]))
    assert max(errors) < 0.05 and len(errors) == 7  # 0.1 deg over a few metres: millimetres
