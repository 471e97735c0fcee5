# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Files a user may hand kiseki broken: random bytes or hand-edited waypoint, trajectory and
command files give one line naming the file (and the entry and field), never a traceback or a
codec error without a file name."""

from __future__ import annotations

import subprocess
import sys
import warnings

import pytest
import yaml

from kiseki.apps.teach.taught_route import load_route
from kiseki.sim.run import read_commands

RANDOM_BYTES = bytes(range(128, 256)) * 4  # not UTF-8

GOOD = {
    "maps": {"band": {"file": "map_band.yaml", "image_sha1": "0" * 40}},
    "waypoints": [
        {"id": 0, "name": "P0", "x": 0.0, "y": 0.0, "theta": 0.0, "truth": [0.0, 0.0, 0.0]},
        {"id": 1, "name": "G", "x": 1.0, "y": 0.0, "theta": 0.0, "truth": [1.0, 0.0, 0.0]},
    ],
}


def _edited(change) -> dict:
    doc = yaml.safe_load(yaml.safe_dump(GOOD))
    change(doc)
    return doc


@pytest.mark.parametrize(
    ("doc", "needle"),
    [
        (_edited(lambda d: d.update(waypoints=None)), "waypoints: must be a valid list, got None"),
        (_edited(lambda d: d.update(waypoints=[])), "waypoints: list should have at least 1 item"),
        (
            _edited(lambda d: d["waypoints"].__setitem__(1, "G")),
            "waypoints[1]: must be a mapping of name, x, y, theta, got 'G'",
        ),
        (
            _edited(lambda d: d["waypoints"][1].update(x="abc")),
            "waypoints[1].x: must be a valid number, got 'abc' (waypoint 'G')",
        ),
        (_edited(lambda d: d["waypoints"][0].pop("name")), "waypoints[0].name: missing"),
        (
            _edited(lambda d: d["waypoints"][0].update(truth=[0, 0])),
            "waypoints[0].truth: must be the true pose [x, y, theta], got [0, 0] (waypoint 'P0')",
        ),
        (
            _edited(lambda d: d["waypoints"][1].update(name="P0")),
            "waypoints: waypoint names must be unique (P0 repeat)",
        ),
        (
            _edited(lambda d: d.update(maps={"band": "map.yaml"})),
            "maps.band: must be a mapping of file and image_sha1, got 'map.yaml'",
        ),
    ],
)
def test_hand_edited_waypoint_files_are_refused_by_entry_and_field(tmp_path, doc, needle):
    path = tmp_path / "waypoints.yaml"
    path.write_text(yaml.safe_dump(doc))
    with pytest.raises(ValueError) as err:
        load_route(path, "band", ["P0", "G"])
    assert str(path) in str(err.value) and needle in str(err.value)


def test_a_waypoint_without_truth_is_still_a_waypoint(tmp_path):
    doc = _edited(lambda d: [w.pop("truth") for w in d["waypoints"]])
    path = tmp_path / "waypoints.yaml"
    path.write_text(yaml.safe_dump(doc))
    with pytest.raises(FileNotFoundError, match="the taught map is missing"):
        load_route(path, "band", ["P0", "G"])  # past the entries' checks: the map is next


def test_random_bytes_are_named_as_what_they_should_be(tmp_path):
    junk = tmp_path / "junk.bin"
    junk.write_bytes(RANDOM_BYTES)
    with pytest.raises(ValueError, match=f"{junk}: not a kiseki waypoint file"):
        load_route(junk, "band", ["P0", "G"])
    with pytest.raises(ValueError, match=f"{junk}: not a command CSV"):
        read_commands(junk)
    header_only = tmp_path / "c.csv"
    header_only.write_text("t,v,w\n")
    with pytest.raises(ValueError, match="no commands below the header"):
        read_commands(header_only)
    empty = tmp_path / "e.csv"
    empty.write_text("")
    with pytest.raises(ValueError, match="empty command file"):
        read_commands(empty)


@pytest.mark.parametrize(
    "args",
    [
        ["map", "render", "MAP", "-o", "x.png", "--trajectory", "JUNK"],
        ["sim", "run", "SCENE", "-o", "r.mcap", "--controller", "commands", "--commands", "JUNK"],
        ["playback", "SCENE", "--route", "P0,G", "--waypoints", "JUNK", "--map", "MAP"],
        ["serve", "--taught", "FOLDER"],
    ],
)
def test_the_cli_names_a_file_of_random_bytes(tmp_path, project_root, args):
    from kiseki.grid import OccupancyGrid
    from kiseki.io.ros_map import save_map

    junk = tmp_path / "junk.bin"
    junk.write_bytes(RANDOM_BYTES)
    folder = tmp_path / "taught"
    folder.mkdir()
    (folder / "waypoints.yaml").write_bytes(RANDOM_BYTES)
    map_yaml = save_map(OccupancyGrid(10, 10, 0.1), tmp_path / "m.yaml")
    scene = project_root / "data" / "worlds" / "factory_turn.yaml"
    swap = {"JUNK": junk, "MAP": map_yaml, "SCENE": scene, "FOLDER": folder}
    args = [str(swap.get(a, a)) for a in args]
    done = subprocess.run(
        [sys.executable, "-m", "kiseki.cli", *args], capture_output=True, text=True, cwd=tmp_path
    )
    assert done.returncode == 1, done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in done.stderr, done.stderr
    assert "junk.bin" in lines[0] or "waypoints.yaml" in lines[0], lines[0]
    assert "codec" not in lines[0]


@pytest.mark.parametrize(("signum", "code"), [(15, 143), (2, 130)])  # SIGTERM, SIGINT
def test_an_interrupted_sim_run_closes_its_mcap_and_says_so(tmp_path, project_root, signum, code):
    import time

    from kiseki.io.runlog import read_run

    out = tmp_path / "run.mcap"
    scene = project_root / "data" / "worlds" / "factory_turn.yaml"
    proc = subprocess.Popen(
        [sys.executable, "-m", "kiseki.cli", "sim", "run", str(scene), "-o", str(out)],
        stderr=subprocess.PIPE,
        stdout=subprocess.DEVNULL,
        text=True,
    )
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and (not out.exists() or out.stat().st_size < 100_000):
        time.sleep(0.2)  # until the run has written something
    proc.send_signal(signum)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == code, err
    assert "interrupted" in err and str(out) in err
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a truncated MCAP would warn
        run = read_run(out)
    assert not run.truncated
    assert run.topics()["/ground_truth"][1] > 0
