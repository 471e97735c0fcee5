# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What simulate is given, checked before anything runs: a scene or a config of another kind
was an AttributeError from inside the loop ('NoneType' object has no attribute
'robot_specs')."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

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
