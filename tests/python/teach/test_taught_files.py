# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The files a taught run is read from outside kiseki teach: ``kiseki serve``'s waypoint file
(kiseki.serve.taught) and the map YAML a waypoint file is tied to (``--map`` of playback) are
read through their models: a valid file reads as before, a hand-edited bad one is refused in
one line naming the file, the field and the value."""

from __future__ import annotations

import copy
import hashlib

import pytest
import yaml

from kiseki.apps.teach.taught_route import load_route, waypoints_file_hash
from kiseki.errors import MapFormatError
from kiseki.grid import OccupancyGrid
from kiseki.io.ros_map import save_map
from kiseki.serve.taught import TaughtRun, taught_scene

MARKS = [
    {"id": 0, "name": "P0", "x": 0.0, "y": -0.5, "theta": 0.25},
    {"id": 1, "name": "P1", "x": 2.5, "y": 0.125, "theta": -0.5, "truth": [2.5, 0.1, -0.5]},
]


def _taught(folder, marks=MARKS) -> tuple:
    """A teaching folder as kiseki teach writes it (no log: no scene recorded)."""
    map_yaml = save_map(OccupancyGrid(40, 20, 0.1), folder / "map_band.yaml")
    image = folder / yaml.safe_load(map_yaml.read_text())["image"]
    doc = {
        "merge": "thesis",
        "maps": {"band": {"file": "map_band.yaml", "image_sha1": _sha1(image)}},
        "waypoints": copy.deepcopy(marks),
    }
    path = folder / "waypoints.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False))
    return path, doc


def _sha1(path) -> str:
    return hashlib.sha1(path.read_bytes()).hexdigest()


def test_serve_reads_a_valid_waypoint_file_as_before(tmp_path):
    path, doc = _taught(tmp_path)
    run = TaughtRun(tmp_path, "both")
    assert run.waypoints == MARKS and run.by_name("P1") == MARKS[1]
    assert run.map_path == tmp_path / "map_band.yaml"
    assert taught_scene(tmp_path) is None  # no teaching log beside it
    assert run.rename("P0", "Cell A") == {"id": 0, "name": "Cell A", "x": 0.0, "y": -0.5}
    now = yaml.safe_load(path.read_text())
    assert now == {**doc, "waypoints": [{**MARKS[0], "name": "Cell A"}, MARKS[1]]}
    assert [w["name"] for w in run.public()["waypoints"]] == ["Cell A", "P1"]


@pytest.mark.parametrize(
    ("edit", "problem"),
    [
        (
            lambda d: d["waypoints"][1].update(x="abc"),
            "waypoints[1].x: must be a valid number, got 'abc' (waypoint 'P1')",
        ),
        (
            lambda d: d["waypoints"][0].update(theta=float("nan")),
            "waypoints[0].theta: must be a finite number, got nan (waypoint 'P0')",
        ),
        (lambda d: d.update(log=7), "log: must be a valid string, got 7"),
        (lambda d: d["waypoints"][1].update(name="P0"), "waypoint names must be unique (P0"),
        (lambda d: d["waypoints"][0].pop("y"), "waypoints[0].y: missing (waypoint 'P0')"),
    ],
)
def test_serve_refuses_a_bad_waypoint_file_naming_the_field_and_value(tmp_path, edit, problem):
    path, doc = _taught(tmp_path)
    edit(doc)
    path.write_text(yaml.safe_dump(doc, sort_keys=False))
    for read in (lambda: TaughtRun(tmp_path, "both"), lambda: taught_scene(tmp_path)):
        with pytest.raises(ValueError) as err:
            read()
        line = str(err.value)
        assert "\n" not in line and line.startswith(f"{path}: ") and problem in line, line


def test_a_rename_rereads_the_file_through_its_model(tmp_path):
    path, doc = _taught(tmp_path)
    run = TaughtRun(tmp_path, "both")
    doc["waypoints"][1]["y"] = "north"  # edited by hand while the server runs
    path.write_text(yaml.safe_dump(doc, sort_keys=False))
    before = path.read_bytes()
    with pytest.raises(ValueError, match=r"waypoints\[1\]\.y: must be a valid number, got 'north'"):
        run.rename("P0", "Cell A")
    assert path.read_bytes() == before


def test_a_map_yaml_is_read_through_its_model(tmp_path):
    path, _ = _taught(tmp_path)
    map_yaml = tmp_path / "map_band.yaml"
    digest = _sha1(tmp_path / yaml.safe_load(map_yaml.read_text())["image"])
    assert waypoints_file_hash(map_yaml) == digest  # a valid map reads as before
    meta = yaml.safe_load(map_yaml.read_text())
    other = tmp_path / "other.yaml"
    for edit, problem in [
        (lambda m: m.pop("image"), "image: missing"),
        (lambda m: m.update(image=3), "image: must be a valid string, got 3"),
        (
            lambda m: m.update(resolution=-0.1),
            "resolution: must be greater than or equal to 0.0001, got -0.1",
        ),
    ]:
        changed = dict(meta)
        edit(changed)
        other.write_text(yaml.safe_dump(changed))
        with pytest.raises(MapFormatError) as err:
            waypoints_file_hash(other)
        assert str(err.value) == f"{other}: {problem}"
        with pytest.raises(ValueError) as err:  # kiseki playback --map other.yaml
            load_route(path, "band", ["P0", "P1"], other)
        assert "\n" not in str(err.value) and f"{other}: {problem}" in str(err.value)
    other.write_text(yaml.safe_dump({**meta, "image": "gone.pgm"}))
    with pytest.raises(ValueError, match=r"other.yaml: cannot read the image it names \(.*gone"):
        load_route(path, "band", ["P0", "P1"], other)
