# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Issue 27, item 1: the output guard (kiseki._support.guard) against the defects a user found,
run as a user would (``python -m kiseki.cli``), inputs compared by SHA-256 before and after:
each is one line ``kiseki: error: ...`` naming the option and the file, exit status 1, before
any work."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from _helpers.output_guard import _spec, refused, run, sha256s
from _helpers.room_log import room, write_log


@pytest.fixture
def inputs(tmp_path: Path) -> Path:
    from kiseki import save_map

    save_map(room(), tmp_path / "room.yaml")
    write_log(tmp_path / "log.mcap")
    return tmp_path


def test_terrain_planes_never_writes_its_csv_over_the_cloud(tmp_path):
    from kiseki import _core

    rng = np.random.default_rng(0)
    floor = np.column_stack([rng.uniform(-2, 2, (600, 2)), np.zeros(600)])
    box = rng.uniform([0.5, 0.5, 0.0], [1.0, 1.0, 0.5], (200, 3))
    _core.write_pcd(str(tmp_path / "cloud.pcd"), np.vstack([floor, box]))
    before = sha256s(tmp_path)
    done = run("terrain", "planes", "cloud.pcd", "-o", "p.png", "--csv", "cloud.pcd", cwd=tmp_path)
    refused(done, "--csv cloud.pcd would overwrite the input CLOUD cloud.pcd")
    assert sha256s(tmp_path) == before  # no picture either: refused before the work


def test_terrain_run_never_writes_over_the_octree_it_reads(tmp_path, project_root):
    from kiseki import _core
    from kiseki.sim.scene import load_scene

    scene = load_scene(project_root / "data" / "worlds" / "factory_corridor.yaml")
    (tmp_path / "OUT").mkdir()
    _core.OctreeWorld.from_boxes(scene.world, 0.2).write_binary(
        str(tmp_path / "OUT" / "global_map.bt")
    )
    before = sha256s(tmp_path)
    done = run("terrain", "run", "OUT/global_map.bt", "--moves", "1", "-o", "OUT", cwd=tmp_path)
    refused(
        done,
        "--output OUT would overwrite the input WORLD OUT/global_map.bt",
        "(the command writes global_map.bt there)",
    )
    assert sha256s(tmp_path) == before


@pytest.fixture
def bag(tmp_path: Path) -> Path:
    """A ROS 2 bag folder (sqlite3) of the room's log, with reference poses."""
    from kiseki import save_map
    from kiseki.datasets import open_scans, write_bag

    write_log(tmp_path / "log.mcap")
    scans = open_scans(tmp_path / "log.mcap")
    (tmp_path / "log.mcap").unlink()
    save_map(room(), tmp_path / "room.yaml")
    return write_bag(scans, tmp_path / "bag", "ros2-sqlite3")


LOCALIZE_BAG = ["localize", "bag", "--map", "room.yaml", "--reference-topic", "/ground_truth"]
METADATA = ("exists inside the input folder LOG bag", "would overwrite the input")


@pytest.mark.parametrize(
    ("command", "output", "needles"),
    [
        (LOCALIZE_BAG, "bag/metadata.yaml", METADATA),
        (["map", "from-log", "bag", "--reference-topic", "/ground_truth"], "bag/metadata.yaml",
         METADATA),
        (LOCALIZE_BAG, "bag/new.csv", ("is inside the input folder LOG bag",)),  # a new file
    ],
)  # fmt: skip
def test_an_output_inside_a_ros2_bag_folder_is_refused(bag, command, output, needles):
    assert (bag / "metadata.yaml").is_file()
    before = sha256s(bag.parent)
    refused(run(*command, "-o", output, cwd=bag.parent), f"--output {output} ", *needles)
    assert sha256s(bag.parent) == before


def test_an_existing_folder_as_the_output_file_is_refused_before_the_work(inputs):
    """It failed after the work, naming a temporary file: [Errno 21] Is a directory:
    '.outdir.zb7lp2zf' -> 'outdir'. As every file output of every command (speed limits' here,
    in this process)."""
    from kiseki.cli.speed import speed_limits

    (inputs / "outdir").mkdir()
    (inputs / "outdir" / "keep.txt").write_text("mine")
    before = sha256s(inputs)
    done = run("localize", "log.mcap", "--map", "room.yaml", "-o", "outdir", cwd=inputs)
    line = refused(done, "--output outdir is a folder")
    assert ".outdir." not in line
    assert sha256s(inputs) == before and sorted(os.listdir(inputs / "outdir")) == ["keep.txt"]
    with pytest.raises(IsADirectoryError, match="--plot .*outdir is a folder"):
        _spec(speed_limits).check(
            {"log": inputs / "log.mcap", "map_file": inputs / "room.yaml",
             "output": inputs / "s.csv", "plot": inputs / "outdir"}
        )  # fmt: skip


def test_a_magnetic_map_folder_takes_no_new_file_either(tmp_path):
    """predict compared its output with the map folder's files only: a new file went in."""
    (tmp_path / "d.csv").write_text("x,y,mx,my,mz\n0,0,1,2,3\n1,0,1,2,4\n0,1,1,3,3\n1,1,2,2,3\n")
    (tmp_path / "p.csv").write_text("x,y\n0.5,0.5\n")
    from typer.testing import CliRunner

    from kiseki.cli import app

    fit = ["magnetic", "fit", str(tmp_path / "d.csv"), "-o", str(tmp_path / "m")]
    done = CliRunner().invoke(app, [*fit, "--kernel", "3,1,40,0.1"])  # in this process: faster
    assert done.exit_code == 0, done.output
    before = sha256s(tmp_path)
    done = run("magnetic", "predict", "m", "--at", "p.csv", "-o", "m/field.csv", cwd=tmp_path)
    refused(done, "--output m/field.csv is inside the input folder MAP m")
    assert sha256s(tmp_path) == before
