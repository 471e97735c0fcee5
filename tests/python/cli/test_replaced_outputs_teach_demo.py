# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``kiseki teach -o`` and ``kiseki demo --out`` keep a user's own files: a folder holding a
map, waypoint file, config or summary by a name the command writes was replaced without a word
(exit 0) unless it held teach.mcap; now it is refused before any work, in one line naming the
folder and the first file, unless --overwrite (teach) or the folder is an earlier demo's."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest
import yaml

from kiseki.apps.teach import teach
from kiseki.apps.teach.teaching import TEACHING_FILES
from kiseki.cli.demo import DEMO_FILES, WRITTEN_BY
from kiseki.sim.scene import load_scene

TEACH_REMEDY = "give a new or empty folder as --out, or add --overwrite"
DEMO_REMEDY = "give a new or empty folder as --out (an earlier demo's folder is replaced)"


def run(*args: str, cwd) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "kiseki.cli", *args], capture_output=True, text=True, cwd=cwd
    )


def contents(folder) -> dict[str, bytes]:
    return {
        p.relative_to(folder).as_posix(): p.read_bytes() for p in folder.rglob("*") if p.is_file()
    }


def refused(done: subprocess.CompletedProcess, message: str) -> None:
    assert done.returncode == 1, done.stderr
    assert "Traceback" not in done.stderr
    assert done.stderr.splitlines() == [f"kiseki: error: {message}"]


@pytest.fixture
def short_scene(tmp_path, project_root):
    """The corridor shortened to 1.5 m (P0, G): a teaching run or a demo in about 3 s."""
    doc = yaml.safe_load((project_root / "data" / "worlds" / "factory_corridor.yaml").read_text())
    doc["route"]["waypoints"], doc["route"]["names"] = [[0.0, 0.0], [1.5, 0.0]], ["P0", "G"]
    (tmp_path / "short.yaml").write_text(yaml.safe_dump(doc))
    return "short.yaml"


def test_teach_refuses_a_folder_of_the_users_maps_and_waypoints(tmp_path, short_scene):
    """The probe: te holds the user's map_plane.yaml and waypoints.yaml, no teach.mcap."""
    (tmp_path / "te").mkdir()
    (tmp_path / "te" / "map_plane.yaml").write_text("the user's map\n")
    (tmp_path / "te" / "waypoints.yaml").write_text("the user's waypoints\n")
    before = contents(tmp_path)
    done = run("teach", short_scene, "-o", "te", cwd=tmp_path)
    refused(
        done,
        f"--out te holds map_plane.yaml (and 1 more), which this command would replace: "
        f"{TEACH_REMEDY}",
    )
    assert contents(tmp_path) == before  # nothing replaced, nothing written


@pytest.mark.parametrize("name", TEACHING_FILES[1:])
def test_teach_refuses_any_file_a_teaching_run_writes(tmp_path, short_scene, name):
    (tmp_path / "te").mkdir()
    (tmp_path / "te" / name).write_text("the user's own\n")
    (tmp_path / "te" / "notes.txt").write_text("not a name teach writes\n")
    before = contents(tmp_path)
    done = run("teach", short_scene, "-o", "te", cwd=tmp_path)
    refused(done, f"--out te holds {name}, which this command would replace: {TEACH_REMEDY}")
    assert contents(tmp_path) == before


def test_teach_from_the_keyboard_refuses_too(tmp_path, short_scene):
    (tmp_path / "te").mkdir()
    (tmp_path / "te" / "map_truth.json").write_text("{}\n")
    (tmp_path / "keys.txt").write_text("0 w\n0.5 m\n1 q\n")
    before = contents(tmp_path)
    done = run("teach", short_scene, "-o", "te", "--keyboard", "--keys", "keys.txt", cwd=tmp_path)
    refused(
        done, f"--out te holds map_truth.json, which this command would replace: {TEACH_REMEDY}"
    )
    assert contents(tmp_path) == before


def test_an_existing_teaching_log_keeps_its_message(tmp_path, short_scene):
    """teach.mcap is checked first, as before, even beside other files teach writes."""
    (tmp_path / "te").mkdir()
    (tmp_path / "te" / "teach.mcap").write_bytes(b"")
    (tmp_path / "te" / "map_band.yaml").write_text("the user's map\n")
    before = contents(tmp_path)
    done = run("teach", short_scene, "-o", "te", cwd=tmp_path)
    refused(
        done,
        "te/teach.mcap: a teaching log exists; --resume rebuilds from it, --overwrite replaces it",
    )
    assert contents(tmp_path) == before


def test_teach_with_overwrite_replaces_them(tmp_path, short_scene):
    (tmp_path / "te").mkdir()
    (tmp_path / "te" / "map_plane.yaml").write_text("the user's map\n")
    (tmp_path / "te" / "waypoints.yaml").write_text("the user's waypoints\n")
    done = run("teach", short_scene, "-o", "te", "--overwrite", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert set(contents(tmp_path / "te")) == set(TEACHING_FILES)  # every file it writes
    assert yaml.safe_load((tmp_path / "te" / "map_plane.yaml").read_text())["image"] == (
        "map_plane.pgm"
    )
    marks = yaml.safe_load((tmp_path / "te" / "waypoints.yaml").read_text())["waypoints"]
    assert [m["name"] for m in marks] == ["P0", "G"]


def test_demo_refuses_a_folder_of_the_users_config_and_summary(tmp_path, short_scene):
    """The probe: dm holds the user's config.yaml and summary.json (no teach/teach.mcap)."""
    (tmp_path / "dm").mkdir()
    (tmp_path / "dm" / "config.yaml").write_text("the user's config\n")
    (tmp_path / "dm" / "summary.json").write_text('{"the user": "summary"}\n')
    before = contents(tmp_path)
    done = run("demo", "--scene", short_scene, "--out", "dm", "--particles", "20", cwd=tmp_path)
    refused(
        done,
        f"--out dm holds config.yaml (and 1 more), which this command would replace: {DEMO_REMEDY}",
    )
    assert contents(tmp_path) == before
    assert sorted(p.name for p in (tmp_path / "dm").iterdir()) == ["config.yaml", "summary.json"]


@pytest.mark.parametrize("name", ["scene.png", "teach/waypoints.yaml", "taught_map_band.png"])
def test_demo_refuses_any_file_it_writes(tmp_path, short_scene, name):
    (tmp_path / "dm" / "teach").mkdir(parents=True)
    (tmp_path / "dm" / name).write_text("the user's own\n")
    before = contents(tmp_path)
    done = run("demo", "--scene", short_scene, "--out", "dm", "--particles", "20", cwd=tmp_path)
    refused(done, f"--out dm holds {name}, which this command would replace: {DEMO_REMEDY}")
    assert contents(tmp_path) == before


def test_an_earlier_demos_folder_is_replaced(tmp_path, short_scene):
    """The README's promise: the demo runs twice into its folder; what it writes is exactly
    DEMO_FILES (what it checks before)."""
    first = run("demo", "--scene", short_scene, "--out", "d", "--particles", "20", cwd=tmp_path)
    assert first.returncode == 0, first.stderr
    assert set(contents(tmp_path / "d")) == set(DEMO_FILES)
    again = ("--particles", "30", "--seed", "4")
    done = run("demo", "--scene", short_scene, "--out", "d", *again, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    config = yaml.safe_load((tmp_path / "d" / "config.yaml").read_text())
    assert (config["particles"], config["seed"]) == (30, 4)  # the second run's
    assert json.loads((tmp_path / "d" / "summary.json").read_text())["waypoints"] == ["P0", "G"]


@pytest.mark.parametrize("cut", [False, True])
def test_a_demo_interrupted_before_its_summary_is_still_the_demos_own(tmp_path, short_scene, cut):
    """A demo stopped after its teaching, before summary.json, left a folder the demo refused
    to run into again: its teaching log, the demo's first file, marks it as the demo's by its
    metadata, also when the log was cut short by a kill (`cut`: its last third gone)."""
    taught = teach(
        load_scene(tmp_path / short_scene), tmp_path / "d" / "teach", metadata=WRITTEN_BY
    )
    if cut:
        data = taught.log.read_bytes()
        taught.log.write_bytes(data[: 2 * len(data) // 3])
    (tmp_path / "d" / "config.yaml").write_text("the interrupted run's\n")
    done = run("demo", "--scene", short_scene, "--out", "d", "--particles", "20", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert set(contents(tmp_path / "d")) == set(DEMO_FILES)


def test_a_users_own_teaching_run_named_like_the_demos_is_not_replaced(tmp_path, short_scene):
    """The user's `kiseki teach -o d/teach` counted as a demo's teaching (any teach/teach.mcap
    did), so `kiseki demo --out d` replaced the user's run."""
    taught = run("teach", short_scene, "-o", "d/teach", cwd=tmp_path)
    assert taught.returncode == 0, taught.stderr
    before = contents(tmp_path)
    done = run("demo", "--scene", short_scene, "--out", "d", "--particles", "20", cwd=tmp_path)
    files = len([n for n in before if n.startswith("d/")])
    refused(
        done,
        f"--out d holds teach/teach.mcap (and {files - 1} more), which this command would "
        f"replace: {DEMO_REMEDY}",
    )
    assert contents(tmp_path) == before
    (tmp_path / "d" / "teach" / "teach.mcap").write_bytes(b"not a log")  # nor is a broken one
    done = run("demo", "--scene", short_scene, "--out", "d", "--particles", "20", cwd=tmp_path)
    assert done.returncode == 1 and "holds teach/teach.mcap" in done.stderr


def test_a_demo_that_failed_in_its_teaching_can_be_run_into_again(tmp_path, short_scene):
    """The demo drew scene.png before teaching, so a teaching that failed (a goal off the
    scene) left a folder holding scene.png only, which the demo then refused as not its own.
    It teaches first now: a failed teaching leaves nothing the demo would refuse."""
    doc = yaml.safe_load((tmp_path / short_scene).read_text())
    doc["route"]["waypoints"] = [[0.0, 0.0], [500.0, 0.0]]
    (tmp_path / "far.yaml").write_text(yaml.safe_dump(doc))
    failed = run("demo", "--scene", "far.yaml", "--out", "d", "--particles", "20", cwd=tmp_path)
    assert failed.returncode == 1 and "Traceback" not in failed.stderr
    assert not [p for p in (tmp_path / "d").rglob("*") if p.is_file()]
    done = run("demo", "--scene", short_scene, "--out", "d", "--particles", "20", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
