# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""`kiseki playback` plays a taught route only in the scene it was taught in (the SHA-1 the
teaching recorded), unless --variant names a changed copy, whose label and both SHA-1s it then
records; on a 3 m corridor (the factory corridor's route shortened)."""

from __future__ import annotations

import hashlib
import subprocess
import sys

import pytest
import yaml

from kiseki.apps.teach import teach
from kiseki.io.runlog import read_run
from kiseki.sim.scene import load_scene
from kiseki.teach.scene_identity import TaughtScene, check_scene


def kiseki(*args, cwd):
    return subprocess.run(
        [sys.executable, "-m", "kiseki.cli", *map(str, args)],
        cwd=cwd,
        capture_output=True,
        text=True,
    )


def sha1(path) -> str:
    return hashlib.sha1(path.read_bytes()).hexdigest()


@pytest.fixture(scope="module")
def taught(tmp_path_factory, project_root):
    """A 3 m corridor taught once, and a copy of its scene with the first workbench moved."""
    root = tmp_path_factory.mktemp("identity")
    doc = yaml.safe_load((project_root / "data" / "worlds" / "factory_corridor.yaml").read_text())
    doc["route"]["waypoints"] = [[0.0, 0.0], [1.5, 0.0], [3.0, 0.0]]
    scene = root / "corridor.yaml"
    scene.write_text(yaml.safe_dump(doc))
    teach(load_scene(scene), root / "t", seed=1)
    bench = next(o for o in doc["objects"] if o["type"] == "workbench")
    bench["center"] = [bench["center"][0] + 0.4, bench["center"][1]]
    moved = root / "moved.yaml"
    moved.write_text(yaml.safe_dump(doc))
    return root, scene, moved


def test_the_taught_scene_plays_back_and_its_sha1_is_logged(taught):
    root, scene, _ = taught
    recorded = yaml.safe_load((root / "t" / "waypoints.yaml").read_text())
    assert recorded["scene_sha1"] == sha1(scene)
    done = kiseki("playback", scene, "--taught", "t", "--route", "P0,P2", "--log", "same.mcap",
                  cwd=root)  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert "goal reached: True" in " ".join(done.stdout.split())
    meta = read_run(root / "same.mcap").metadata
    assert meta["scene_sha1"] == meta["taught_scene_sha1"] == sha1(scene)
    assert "variant" not in meta


def test_a_changed_scene_is_refused_in_one_line_and_nothing_written(taught):
    root, scene, moved = taught
    done = kiseki("playback", moved, "--taught", "t", "--route", "P0,P2", "--log", "no.mcap",
                  cwd=root)  # fmt: skip
    assert done.returncode == 1
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1, done.stderr
    assert str(moved) in lines[0] and str(scene) in lines[0] and "--variant" in lines[0]
    assert not (root / "no.mcap").exists()
    # a waypoint file from before the scene was recorded in it: the teaching log tells
    old = root / "t" / "old_waypoints.yaml"
    doc = yaml.safe_load((root / "t" / "waypoints.yaml").read_text())
    del doc["scene_file"], doc["scene_sha1"]
    old.write_text(yaml.safe_dump(doc, sort_keys=False))
    done = kiseki("playback", moved, "--waypoints", old, "--route", "P0,P2", cwd=root)
    assert done.returncode == 1 and "--variant" in done.stderr
    done = kiseki("playback", moved, "--taught", "t", "--route", "P0,P2", "--variant", "a b",
                  cwd=root)  # fmt: skip
    assert done.returncode == 1 and "variant label" in done.stderr


def test_a_named_variant_plays_back_and_records_both_sha1s(taught):
    root, scene, moved = taught
    done = kiseki("playback", moved, "--taught", "t", "--route", "P0,P2", "--log", "v.mcap",
                  "--variant", "bench-moved", cwd=root)  # fmt: skip
    assert done.returncode == 0, done.stderr
    meta = read_run(root / "v.mcap").metadata
    assert meta["variant"] == "bench-moved"
    assert (meta["scene_sha1"], meta["taught_scene_sha1"]) == (sha1(moved), sha1(scene))
    assert sha1(moved) != sha1(scene)
    text = " ".join(done.stdout.split())
    assert f"scene variant 'bench-moved': {moved} (SHA-1 {sha1(moved)})" in text
    assert f"(SHA-1 {sha1(scene)})" in text


def test_the_api_refuses_a_changed_scene_without_a_label(taught):
    _, scene, moved = taught
    known = TaughtScene(str(scene), sha1(scene))
    assert check_scene(known, scene) == {
        "scene_sha1": sha1(scene),
        "taught_scene_file": str(scene),
        "taught_scene_sha1": sha1(scene),
    }
    with pytest.raises(ValueError, match="not the scene the route was taught in"):
        check_scene(known, moved)
    assert check_scene(known, moved, "exp3-boxes")["variant"] == "exp3-boxes"
    assert check_scene(None, moved) == {"scene_sha1": sha1(moved)}  # a hand-made waypoint file


def test_a_variant_label_on_the_taught_scene_itself_is_refused(taught):
    """The label went into the log's metadata as if the scene had been changed."""
    root, scene, _ = taught
    with pytest.raises(ValueError) as err:
        check_scene(TaughtScene(str(scene), sha1(scene)), scene, "boxes")
    assert str(err.value) == (
        f"scene variant 'boxes' names a changed scene, but {scene} is the scene the route was "
        "taught in (the same SHA-1): play back without a variant label"
    )
    done = kiseki("playback", scene, "--taught", "t", "--route", "P0,P2", "--log", "u.mcap",
                  "--variant", "boxes", cwd=root)  # fmt: skip
    assert done.returncode == 1 and not (root / "u.mcap").exists()
    assert done.stderr.strip().endswith("play back without a variant label")
    assert "Traceback" not in done.stderr


def test_serve_knows_the_taught_scene_by_its_sha1_when_the_file_is_gone(tmp_path, project_root):
    """The taught scene file moved away: a byte-identical copy is accepted, a changed copy of
    the same name is refused (a name alone once let it through)."""
    from kiseki.serve import scene_of

    doc = yaml.safe_load((project_root / "data" / "worlds" / "factory_corridor.yaml").read_text())
    doc["route"]["waypoints"] = [[0.0, 0.0], [1.5, 0.0], [3.0, 0.0]]
    text = yaml.safe_dump(doc)
    for sub in ("taught_in", "copy", "changed"):
        (tmp_path / sub).mkdir()
    scene = tmp_path / "taught_in" / "corridor.yaml"
    scene.write_text(text)
    teach(load_scene(scene), tmp_path / "t", seed=1)
    scene.unlink()
    copy = tmp_path / "copy" / "corridor.yaml"
    copy.write_text(text)
    changed = tmp_path / "changed" / "corridor.yaml"
    bench = next(o for o in doc["objects"] if o["type"] == "workbench")
    bench["center"] = [bench["center"][0] + 0.4, bench["center"][1]]
    changed.write_text(yaml.safe_dump(doc))
    assert scene_of(tmp_path / "t", copy) == copy
    with pytest.raises(ValueError, match="not this scene"):
        scene_of(tmp_path / "t", changed)
