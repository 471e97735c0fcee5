# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The scene file's models (kiseki.sim.scene_schema, kiseki.sim.primitives_schema): the
project's worlds read to the boxes they read to before the models, each primitive expands to its
closed-form boxes, every limit is enforced with the limit in the message, and wrong types, NaNs
and unknown keys are named with their path."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

import kiseki.sim.scene as scene_module
from kiseki._support.schema import SchemaError
from kiseki.sim.primitives import expand
from kiseki.sim.scene import load_scene

WORLDS = Path(__file__).resolve().parents[3] / "data" / "worlds"

# (boxes, fingerprint) of each world and variant, recorded with the hand-written validators the
# models replaced (kiseki before issue 17 item 2): the fingerprint weighs every number of every
# box (centre, half size, rotation) by its box's index and column, so a changed, missing or
# reordered box changes it
RECORDED = {
    ("coop_three_robots", "teach"): (2, 256.20000000000005),
    ("factory_corridor", "teach"): (50, 60623.1779038078),
    ("factory_turn", "teach"): (57, 73108.07790531844),
    ("magnetic_floor", "teach"): (35, 56167.95),
    ("magnetic_hall", "teach"): (6, 1227.15),
    ("magnetic_lidar_path", "teach"): (15, 17390.0),  # added after the models (issue 11)
    ("magnetic_path", "teach"): (13, 16545.4),
    ("magnetic_path", "playback"): (11, 12497.138290724795),
    ("rubble_a", "teach"): (59, 52562.36895365919),
    ("rubble_b", "teach"): (14, 3192.369250646363),
    ("speed_corner", "teach"): (5, 814.45),
    ("speed_corridor", "teach"): (8, 2617.075),
    ("speed_crossroad", "teach"): (9, 3061.3),
    ("speed_crossroad", "playback"): (10, 3597.7),
    ("terrain_corridor", "teach"): (12, 4016.297543298578),  # added after the models (issue 13)
}


def fingerprint(scene) -> tuple[int, float]:
    c, h, r = scene.boxes.arrays()
    n = len(c)
    values = np.hstack([c, h, r.reshape(n, 9)])
    weights = np.arange(1, n + 1)[:, None] * np.arange(1, 16)[None, :]
    return n, float(np.sum(weights * values))


def test_every_world_reads_to_the_boxes_recorded_before_the_models():
    worlds = sorted(p.stem for p in WORLDS.glob("*.yaml"))
    assert worlds == sorted({w for w, _ in RECORDED})  # a new world gets its line here
    for world in worlds:
        for variant in ("teach", "playback"):
            n, fp = RECORDED.get((world, variant), RECORDED[(world, "teach")])
            got = fingerprint(load_scene(WORLDS / f"{world}.yaml", variant))
            assert got[0] == n and got[1] == pytest.approx(fp, rel=1e-12), (world, variant)


def write(tmp_path: Path, doc: dict, name: str = "scene.yaml") -> Path:
    path = tmp_path / name
    path.write_text(yaml.safe_dump(doc))
    return path


def base(**keys) -> dict:
    doc = {
        "bounds": {"min": [-5, -5, -0.1], "max": [5, 5, 3]},
        "objects": [{"type": "pillar", "center": [3, 3], "size": [0.2, 0.2]}],
    }
    doc.update(keys)
    return doc


def boxes(spec: dict) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    c, h, r = expand(spec, "t.yaml").arrays()
    return list(zip(c, h, r, strict=True))


def yaw(deg: float) -> np.ndarray:
    a = math.radians(deg)
    return np.array([[math.cos(a), -math.sin(a), 0], [math.sin(a), math.cos(a), 0], [0, 0, 1]])


def test_each_primitive_expands_to_its_closed_form_boxes():
    ((c, h, r),) = boxes({"type": "wall", "from": [0, 0], "to": [0, 4], "height": 2, "z": 0.5})
    np.testing.assert_allclose(c, [0, 2, 1.5])
    np.testing.assert_allclose(h, [2, 0.05, 1])
    np.testing.assert_allclose(r, yaw(90), atol=1e-15)
    ((c, h, _),) = boxes({"type": "box", "center": [1, 2], "size": [0.4, 0.6, 1.0]})
    np.testing.assert_allclose(c, [1, 2, 0.5])  # two numbers: standing on the floor
    np.testing.assert_allclose(h, [0.2, 0.3, 0.5])
    ((c, _, r),) = boxes({"type": "box", "center": [1, 2, 3], "size": [1, 1, 1], "yaw": 30})
    np.testing.assert_allclose(c, [1, 2, 3])
    np.testing.assert_allclose(r, yaw(30), atol=1e-15)
    bench = boxes({"type": "workbench", "center": [0, 0], "size": [2, 1], "height": 0.8})
    assert len(bench) == 5  # the top and four legs
    np.testing.assert_allclose(bench[0][0], [0, 0, 0.78])
    legs = sorted(tuple(b[0][:2]) for b in bench[1:])
    corners = [(-0.975, -0.475), (-0.975, 0.475), (0.975, -0.475), (0.975, 0.475)]
    np.testing.assert_allclose(legs, corners)
    shelf = {"type": "shelf", "center": [0, 0], "size": [1, 0.4], "levels": 5, "items": 3}
    assert len(boxes(shelf)) == 4 + 5 + 3 * 4  # posts, boards, items on all but the top
    assert len(boxes({**shelf, "levels": 1})) == 4 + 1 + 3  # items on the only board
    ((c, h, _),) = boxes({"type": "slope", "center": [0, 0], "size": [3, 1], "rise": 4})
    np.testing.assert_allclose([c[2], h[0]], [2, 2.5])  # hypot(3, 4) / 2
    ((c, h, _),) = boxes({"type": "beam", "from": [0, 0], "to": [2, 0], "size": [0.2, 0.3], "z": 2})
    np.testing.assert_allclose(np.hstack([c, h]), [1, 0, 2, 1, 0.1, 0.15])
    rubble = boxes({"type": "rubble", "center": [1, 1], "radius": 0.5, "count": 7, "seed": 3})
    assert len(rubble) == 7
    assert all(math.dist(c[:2], (1, 1)) <= 0.5 for c, _, _ in rubble)
    again = boxes({"type": "rubble", "center": [1, 1], "radius": 0.5, "count": 7, "seed": 3})
    np.testing.assert_array_equal([b[0] for b in rubble], [b[0] for b in again])  # seeded


@pytest.mark.parametrize(
    ("objects", "match"),
    [
        ([{"type": "shelf", "center": [0, 0], "size": [1, 0.4], "levels": 51}],
         r"objects\[0\]\.levels: must be less than or equal to 50, got 51"),
        ([{"type": "shelf", "center": [0, 0], "size": [1, 0.4], "items": 101}],
         r"objects\[0\]\.items: must be less than or equal to 100, got 101"),
        ([{"type": "rubble", "center": [0, 0], "radius": 1, "count": 100_001}],
         r"objects\[0\]\.count: must be less than or equal to 100000, got 100001"),
        ([{"type": "rubble", "center": [0, 0], "radius": 1, "count": 100_000}] * 2 + [
          {"type": "shelf", "center": [0, 0], "size": [1, 0.4], "levels": 50, "items": 100}],
         r"objects: make 204,954 boxes, more than the limit of 200,000 boxes"),
    ],
)  # fmt: skip
def test_object_limits_are_enforced_before_anything_is_built(tmp_path, monkeypatch, objects, match):
    def never(_obj):
        raise AssertionError("a box was built")

    monkeypatch.setattr(scene_module, "boxes_of", never)
    with pytest.raises(SchemaError, match=match) as info:
        load_scene(write(tmp_path, base(objects=objects)))
    assert str(tmp_path / "scene.yaml") in str(info.value)


def test_objects_at_their_limits_are_taken(tmp_path):
    shelf = {"type": "shelf", "center": [0, 0], "size": [1, 0.4], "levels": 50, "items": 100}
    scene = load_scene(write(tmp_path, base(objects=[shelf])))
    assert len(scene.boxes.centers) == 4 + 50 + 100 * 49


def scene_line(doc: dict, tmp_path: Path) -> str:
    with pytest.raises(SchemaError) as info:
        load_scene(write(tmp_path, doc, "bad.yaml"))
    text = str(info.value)
    assert text.startswith(f"{tmp_path / 'bad.yaml'}: ") and "\n" not in text
    return text.removeprefix(f"{tmp_path / 'bad.yaml'}: ")


def robots(n: int) -> list[dict]:
    return [{"name": f"r{i}", "start": [0, i * 0.1, 0]} for i in range(n)]


MOVE = {"robot": "r0", "to": [1, 1]}
POSES = {"corner": [0, 0], "distance": 1, "heading_deg": 0}
WALKER = {"start": [0, 0], "velocity": [1, 0]}


@pytest.mark.parametrize(
    ("doc", "expected"),
    [
        (base(grid_resolution=1e-6), "grid_resolution: resolution 1e-06 m makes a map of "
         "10000000 x 10000000 cells over 10 x 10 m: more than the limit of 1e+08 cells, got 1e-06"),
        ({"objects": base()["objects"], "grid_resolution": 1e-6},  # the world's own bounds
         "grid_resolution: resolution 1e-06 m makes a map of 200001 x 200001 cells over "
         "0.2 x 0.2 m: more than the limit of 1e+08 cells, got 1e-06"),
        (base(magnetic={}, measurement_grid={"lower": [0, 0, 0], "upper": [4, 4, 1],
                                             "spacing": 0.01}),
         "measurement_grid: 16,240,901 points, more than 10,000,000"),
        (base(robots=robots(101)), "robots: list should have at most 100 items"),
        (base(pedestrians=[{**WALKER, "name": f"p{i}"} for i in range(1001)]),
         "pedestrians: list should have at most 1000 items"),
        (base(robots=robots(1), turns={"goal": [1, 1], "moves": [MOVE] * 10_001}),
         "turns.moves: list should have at most 10000 items"),
        (base(robots=robots(1), turns={"goal": [1, 1], "speed": 5.5, "moves": [MOVE]}),
         "turns.speed: must be less than or equal to 5, got 5.5"),
        (base(poses={**POSES, "phi_deg": [0, 10_000, 1]}),
         "poses.phi_deg: must give at most 10,000 poses, got [0, 10000, 1]"),
    ],
)  # fmt: skip
def test_scene_limits_are_stated_in_the_message(tmp_path, doc, expected):
    assert scene_line(doc, tmp_path).startswith(expected)


def test_scene_values_at_their_limits_are_taken(tmp_path):
    doc = base(robots=robots(100), turns={"goal": [1, 1], "speed": 5, "moves": [MOVE] * 10_000},
               poses={**POSES, "phi_deg": [0, 9999, 1]})  # fmt: skip
    scene = load_scene(write(tmp_path, doc))
    assert len(scene.robot_specs) == 100 and len(scene.turns["moves"]) == 10_000
    assert len(scene.poses) == 10_000 and scene.turns["speed"] == 5.0


@pytest.mark.parametrize(
    ("seed", "ok"), [(0, True), (2**64 - 1, True), (2**64, False), (-1, False), (1.0, False)]
)
def test_object_seeds_are_integers_below_2_to_the_64(tmp_path, seed, ok):
    doc = base(
        objects=[{"type": "rubble", "center": [0, 0], "radius": 1, "count": 2, "seed": seed}]
    )
    if ok:
        assert len(load_scene(write(tmp_path, doc)).boxes.centers) == 2
    else:
        line = scene_line(doc, tmp_path)
        assert line == f"objects[0].seed: must be an integer in [0, 2**64), got {seed!r}"


@pytest.mark.parametrize(
    ("edit", "expected"),
    [
        (lambda d: d["objects"][0].update(height=float("nan")),
         "objects[0].height: must be a finite number, got nan"),
        (lambda d: d["objects"].append({"type": "wall", "from": [0, 0], "to": [1, float("inf")]}),
         "objects[1].to[1]: must be a finite number, got inf"),
        (lambda d: d["objects"][0].update(size=["0.2", 0.2]),
         "objects[0].size[0]: must be a valid number, got '0.2'"),
        (lambda d: d["objects"][0].update(colour="red"), "objects[0].colour: unknown key"),
        (lambda d: d["objects"].append({"type": "teapot"}), "objects[1]: unknown type 'teapot'"),
        (lambda d: d["objects"].append({"type": "wall", "from": [1, 1], "to": [1, 1]}),
         "objects[1]: 'from' and 'to' must differ"),
        (lambda d: d.update(grid_resolution="0.05"), "grid_resolution: must be a valid number"),
        (lambda d: d.update(floor=1), "floor: must be a valid boolean, got 1"),
        (lambda d: d.update(robots=[{"name": "a", "colour": "red"}]),
         "robots[0].colour: unknown key"),
        (lambda d: d.update(robots=[{"name": "a"}, {"name": "a"}]),
         "robots[1].name: robot names must be unique, got 'a'"),
        (lambda d: d.update(pedestrians=[{**WALKER, "name": "p", "radius": True}]),
         "pedestrians[0].radius: must be a valid number, got True"),
        (lambda d: d.update(pedestrians=[{**WALKER, "name": "p", "start_time": -1}]),
         "pedestrians[0].start_time: must be greater than or equal to 0, got -1"),
        (lambda d: d.update(robots=robots(1), turns={"goal": [1, 1], "moves": [
            {"robot": "r0", "to": [1, math.nan]}]}),
         "turns.moves[0].to[1]: must be a finite number, got nan"),
        (lambda d: d.update(robots=robots(2), turns={"goal": [1, 1], "moves": [
            {"robot": "r9", "to": [1, 1]}]}),
         "turns.moves[0].robot: must be one of the scene's robots (r0, r1), got 'r9'"),
        (lambda d: d.update(robots=robots(1), turns={"goal": [1, 1], "moves": [
            {"robot": "r0", "to": [1, 2]}]}),
         "turns.moves[0].to: the last move must end on the goal [1.0, 1.0], got [1.0, 2.0]"),
    ],
)  # fmt: skip
def test_wrong_values_are_named_with_their_path(tmp_path, edit, expected):
    doc = base()
    edit(doc)
    assert scene_line(doc, tmp_path).startswith(expected)


@pytest.mark.parametrize(
    ("doc", "expected"),
    [
        (base(point_robots=True), "point_robots: applies only to a scene with 'robots'"),
        (base(measurement_grid={"lower": [0, 0, 0], "upper": [1, 1, 0], "spacing": 0.5}),
         "measurement_grid: applies only to a scene with 'magnetic'"),
        (base(robots=robots(1), route={"waypoints": [[0, 0], [1, 0]]}),
         "route: give 'robots' or this, not both"),
        (base(robots=[{**robots(1)[0], "route": {"waypoints": [[0, 0], [1, 1]]}}],
              turns={"goal": [1, 1], "moves": [MOVE]}),
         "turns: a scene with 'turns' gives its robots no routes"),
        ({**base(floor=True), "bounds": None}, "floor: 'floor: true' needs 'bounds'"),
    ],
)  # fmt: skip
def test_options_that_do_not_apply_are_errors(tmp_path, doc, expected):
    assert scene_line(doc, tmp_path).startswith(expected)


BEARING = {"type": "bearing", "targets": ["b"]}


def test_a_valid_document_reads_to_its_values(tmp_path):
    doc = base(
        name="t",
        floor=True,
        grid_resolution=0.1,
        robots=[{"name": "a", "type": "omni", "start": [0, 0, 0], "sensors": [BEARING]},
                {"name": "b", "start": [1, 0, 0]}],
        turns={"goal": [2, 2],
               "moves": [{"robot": "b", "to": [1, 1]}, {"robot": "a", "to": [2, 2]}]},
        poses={**POSES, "phi_deg": [0, 90, 45]},
        pedestrians=[{**WALKER, "name": "p", "stop_after": 2}],
    )  # fmt: skip
    scene = load_scene(write(tmp_path, doc))
    assert scene.name == "t" and scene.grid_resolution == 0.1
    assert scene.robot_specs == [
        {"name": "a", "robot": {"type": "omni", "start": [0, 0, 0]}, "sensors": [BEARING],
         "route": {}},
        {"name": "b", "robot": {"start": [1, 0, 0]}, "sensors": [], "route": {}},
    ]  # fmt: skip
    assert scene.turns == {"goal": (2.0, 2.0), "speed": 0.3,
                           "moves": [("b", (1.0, 1.0)), ("a", (2.0, 2.0))]}  # fmt: skip
    s = math.sqrt(0.5)  # corner + distance * (-cos phi, -sin phi), phi = 0, 45, 90 deg
    np.testing.assert_allclose(scene.poses, [(-1, 0, 0), (-s, -s, 0), (0, -1, 0)], atol=1e-12)
    (walker,) = scene.pedestrians
    assert (walker.start, walker.velocity, walker.radius, walker.stop_after) == (
        (0.0, 0.0), (1.0, 0.0), 0.25, 2.0)  # fmt: skip
    floor = scene.boxes.arrays()
    np.testing.assert_allclose([floor[0][-1], floor[1][-1]], [[0, 0, -0.05], [5, 5, 0.05]])
