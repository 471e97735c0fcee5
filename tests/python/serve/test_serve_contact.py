# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""kiseki serve when the simulated AGV meets an obstacle that was not there when the route was
taught (a pillar placed only in the scene's playback variant): the route stops at the contact
and the page reads why. Before, the robot drove through the pillar and the route finished."""

from __future__ import annotations

import math
import time

import yaml
from fastapi.testclient import TestClient

from kiseki.apps.teach import teach
from kiseki.serve import build_server
from kiseki.sim.scene import load_scene

BASE = "http://127.0.0.1:8000"


def test_a_route_into_an_obstacle_stops_there_and_says_so(tmp_path, project_root):
    doc = yaml.safe_load((project_root / "data" / "worlds" / "factory_corridor.yaml").read_text())
    doc["route"] = {"waypoints": [[0.0, 0.0], [1.5, 0.0], [3.0, 0.0]],
                    "names": ["P0", "P1", "P2"], "speed": 0.5}  # fmt: skip
    doc["objects"].append(
        {"type": "pillar", "center": [2.0, 0.0], "size": [0.3, 0.3], "height": 2.5,
         "only_in": "playback"}
    )  # fmt: skip
    scene = tmp_path / "corridor.yaml"
    scene.write_text(yaml.safe_dump(doc, sort_keys=False))
    teach(load_scene(scene), tmp_path / "t", seed=1)  # the pillar is not there yet
    server = build_server(tmp_path / "t", particles=200, speed_up=math.inf, dwell=0.5)
    with TestClient(server.app, base_url=BASE) as client:
        response = client.post("/api/routes", json={"start": "P0", "goal": "P2"})
        assert response.status_code == 202, response.text
        end = time.monotonic() + 120
        while (state := client.get("/api/state").json())["status"] == "running":
            assert time.monotonic() < end, state
            time.sleep(0.05)
    assert state["status"] == "stopped"
    assert state["detail"].startswith("the route failed: COLLISION at t = ")
    assert ": robot hit obstacle at (1.8" in state["detail"]
    assert state["pose"][0] + 0.525 < 1.9  # the robot's front at the pillar's face (1.85)
