# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""A scene's objects and its given bounds: an object wholly outside them (a box 1,300 m away)
was loaded and never seen by any sensor, map or grid of the run; one that reaches past them (a
wall longer than the room) is part of the world."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from kiseki.sim.scene import load_scene


def _scene(tmp_path, objects):
    doc = {
        "name": "t",
        "bounds": {"min": [-2, -2, -0.1], "max": [4, 4, 2]},
        "floor": True,
        "objects": objects,
        "robot": {"type": "diff_drive", "start": [1.0, 0.0, 0.0]},
        "route": {"waypoints": [[1, 0], [2, 0]]},
    }
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(doc))
    return path


def test_an_object_wholly_outside_the_bounds_is_refused_naming_it(tmp_path):
    far = {"type": "box", "center": [1300.0, 0.0], "size": [0.4, 0.4, 1.0]}
    path = _scene(tmp_path, [{"type": "box", "center": [0.5, 2.0], "size": [0.4, 0.4, 1.0]}, far])
    with pytest.raises(ValueError) as err:
        load_scene(path)
    assert str(err.value).startswith(
        f"{path}: objects[1] spans x 1299.8..1300.2, y -0.2..0.2, z 0..1: wholly outside the "
        "scene's bounds x -2..4, y -2..4"
    )


def test_an_object_reaching_past_the_bounds_is_kept(tmp_path):
    """A ray inside the bounds meets the long wall where it is."""
    wall = {"type": "box", "center": [1.0, 3.5], "size": [30.0, 0.2, 1.0]}
    world = load_scene(_scene(tmp_path, [wall])).world
    ranges = world.cast_many([[1.0, 0.0, 0.5], [-1.5, 0.0, 0.5]], [[0, 1, 0], [0, 1, 0]], 10.0)
    np.testing.assert_allclose(ranges, [3.4, 3.4], atol=1e-9)
