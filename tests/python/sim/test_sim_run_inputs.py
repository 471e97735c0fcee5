# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What simulate is given, checked before anything runs: a scene or a config of another kind
was an AttributeError from inside the loop ('NoneType' object has no attribute
'robot_specs'), a command list a TypeError, an (n, 3) command array an IndexError, and rows
out of time order were followed in the wrong order without a word."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from kiseki.io.runlog import read_run
from kiseki.sim.run import SimConfig, simulate
from kiseki.sim.scene import load_scene


@pytest.fixture
def scene(tmp_path):
    """An open floor with the omni robot at the origin."""
    doc = {
        "name": "floor",
        "bounds": {"min": [-1.0, -2.0, -0.1], "max": [4.0, 2.0, 2.1]},
        "floor": True,
        "objects": [{"type": "box", "center": [3.8, 1.8], "size": [0.1, 0.1, 0.5]}],
        "robot": {"type": "omni", "start": [0.0, 0.0, 0.0]},
    }
    path = tmp_path / "floor.yaml"
    path.write_text(yaml.safe_dump(doc))
    return load_scene(path)


GO = np.array([[0.0, 0.5, 0.0, 0.0]])


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        ({"scene": None}, "scene must be a kiseki Scene (load_scene), got NoneType"),
        ({"scene": "floor.yaml"}, "scene must be a kiseki Scene (load_scene), got str"),
        ({"config": {"dt": 0.1}}, "config must be a SimConfig or None, got dict"),
        ({"out": None}, "out must be a path (the MCAP file), got NoneType"),
    ],
)
def test_a_scene_config_or_output_of_another_kind_is_refused_naming_it(
    scene, tmp_path, args, needle
):
    call = {"scene": scene, "out": tmp_path / "run.mcap", "config": SimConfig(duration=0.5)}
    with pytest.raises(TypeError) as caught:
        simulate(**(call | args), commands=GO, progress=False)
    assert str(caught.value) == needle
    assert not (tmp_path / "run.mcap").exists()


@pytest.mark.parametrize(
    ("commands", "needle"),
    [
        (np.array([[0.0, 0.5, 0.0]]), r"must be an \(n, 4\) array of 1 to 1,000,000 rows t, vx,"),
        # more rows than a command script may hold (the file's limit, MAX_COMMANDS)
        (np.zeros((1_000_001, 4)), r"commands must be an \(n, 4\) array of 1 to 1,000,000 rows"),
        (np.array([[0.0, np.nan, 0.0, 0.0]]), r"finite numbers within \+-1e\+09, got \[\[ 0\. nan"),
        (np.array([[0.0, 1e300, 0.0, 0.0]]), r"finite numbers within \+-1e\+09"),
        (np.zeros((0, 4)), r"commands must be an \(n, 4\) array"),
        ([["0", "a", 0, 0]], r"commands must be an \(n, 4\) array"),
        (np.array([[1.0, 0.5, 0, 0], [0.0, 0.1, 0, 0]]), r"must lie in \[0, 86,400\] s and not de"),
        (np.array([[-1.0, 0.5, 0, 0]]), r"the times \(column 0\) must lie in \[0, 86,400\] s"),
    ],
)
def test_bad_commands_are_refused_naming_them(scene, tmp_path, commands, needle):
    with pytest.raises(ValueError, match=needle):
        simulate(scene, tmp_path / "run.mcap", SimConfig(duration=0.5), commands, progress=False)
    assert not (tmp_path / "run.mcap").exists()


def test_commands_given_as_a_list_drive_as_the_array_does(scene, tmp_path):
    """A list of rows was a TypeError ('list indices must be integers or slices')."""
    config = SimConfig(duration=1.0)
    simulate(scene, tmp_path / "a.mcap", config, GO, progress=False)
    simulate(scene, tmp_path / "l.mcap", config, GO.tolist(), progress=False)
    poses = [read_run(tmp_path / f"{n}.mcap").poses("/ground_truth")[1] for n in "al"]
    np.testing.assert_array_equal(poses[0], poses[1])
    assert poses[0][-1, 0] > 0.1  # the robot moved along x
