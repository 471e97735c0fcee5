# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Mistakes whose one line named the wrong thing, found by probing the commands: each line now
names what the user typed and what is wrong with it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from _helpers.boundaries_cli import digests, one_error, run
from _helpers.room_log import ANGLES, room, room_scans
from kiseki import save_map
from kiseki.io.runlog import RunWriter
from kiseki.scans import LaserScans

WORLDS = Path(__file__).resolve().parents[3] / "data" / "worlds"
SCENE = WORLDS / "factory_corridor.yaml"
MAGNETIC = WORLDS / "magnetic_path.yaml"  # walls 4 m to the left and right of the start
ROUTE = "[[0.0, 0.0], [118.0, 0.0]]"  # magnetic_path.yaml's route


def write_magnetic_scenes(folder: Path) -> None:
    """The first 16 m of magnetic_path.yaml with a box 2 m left of its middle and one 3 m right
    of its end (boxes.yaml), and its route slanted 1 m to the left over 16 m (slant.yaml)."""
    text = MAGNETIC.read_text(encoding="utf-8")
    assert text.count(ROUTE) == 1 and text.count("objects:\n") == 1
    boxes = "".join(
        f"  - {{type: box, center: {at}, size: [0.4, 0.4, 1.0]}}\n"
        for at in ([8.0, 2.0], [16.0, -3.0])
    )
    short = text.replace(ROUTE, "[[0.0, 0.0], [16.0, 0.0]]")
    (folder / "boxes.yaml").write_text(short.replace("objects:\n", "objects:\n" + boxes))
    (folder / "slant.yaml").write_text(text.replace(ROUTE, "[[0.0, 0.0], [16.0, 1.0]]"))


@pytest.fixture
def inputs(tmp_path: Path) -> Path:
    save_map(room(), tmp_path / "room.yaml")
    # a CMU robotdata log (odometry and scans in cm, no reference poses): two scans
    laser = "L 100 -50 0 125 -50 0 " + " ".join(["200"] * 180)
    text = f"O 100 -50 0 0.01\n{laser} 0.05\nO 100 -50 0 0.1\n{laser} 0.15\n"
    (tmp_path / "robotdata.log").write_text(text)
    (tmp_path / "taught-file").write_text("not a folder")
    (tmp_path / "sub").mkdir()
    for name, image in (("dot", "."), ("folder", "sub")):  # map YAMLs whose image is a folder
        (tmp_path / f"{name}.yaml").write_text(
            f"image: {image}\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\n"
        )
    scans = room_scans(3)
    with RunWriter(tmp_path / "no_truth.mcap") as w:  # a run without /ground_truth
        for t, pose, ranges in zip(scans.times, scans.poses, scans.ranges, strict=True):
            w.write_odometry("/odom", t, pose)
            w.write_laser_scan("/scan", t, pose, ANGLES, ranges, max_range=8.0)
    with RunWriter(tmp_path / "no_odom.mcap") as w:  # a run without /odom
        for t, pose, ranges in zip(scans.times, scans.poses, scans.ranges, strict=True):
            w.write_pose("/ground_truth", t, pose)
            w.write_laser_scan("/scan", t, pose, ANGLES, ranges, max_range=8.0)
    write_magnetic_scenes(tmp_path)
    return tmp_path


@pytest.mark.parametrize(
    ("args", "line"),
    [
        (  # it asked for --reference-topic, an option of ROS bags only
            ["speed", "limits", "robotdata.log", "--map", "room.yaml", "-o", "s.csv"],
            "robotdata.log: the log has no reference poses",
        ),
        (  # it named the waypoint file inside the missing folder
            ["playback", SCENE, "--taught", "nowhere", "--route", "P0,P1"],
            "--taught nowhere: no such folder (kiseki teach writes one)",
        ),
        (
            ["playback", SCENE, "--taught", "taught-file", "--route", "P0,P1"],
            "--taught taught-file: not a folder (kiseki teach writes one)",
        ),
        (  # 'no waypoint named , ,'
            ["playback", SCENE, "--taught", ".", "--route", ",,"],
            "--route ',,': a waypoint name is empty: give names as P0,P1,P2",
        ),
        (  # '' is the current folder: '.: unknown map format'
            ["map", "info", ""],
            ".: a folder, not a map file (.yaml, .yml, .dat or .dat.gz)",
        ),
        (
            ["demo", "--scene", "sub", "--out", "d"],
            "sub: a folder, not a scene file",
        ),  # 'not found'
        (
            ["teach", SCENE, "--keyboard", "--keys", "sub", "-o", "t"],
            "sub: a folder, not a key script",
        ),
        (  # '...magnetic_path.yaml: the robot's start footprint overlaps an obstacle'
            ["magnetic", "teach", MAGNETIC, "-o", "taught", "--offset", "4"],
            "--offset 4 m: the left parallel path would start at (0.00, 4.00), where the robot's "
            f"footprint overlaps an obstacle in {MAGNETIC}; the parallel paths' starts and "
            "waypoints are clear up to --offset 3.50 m",
        ),
        (  # 'boxes.yaml: the teaching run along the left parallel path did not reach its end...'
            ["magnetic", "teach", "boxes.yaml", "-o", "taught", "--offset", "2"],
            "--offset 2 m: the teaching run along the left parallel path did not reach its end "
            "in boxes.yaml (hit obstacle at (7.81, 2.00) at t = 12.7 s): no map; give an "
            "--offset whose parallel paths clear the scene's obstacles",
        ),
        (  # '...the teaching run along the right parallel path did not reach its end...'
            ["magnetic", "teach", "boxes.yaml", "-o", "taught", "--offset", "3"],
            "--offset 3 m: the right parallel path would pass waypoint W1 at (16.00, -3.00), "
            "where the robot cannot stand in any heading (an obstacle 0.07 m away, within half "
            "its width of 0.29 m) in boxes.yaml; the parallel paths' starts and waypoints are "
            "clear up to --offset 2.56 m",
        ),
        (  # 'slant.yaml: route waypoint W1 [15.55..., 8.18...] lies outside the scene's bounds'
            ["magnetic", "teach", "slant.yaml", "-o", "taught", "--offset", "7.2"],
            "--offset 7.2 m: the left parallel path would pass waypoint W1 at (15.55, 8.19), "
            "outside the scene's bounds (x -5..125, y -8..8) in slant.yaml; the parallel paths' "
            "starts and waypoints are clear up to --offset 2.56 m",
        ),
        (  # 'dot.yaml: image file . not found' of the folder the YAML is in
            ["map", "info", "dot.yaml"],
            "dot.yaml: image '.' is a folder, not a map image",
        ),
        (
            ["speed", "limits", "robotdata.log", "--map", "folder.yaml", "-o", "s.csv"],
            "folder.yaml: image 'sub' is a folder, not a map image",
        ),
        (  # '(pass truth_topic=None to use the scan poses as written)': an API argument
            ["map", "from-log", "no_truth.mcap", "-o", "m.yaml"],
            "no_truth.mcap: no ground-truth topic '/ground_truth' (topics: ['/odom', '/scan']): "
            "the scans are placed by its poses; give a run that records it (kiseki sim run does)",
        ),
        (  # '(...; pass odom_topic=None for NaN odometry)': an API argument
            ["map", "from-log", "no_odom.mcap", "-o", "m.yaml"],
            "no_odom.mcap: no odometry topic '/odom' (topics: ['/ground_truth', '/scan']): the "
            "scans' odometry is read from it; give a run that records it (kiseki sim run does)",
        ),
        (  # an MCAP run written to x.txt
            ["sim", "run", SCENE, "-o", "x.txt"],
            "--output x.txt: extension '.txt'; give a file ending in .mcap",
        ),
        (  # an OctoMap .bt written to x.txt
            ["sim", "show", SCENE, "-o", "s.png", "--octree", "x.txt"],
            "--octree x.txt: extension '.txt'; give a file ending in .bt",
        ),
    ],
    ids=[
        "reference-topic",
        "taught-missing",
        "taught-file",
        "empty-route",
        "map-folder",
        "scene-folder",
        "keys-folder",
        "offset-too-wide",
        "offset-blocked-midway",
        "offset-waypoint-blocked",
        "offset-waypoint-outside",
        "map-image-dot",
        "map-image-folder",
        "run-without-truth",
        "run-without-odom",
        "sim-run-suffix",
        "octree-suffix",
    ],
)
def test_the_line_names_what_was_typed_and_what_is_wrong(inputs, args, line):
    before = digests(inputs)
    assert one_error(run(*args, cwd=inputs)) == f"kiseki: error: {line}"
    assert digests(inputs) == before


def test_a_bag_without_reference_poses_is_told_of_reference_topic(inputs):
    """speed limits on a ROS bag without reference poses names --reference-topic, the option
    that gives them (a CARMEN or Wean log has no such option: robotdata.log above is not told)."""
    from kiseki.datasets import write_bag

    scans = room_scans(5)
    nowhere = LaserScans(
        scans.times, np.full_like(scans.poses, np.nan), scans.odometry, scans.ranges,
        scans.angles, scans.max_range,
    )  # fmt: skip
    write_bag(nowhere, inputs / "odom.bag", "ros1")  # /scan and /odom only
    before = digests(inputs)
    done = run("speed", "limits", "odom.bag", "--map", "room.yaml", "-o", "s.csv", cwd=inputs)
    line = "odom.bag: the log has no reference poses (give --reference-topic)"
    assert one_error(done) == f"kiseki: error: {line}"
    assert digests(inputs) == before
