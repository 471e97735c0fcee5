# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The waypoint file's model (kiseki.teach.waypoint_schema): a file as kiseki teach writes it
reads to the marks it was written from, hand edits that are still valid keep reading, and every
problem is one line naming the file, the field, the value (and the waypoint), limits with the
limit."""

from __future__ import annotations

import hashlib

import pytest
import yaml

from kiseki._support.schema import SchemaError, parse
from kiseki.apps.teach.taught_route import load_route
from kiseki.grid import OccupancyGrid
from kiseki.io.ros_map import save_map
from kiseki.teach.scene_identity import TaughtScene, taught_scene_of
from kiseki.teach.waypoint_schema import (
    MAX_BANDS,
    MAX_NAME_LENGTH,
    MAX_WAYPOINTS,
    WaypointFile,
    read_waypoint_file,
)

MARKS = [
    {"id": 0, "name": "P0", "x": 0.0, "y": -0.01, "theta": 0.002, "truth": [0.0, 0.0, 0.0]},
    {"id": 1, "name": "P1", "x": 2.5, "y": 0.125, "theta": -0.5, "truth": [2.51, 0.1, -0.49]},
    {"id": 2, "name": "P2", "x": 5.0, "y": 1e-7, "theta": 3.1, "truth": [5.0, 0.0, 3.14]},
]


def _sha1(path) -> str:
    return hashlib.sha1(path.read_bytes()).hexdigest()


def _taught(tmp_path, marks=MARKS, **extra) -> tuple:
    """A teaching folder as kiseki teach writes it: the band map and the waypoint file."""
    map_yaml = save_map(OccupancyGrid(60, 30, 0.1), tmp_path / "map_band.yaml")
    image = tmp_path / yaml.safe_load(map_yaml.read_text())["image"]
    doc = {
        "log": "teach.mcap",
        "merge": "thesis",
        "scene_file": "data/worlds/factory_corridor.yaml",
        "scene_sha1": "ab" * 20,
        "maps": {"band": {"file": "map_band.yaml", "image_sha1": _sha1(image)}},
        "waypoints": marks,
        **extra,
    }
    path = tmp_path / "waypoints.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False))
    return path, doc


def test_a_taught_file_reads_to_the_marks_it_was_written_from(tmp_path):
    path, doc = _taught(tmp_path)
    map_path, route = load_route(path, "band", ["P0", "P2", "P1"])
    assert map_path == tmp_path / "map_band.yaml"
    assert route == [MARKS[0], MARKS[2], MARKS[1]]  # the old reader returned these dicts
    assert all(type(w["truth"]) is list and type(w["x"]) is float for w in route)
    assert taught_scene_of(path) == TaughtScene(doc["scene_file"], doc["scene_sha1"], str(tmp_path))


def test_valid_hand_edits_keep_reading(tmp_path):
    marks = [
        {"name": "A", "x": 0, "y": 0, "theta": 0},  # no id, no truth, ints
        {"name": "B", "x": 1, "y": 2.0, "theta": 0.5, "truth": None},  # an emptied truth
    ]
    path, _ = _taught(tmp_path, marks)
    text = path.read_text().replace("theta: 0.5", "theta: 5e-1")  # YAML 1.2: a number
    path.write_text(text)
    _, route = load_route(path, "band", ["A", "B"])
    assert route == [
        {"name": "A", "x": 0.0, "y": 0.0, "theta": 0.0},
        {"name": "B", "x": 1.0, "y": 2.0, "theta": 0.5},  # no 'truth' key: playback skips it
    ]
    older = {k: v for k, v in yaml.safe_load(text).items() if k not in ("scene_file", "scene_sha1")}
    path.write_text(yaml.safe_dump(older))
    assert taught_scene_of(path) is None  # no scene recorded, no log beside it


def _problem(tmp_path, change) -> str:
    doc = yaml.safe_load(yaml.safe_dump(_taught(tmp_path)[1]))
    change(doc)
    path = tmp_path / "edited.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False))
    with pytest.raises(SchemaError) as err:
        read_waypoint_file(path)
    text = str(err.value)
    assert text.startswith(f"{path}: ") and "\n" not in text
    return text[len(f"{path}: ") :]


@pytest.mark.parametrize(
    ("change", "expected"),
    [
        (
            lambda d: d["waypoints"][1].update(y=float("nan")),
            "waypoints[1].y: must be a finite number, got nan (waypoint 'P1')",
        ),
        (
            lambda d: d["waypoints"][2].update(theta=True),
            "waypoints[2].theta: must be a valid number, got True (waypoint 'P2')",
        ),
        (
            lambda d: d["waypoints"][0].update(truth=[0.0, "0", 0.0]),
            "waypoints[0].truth[1]: must be a valid number, got '0' (waypoint 'P0')",
        ),
        (
            lambda d: d["waypoints"][1].update(colour="red"),
            "waypoints[1].colour: unknown key (waypoint 'P1')",
        ),
        (
            lambda d: d["waypoints"][1].update(name=7),
            "waypoints[1].name: must be a valid string, got 7",
        ),
        (
            lambda d: d["waypoints"][2].update(id=-1),
            "waypoints[2].id: must be greater than or equal to 0, got -1 (waypoint 'P2')",
        ),
        (lambda d: d.update(note="hi"), "note: unknown key"),
        (lambda d: d.pop("maps"), "maps: missing"),
        (
            lambda d: d.update(scene_sha1="xyz"),
            "scene_sha1: must be a SHA-1 (40 lower-case hex digits), got 'xyz'",
        ),
        (
            lambda d: d["maps"]["band"].update(image_sha1=None),
            "maps.band.image_sha1: must be a valid string, got None",
        ),
        (
            lambda d: d["maps"]["band"].update(resolution=0.1, origin=[0.0, 0.0]),
            "maps.band.origin[2]: missing",
        ),
    ],
)
def test_a_wrong_value_is_named_by_its_path(tmp_path, change, expected):
    assert _problem(tmp_path, change) == expected


def test_a_map_s_geometry_is_recorded_whole_or_not_at_all(tmp_path):
    """One of resolution and origin alone made playback fail on None (a traceback)."""
    for field, value in (("origin", [0.0, 0.0, 0.0]), ("resolution", 0.1)):
        problem = _problem(tmp_path, lambda d, f=field, v=value: d["maps"]["band"].update({f: v}))
        assert problem.startswith(
            "maps.band: resolution and origin are recorded together (or neither), got {"
        )


def test_every_problem_is_kept(tmp_path):
    def change(doc):
        doc["waypoints"][0]["x"] = "a"
        doc["waypoints"][2]["y"] = "b"

    assert _problem(tmp_path, change).endswith("(waypoint 'P0') (and 1 more)")


def _doc(n: int = 2, bands: int = 1, name: str = "P") -> dict:
    return {
        "maps": {f"b{i}": {"file": f"m{i}.yaml", "image_sha1": "0" * 40} for i in range(bands)},
        "waypoints": [{"name": f"{name}{i}", "x": 0.0, "y": 0.0, "theta": 0.0} for i in range(n)],
    }


@pytest.mark.parametrize(
    ("doc", "expected"),
    [
        (_doc(MAX_WAYPOINTS + 1), f"waypoints: list should have at most {MAX_WAYPOINTS} items"),
        (_doc(bands=MAX_BANDS + 1), f"maps: dictionary should have at most {MAX_BANDS} items"),
        (_doc(name="x" * MAX_NAME_LENGTH), f"at most {MAX_NAME_LENGTH} characters"),
    ],
)
def test_limits_are_enforced_with_the_limit_in_the_message(doc, expected):
    with pytest.raises(SchemaError, match=f"^w.yaml: .*{expected}"):
        parse(WaypointFile, doc, "w.yaml")


def test_the_limits_themselves_are_accepted():
    read = parse(WaypointFile, _doc(MAX_WAYPOINTS, MAX_BANDS), "w.yaml")
    assert len(read.waypoints) == MAX_WAYPOINTS and len(read.maps) == MAX_BANDS
    long = parse(WaypointFile, _doc(1, name="x" * (MAX_NAME_LENGTH - 1)), "w.yaml")
    assert len(long.waypoints[0].name) == MAX_NAME_LENGTH
