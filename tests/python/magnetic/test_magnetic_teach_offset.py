# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The parallel paths of a magnetic teaching (the route moved ``offset`` m to its left and
right): what would end their runs is told as the offset's, before any run when the route itself
is clear, after the route's own run otherwise (the command line's lines:
tests/python/cli/test_cli_messages.py)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from kiseki.apps.magnetic.navigate_run import _shifted, teach
from kiseki.apps.magnetic.teach_checks import OffsetCheck
from kiseki.sim.scene import load_scene

ROUTE = "[[0.0, 0.0], [118.0, 0.0]]"  # magnetic_path.yaml's route


def scene_with(tmp_path: Path, project_data: Path, name: str, route: str, box=None) -> Path:
    text = (project_data / "worlds" / "magnetic_path.yaml").read_text(encoding="utf-8")
    assert text.count(ROUTE) == 1
    text = text.replace(ROUTE, route)
    if box is not None:
        text = text.replace("objects:\n", f"objects:\n  - {{type: box, {box}}}\n", 1)
    (tmp_path / name).write_text(text, encoding="utf-8")
    return tmp_path / name


def test_a_blocked_waypoint_is_refused_before_any_run_naming_the_offset(tmp_path, project_data):
    """The right parallel path's end lies in a box: its run hit it after the route's and the
    left path's runs, and the line named the scene."""
    box = "center: [16.0, -3.0], size: [0.4, 0.4, 1.0]"
    scene = scene_with(tmp_path, project_data, "box.yaml", "[[0.0, 0.0], [16.0, 0.0]]", box)
    line = (
        "offset 3 m: the right parallel path would pass waypoint W1 at (16.00, -3.00), where the "
        "robot cannot stand in any heading (an obstacle 0.07 m away, within half its width of "
        f"0.29 m) in {scene}; the parallel paths' starts and waypoints are clear up to offset "
        "2.56 m"
    )
    with pytest.raises(ValueError) as refused:
        teach(scene, tmp_path / "out", offset=3.0)
    assert str(refused.value) == line
    assert list((tmp_path / "out").iterdir()) == []  # no teaching run


def test_a_route_into_a_wall_is_the_scenes_before_its_parallel_waypoints(tmp_path, project_data):
    """The route turns into the corridor's wall: its own run is told (naming the scene), and
    the parallel paths' waypoints are checked once it reached its end (after_route), so the
    offset is not blamed for the route's wall."""
    route = "[[0.0, 0.0], [7.0, 0.0], [7.0, 5.0], [0.0, 5.0]]"
    scene = scene_with(tmp_path, project_data, "turn.yaml", route)
    loaded = load_scene(scene, "teach")
    points = np.asarray(loaded.route["waypoints"], dtype=np.float64)
    check = OffsetCheck(loaded, scene, 1.0, lambda d: _shifted(points, d), "offset")
    assert not check.route_clear
    check.before_runs()  # the starts are clear; the waypoints wait for the route's run
    with pytest.raises(ValueError) as refused:
        check.after_route()
    assert str(refused.value) == (
        "offset 1 m: the left parallel path would pass waypoint W2 at (6.00, 4.00), where the "
        "robot cannot stand in any heading (an obstacle 0.07 m away, within half its width of "
        f"0.29 m) in {scene}; the parallel paths' starts and waypoints are clear up to offset "
        "0.56 m"
    )
    with pytest.raises(ValueError, match=r"the teaching run along the route did not reach"):
        teach(scene, tmp_path / "out", offset=1.0)
