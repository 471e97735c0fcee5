# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""A scene's ``route`` (kiseki.sim.scene_schema.Route): a bad route is refused when the scene is
loaded, naming the file, the field and the value; the names a scene takes are the names a
waypoint file takes, so what ``kiseki teach`` writes from them the waypoint reader reads."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from kiseki._support.schema import SchemaError, parse
from kiseki.apps.teach import teach
from kiseki.sim.scene import load_scene
from kiseki.teach.waypoint_schema import WaypointFile, read_waypoint_file

SCENE = """\
bounds: {{min: [-5, -5, -0.1], max: [5, 5, 3]}}
objects: [{{type: pillar, center: [3, 3], size: [0.2, 0.2]}}]
route:
  waypoints: [[0, 0], [1, 0], [2, 0]]
  {key}: {value}
"""


def load_error(tmp_path: Path, text: str) -> str:
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    with pytest.raises(SchemaError) as info:
        load_scene(path)
    message = str(info.value)
    assert message.startswith(f"{path}: ") and "\n" not in message
    return message.removeprefix(f"{path}: ")


@pytest.mark.parametrize(
    ("key", "value", "expected"),
    [
        ("speed", ".nan", "route.speed: must be a finite number, got nan"),
        ("speed", "fast", "route.speed: must be a valid number, got 'fast'"),
        ("speed", "1e300", "route.speed: must be less than or equal to 5, got 1e+300"),
        ("speed", "0", "route.speed: must be greater than 0, got 0"),
        ("bogus", "1", "route.bogus: unknown key"),
        ("names", "[P0, P0, P2]", "route.names[1]: waypoint names must be unique, got 'P0'"),
        ("names", "[P0, P1]", "route.names: must give one name per waypoint (3), got ['P0', 'P1']"),
        ("names", "[P0, 1, P2]", "route.names[1]: must be a valid string, got 1"),
        ("names", f"[P0, {'x' * 65}, P2]", "route.names[1]: string should have at most 64 "),
    ],
)
def test_a_bad_route_is_refused_at_load_with_its_field_and_value(tmp_path, key, value, expected):
    assert load_error(tmp_path, SCENE.format(key=key, value=value)).startswith(expected)


@pytest.mark.parametrize(
    ("waypoints", "expected"),
    [
        ("[[.nan, 0], [1, 0]]", "route.waypoints[0][0]: must be a finite number, got nan"),
        ("[[0, 0]]", "route.waypoints: list should have at least 2 items"),
        ("[[0, 0], [0, 0], [1, 0]]", "route.waypoints[1]: consecutive waypoints must differ"),
        ("[[0, 0], [1, 0, 0]]", "route.waypoints[1]: tuple should have at most 2 items"),
    ],
)
def test_bad_waypoints_are_refused_at_load(tmp_path, waypoints, expected):
    text = SCENE.replace("[[0, 0], [1, 0], [2, 0]]", waypoints).format(key="speed", value=0.5)
    assert load_error(tmp_path, text).startswith(expected)


def test_the_multi_robot_form_names_the_robot(tmp_path):
    text = """\
bounds: {min: [-5, -5, -0.1], max: [5, 5, 3]}
objects: [{type: pillar, center: [3, 3], size: [0.2, 0.2]}]
robots:
  - {name: a, route: {waypoints: [[0, 0], [1, 0]]}}
  - {name: b, route: {waypoints: [[0, 1], [1, 1]], speed: -1}}
"""
    assert load_error(tmp_path, text) == "robots[1].route.speed: must be greater than 0, got -1"


def _waypoint_file_takes(names: list) -> bool:
    marks = [{"name": n, "x": float(i), "y": 0.0, "theta": 0.0} for i, n in enumerate(names)]
    try:
        parse(WaypointFile, {"maps": {}, "waypoints": marks}, "waypoints.yaml")
    except SchemaError:
        return False
    return True


@pytest.mark.parametrize(
    "names",
    [
        ["P0", "P1", "P2"],
        ["Cell A", "x" * 64, "終点"],
        ["P0", "P0", "P2"],
        ["P0", "", "P2"],
        ["P0", "x" * 65, "P2"],
        ["P0", 7, "P2"],
    ],
)
def test_a_scene_takes_the_names_a_waypoint_file_takes(tmp_path, names):
    doc = yaml.safe_load(SCENE.format(key="speed", value=0.5))
    doc["route"]["names"] = names
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(doc, allow_unicode=True))
    try:
        load_scene(path)
        taken = True
    except SchemaError:
        taken = False
    assert taken == _waypoint_file_takes(names)


def test_teaching_a_scenes_names_writes_a_waypoint_file_the_reader_takes(tmp_path, project_root):
    doc = yaml.safe_load((project_root / "data" / "worlds" / "factory_corridor.yaml").read_text())
    names = ["Cell A", "x" * 64, "終点"]
    doc["route"] = {"waypoints": [[0.0, 0.0], [1.5, 0.0], [3.0, 0.0]], "names": names}
    scene = tmp_path / "corridor.yaml"
    scene.write_text(yaml.safe_dump(doc, allow_unicode=True))
    teach(load_scene(scene), tmp_path / "t", seed=1)
    marks = read_waypoint_file(tmp_path / "t" / "waypoints.yaml").waypoints
    assert [w.name for w in marks] == names


def test_sim_refuses_a_route_out_of_bounds_and_sideways_commands_to_a_differential_robot(tmp_path):
    """sim run drove a route to a waypoint 1,300 m outside the scene (teach refused it); a
    t,vx,vy,w script on a differential robot lost its vy column without a word."""
    import numpy as np

    from kiseki.sim.run import SimConfig, simulate

    text = SCENE.format(key="speed", value=0.5)
    far = tmp_path / "far.yaml"
    far.write_text(text.replace("[2, 0]]", "[1300, 0]]"))
    with pytest.raises(ValueError) as caught:
        simulate(load_scene(far), tmp_path / "run.mcap", SimConfig(max_duration=1.0))
    assert str(caught.value) == (
        f"{far}: route waypoint W2 [1300.0, 0.0] lies outside the scene's bounds x -5..5, y -5..5"
    )
    here = tmp_path / "here.yaml"
    here.write_text(text)
    sideways = np.array([[0.0, 0.3, 0.0, 0.0], [1.0, 0.0, 0.2, 0.0]])
    with pytest.raises(ValueError, match="row 2 asks for vy = 0.2 m/s"):
        simulate(load_scene(here), tmp_path / "run.mcap", SimConfig(max_duration=1.0), sideways)
    assert not (tmp_path / "run.mcap").exists()
