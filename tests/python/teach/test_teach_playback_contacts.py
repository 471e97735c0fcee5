# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Teaching and playback against the scene's obstacles: a simulated robot never drives through
them. Teaching and playback moved the robot through walls and out of the scene (playback said
"goal reached: True" with the robot outside the scene), while a simulated run stopped at its
first contact. Contacts are judged against the collision check's own reference: the robot's
footprint sampled on the scene's truth at its height (kiseki.sim.collisions)."""

from __future__ import annotations

import io

import numpy as np
import pytest
import yaml

from _helpers.cli_main import kiseki
from _helpers.pixels import blobs, rgb
from kiseki.apps.teach import PlaybackConfig, playback, teach
from kiseki.apps.teach.keyboard import KeyScript, teach_keyboard
from kiseki.apps.teach.playback_picture import render_playback
from kiseki.grid import OccupancyGrid
from kiseki.io.ros_map import load_map
from kiseki.io.runlog import read_run
from kiseki.sim.collisions import FootprintChecker, body_grid, check_route_clear
from kiseki.sim.robot import DiffDriveRobot
from kiseki.sim.scene import load_scene
from kiseki.sim.setup import build_robot

# the cross wall of the test corridor: 0.1 m thick at x = 1.5, its near face at 1.45
WALL_FACE_X = 1.45


def corridor(tmp_path, project_root, name: str, route, extra=()):
    """The factory corridor with `route` (P0, P1, ...) and `extra` objects, written as `name`."""
    doc = yaml.safe_load((project_root / "data" / "worlds" / "factory_corridor.yaml").read_text())
    doc["route"]["waypoints"] = [list(p) for p in route]
    doc["route"]["names"] = [f"P{i}" for i in range(len(route))]
    doc["objects"] += list(extra)
    path = tmp_path / name
    path.write_text(yaml.safe_dump(doc, sort_keys=False))
    return path


CROSS_WALL = {
    "type": "wall",
    "from": [1.5, -1.5],
    "to": [1.5, 1.5],
    "height": 2.5,
    "thickness": 0.1,
}


def contacts(scene, poses) -> int:
    """How many of the poses (n, 3) put the robot's footprint on an obstacle."""
    setup = build_robot(scene, 0)
    checker = FootprintChecker(body_grid(scene, setup.height), setup.length, setup.width)
    return sum(checker.contact(tuple(p)) is not None for p in poses)


def test_halt_leaves_the_robot_at_rest_where_it_is_put():
    robot = DiffDriveRobot(pose=(1.0, 2.0, 0.5), velocity=(0.4, 0.2))
    robot.halt((0.5, -1.0, 4.0))
    assert (robot.pose.x, robot.pose.y) == (0.5, -1.0)
    assert robot.pose.theta == pytest.approx(4.0 - 2 * np.pi)  # wrapped as every pose
    assert robot.velocity == (0.0, 0.0)


def test_a_route_waypoint_where_the_robot_cannot_stand_is_refused_before_anything_is_written(
    tmp_path, project_root
):
    """P1 at the pillar's centre (9.15, -1.35): the cell at the point itself is occupied."""
    path = corridor(tmp_path, project_root, "c.yaml", [(0.0, 0.0), (9.15, -1.35)])
    with pytest.raises(ValueError) as err:
        teach(load_scene(path), tmp_path / "t")
    assert str(err.value).startswith(f"{path}: route waypoint P1 [9.15, -1.35] lies 0.0")
    assert "within half the robot's width (0.29 m): the robot cannot stand there" in str(err.value)
    assert not (tmp_path / "t").exists()


def test_a_waypoint_within_half_the_robot_width_of_a_wall_is_refused(tmp_path, project_root):
    """The side wall's face is at y = 1.50 and nothing else stands near x = -0.5: a waypoint
    0.2 m from the wall is refused (the nearest cell centre 0.225 m away), one 0.35 m from it
    is not."""
    near = corridor(tmp_path, project_root, "near.yaml", [(0.0, 0.0), (-0.5, 1.3)])
    scene = load_scene(near)
    with pytest.raises(ValueError, match=r"route waypoint P1 \[-0.5, 1.3\] lies 0\.23 m from"):
        teach(scene, tmp_path / "near")
    assert not (tmp_path / "near").exists()
    setup = build_robot(scene, 0)
    grid = body_grid(scene, setup.height)
    check_route_clear(scene, [(0.0, 0.0), (-0.5, 1.15)], ["P0", "P1"], setup.width, grid)


def test_scripted_teaching_stops_at_the_first_contact_and_names_it(tmp_path, project_root):
    """Both waypoints are free; the straight leg between them crosses a wall. Before, the robot
    drove through it and the teaching ended with exit 0."""
    path = corridor(tmp_path, project_root, "c.yaml", [(0.0, 0.0), (3.0, 0.0)], [CROSS_WALL])
    with pytest.raises(ValueError) as err:
        teach(load_scene(path), tmp_path / "t")
    message = str(err.value)
    assert message.startswith(f"{path}: pushed along the route, the robot touches an obstacle at")
    x = float(message.split("obstacle at (")[1].split(",")[0])
    assert WALL_FACE_X - 0.05 <= x <= WALL_FACE_X + 0.05  # the wall's face, within a cell
    assert "after waypoint P0: move the route's waypoints so that its path stays clear" in message
    assert message.endswith(
        f"{tmp_path / 't' / 'teach.mcap'} holds the run up to there (to teach into "
        f"{tmp_path / 't'} again: --overwrite, or overwrite=True)"
    )
    truth = read_run(tmp_path / "t" / "teach.mcap").poses("/ground_truth")[1]
    assert contacts(load_scene(path), truth) == 0  # no logged step is in the wall


def test_keyboard_teaching_stops_the_robot_at_a_wall(tmp_path, project_root):
    """Full speed ahead for 10 s at a wall 1.45 m ahead: the robot (0.525 m from its centre to
    its front) stops short of it, within one step and one cell, and stays there; the operator
    reads where. Before, it drove on through the wall to x = 4.8 m."""
    path = corridor(tmp_path, project_root, "c.yaml", [(0.0, 0.0), (1.0, 0.0)], [CROSS_WALL])
    scene = load_scene(path)
    keys = tmp_path / "keys.txt"
    keys.write_text("0.0 w w w w w\n10.0 m q\n")
    status = io.StringIO()
    with KeyScript(keys) as source:
        result = teach_keyboard(scene, tmp_path / "t", source, stream=status)
    truth = read_run(result.log).poses("/ground_truth")[1]
    front = truth[:, 0] + build_robot(scene, 0).length / 2
    assert front.max() <= WALL_FACE_X + 1e-9  # the body never entered the wall
    assert front[-1] >= WALL_FACE_X - 0.05 - 0.05  # stopped within a step (0.05 m) and a cell
    assert contacts(scene, truth) == 0
    assert result.marks[0]["truth"][0] == pytest.approx(truth[-1, 0])
    bumps = [line for line in status.getvalue().splitlines() if line.startswith("bumped")]
    assert len(bumps) >= 1
    assert bumps[0].endswith("the robot stopped; back off (s) before turning (a, d)")
    logged = [m for _, m in read_run(result.log).messages("/collision")]  # each bump, logged
    assert len(logged) == len(bumps)
    assert all(abs(m["contact"][0] - WALL_FACE_X) <= 0.05 for m in logged)


@pytest.fixture(scope="module")
def taught_corridor(tmp_path_factory, project_root):
    """A 3 m corridor taught once, and a copy with a 0.3 m pillar on the route at x = 2."""
    root = tmp_path_factory.mktemp("contacts")
    route = [(0.0, 0.0), (1.5, 0.0), (3.0, 0.0)]
    path = corridor(root, project_root, "c.yaml", route)
    taught = teach(load_scene(path), root / "t", seed=1)
    pillar = {"type": "pillar", "center": [2.0, 0.0], "size": [0.3, 0.3], "height": 2.5}
    blocked = corridor(root, project_root, "blocked.yaml", route, [pillar])
    return root, path, blocked, taught


def test_playback_ends_at_an_obstacle_on_the_route_and_logs_the_contact(taught_corridor):
    """The taught route, played back in the copy with a pillar on it: the run ends at the
    pillar's face (x = 1.85), not reached; the control, the same run in the taught scene,
    reaches the goal."""
    root, path, blocked, taught = taught_corridor
    maps = load_map(taught.maps["band"])
    config = PlaybackConfig(particles=200, seed=2)
    log = root / "blocked.mcap"
    result = playback(
        load_scene(blocked, "playback"), maps, taught.marks, config, log=log,
        taught_scene=taught.scene, variant="pillar",
    )  # fmt: skip
    assert result.collision is not None and not result.reached
    assert result.collision.hit == "obstacle"
    assert 1.85 - 0.05 <= result.collision.contact[0] <= 1.85 + 0.05
    assert result.stop_true[0] + 0.525 == pytest.approx(1.85, abs=0.1)  # the contact pose
    assert result.truth[-1, 0] < 1.5  # nowhere near the goal at x = 3
    logged = list(read_run(log).messages("/collision"))
    assert len(logged) == 1 and logged[0][1]["contact"] == list(result.collision.contact)
    # the picture: the contact's cross between P1 and P2's squares, where the pillar's face is
    picture = render_playback(result, maps, taught.marks, root / "blocked.png")
    image = rgb(picture)
    squares = [c for c, size in blobs(image, (255, 127, 14)) if max(size) < 20]
    row = np.median([c[1] for c in squares])
    p0, p1, p2 = sorted(c[0] for c in squares if abs(c[1] - row) < 15)  # not the legend's
    crosses = [c for c, _ in blobs(image, (214, 39, 40), tol=30) if abs(c[1] - row) < 15]
    assert len(crosses) == 1
    x0, x1, x2 = (m["x"] for m in taught.marks)
    scale = (p2 - p0) / (x2 - x0)  # pixels per metre, from the squares' places
    assert p1 == pytest.approx(p0 + scale * (x1 - x0), abs=2)
    at = x1 + (crosses[0][0] - p1) / scale
    assert at == pytest.approx(result.collision.contact[0], abs=0.05)
    control = playback(
        load_scene(path, "playback"), maps, taught.marks, config, taught_scene=taught.scene
    )
    assert control.collision is None and control.reached


def test_the_playback_command_prints_the_contact(taught_corridor, monkeypatch, capsys):
    root, _, blocked, _ = taught_corridor
    monkeypatch.chdir(root)
    status, out, err = kiseki(
        monkeypatch, capsys, "playback", blocked, "--taught", "t", "--route", "P0,P1,P2",
        "--variant", "pillar", "--plot", "cli.png",
    )  # fmt: skip
    assert status == 0, err
    assert rgb(root / "cli.png").shape[2] == 3 and "picture in cli.png" in out
    text = " ".join(out.split())
    assert "goal reached: False" in text
    assert "COLLISION at t = " in text and ": robot hit obstacle at (1.8" in text
    assert "the run ended there" in text


def test_the_playback_and_serve_commands_call_a_folder_given_as_a_scene_a_folder(
    taught_corridor, monkeypatch, capsys
):
    """They read 'scene file not found' of a folder that is there."""
    root, *_ = taught_corridor
    monkeypatch.chdir(root)
    (root / "sub").mkdir(exist_ok=True)
    playback = ("playback", "sub", "--taught", "t", "--route", "P0,P2")
    for command in (playback, ("serve", "--taught", "t", "--scene", "sub")):
        status, _, err = kiseki(monkeypatch, capsys, *command)
        assert status == 1 and err.strip() == "kiseki: error: sub: a folder, not a scene file", (
            command
        )


def test_teaching_and_playback_refuse_a_scene_with_pedestrians(tmp_path, project_root):
    """Neither simulates them (their cameras would not see them, their logs would not hold
    them): teaching drove through a standing pedestrian, playback ended on one it never saw."""
    anna = {"name": "anna", "start": [2.0, 0.0], "velocity": [0.0, 0.0]}
    path = corridor(tmp_path, project_root, "c.yaml", [(0.0, 0.0), (3.0, 0.0)])
    doc = yaml.safe_load(path.read_text())
    doc["pedestrians"] = [anna]
    path.write_text(yaml.safe_dump(doc, sort_keys=False))
    expected = (
        f"{path}: {{}} does not simulate the scene's pedestrians (anna): remove them for it "
        "(kiseki sim run simulates them)"
    )
    with pytest.raises(ValueError) as err:
        teach(load_scene(path), tmp_path / "t")
    assert str(err.value) == expected.format("teaching") and not (tmp_path / "t").exists()
    marks = [
        {"id": i, "name": f"P{i}", "x": x, "y": 0.0, "theta": 0.0} for i, x in enumerate((0.0, 3.0))
    ]
    with pytest.raises(ValueError) as err:
        playback(load_scene(path, "playback"), OccupancyGrid(80, 80, 0.1), marks)
    assert str(err.value) == expected.format("playback")
