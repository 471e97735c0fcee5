# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""kiseki serve's JSON API and websocket (FastAPI's test client) on a route taught by
kiseki.teach in the demo's factory: every refusal, a full route start -> via -> goal -> home
with method both, two pages seeing the same poses, the stop, renames, the token, and the share
of routes stopping within 0.1 m of the goal over seeds with the server's defaults."""

from __future__ import annotations

import hashlib
import json
import math
import shutil
import struct
import subprocess
import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest
import yaml
from fastapi.testclient import TestClient
from starlette.testclient import WebSocketDenialResponse

from kiseki import load_map
from kiseki.apps.teach import teach
from kiseki.metrics import wilson_interval
from kiseki.serve import Robot, build_server
from kiseki.sim.scene import load_scene

ROUTE = {"start": "P0", "via": ["T1", "T2"], "goal": "G", "home": "P0"}
BASE = "http://127.0.0.1:8000"  # the server's default address: the Host it answers to
WS = "ws://127.0.0.1:8000/ws"


@pytest.fixture(scope="module")
def taught(tmp_path_factory, project_root):
    """The demo's route taught once (P0, T1, T2, G), the folder only read by these tests."""
    out = tmp_path_factory.mktemp("taught")
    teach(load_scene(project_root / "data" / "worlds" / "factory_turn.yaml"), out, seed=5)
    return out


@pytest.fixture
def folder(taught, tmp_path):
    """A copy of the taught folder that a test may rename waypoints in."""
    return shutil.copytree(taught, tmp_path / "taught")


def _digests(folder) -> dict:
    return {p.name: hashlib.sha1(p.read_bytes()).hexdigest() for p in folder.glob("map_*")}


def _client(folder, **options) -> TestClient:
    options = {"particles": 300, "speed_up": math.inf, "dwell": 0.5, **options}
    return TestClient(build_server(folder, **options).app, base_url=BASE)


def _wait(client: TestClient, done, timeout: float = 120.0, **headers) -> dict:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        state = client.get("/api/state", headers=headers).json()
        if done(state):
            return state
        time.sleep(0.05)
    raise AssertionError(f"timed out; last state {state}")


def test_waypoints_and_map_are_the_taught_ones(taught):
    doc = yaml.safe_load((taught / "waypoints.yaml").read_text(encoding="utf-8"))
    grid = load_map(taught / "map_band.yaml")  # method both plays on the band map
    with _client(taught) as client:
        body = client.get("/api/waypoints").json()
        png = client.get("/api/map")
        cells = client.get("/api/map", params={"format": "json"}).json()
        bad = client.get("/api/map", params={"format": "gif"})
        state = client.get("/api/state").json()
    assert [(w["name"], w["x"], w["y"]) for w in body["waypoints"]] == [
        (w["name"], w["x"], w["y"]) for w in doc["waypoints"]
    ]
    assert body["map"]["band"] == "band" and body["map"]["resolution"] == grid.resolution
    assert body["map"]["origin"][:2] == [grid.origin.x, grid.origin.y]
    # the PNG's header gives the map's size (IHDR: width, height after the 8-byte signature)
    assert png.headers["content-type"] == "image/png" and png.content[:8] == b"\x89PNG\r\n\x1a\n"
    assert struct.unpack(">II", png.content[16:24]) == (grid.width, grid.height)
    assert np.array_equal(np.array(cells["cells"]).reshape(grid.height, grid.width), grid.cells)
    assert bad.status_code == 422 and "png or json" in bad.json()["detail"]
    assert state["status"] == "idle" and state["route"] is None and state["history"] == []


@pytest.mark.parametrize(
    ("body", "words"),
    [
        ({**ROUTE, "goal": "X9"}, ["X9"]),  # unknown waypoint, named
        ({**ROUTE, "via": ["T1", "Q"]}, ["Q"]),
        ({**ROUTE, "home": "Nowhere"}, ["Nowhere"]),
        ({"start": "P0", "goal": "G"}, ["P0 -> G", "occupied"]),  # straight through the walls
        ({"start": "P0", "via": ["T2"], "goal": "G"}, ["P0 -> T2", "occupied"]),
        ({"start": "P0", "goal": "T1", "home": "G"}, ["T1 -> G", "occupied"]),  # the way back
        ({**ROUTE, "via": ["T1", "T1"]}, ["twice"]),
        ({"start": "P0", "via": ["T1"]}, ["goal", "required"]),  # missing field
        ({"start": "P0", "via": "T1", "goal": "G"}, ["via"]),  # not a list
        ({**ROUTE, "speed": 2}, ["speed"]),  # unknown field
    ],
)
def test_bad_routes_are_refused_with_422_naming_why(taught, body, words):
    with _client(taught) as client:
        response = client.post("/api/routes", json=body)
        assert client.get("/api/state").json()["status"] == "idle"  # nothing started
    assert response.status_code == 422, response.text
    detail = response.json()["detail"]
    assert isinstance(detail, str) and all(w in detail for w in words), detail


def test_malformed_json_gets_422(taught):
    with _client(taught) as client:
        response = client.post(
            "/api/routes", content=b'{"start": "P0",', headers={"content-type": "application/json"}
        )
    assert response.status_code == 422 and "invalid JSON" in response.json()["detail"]


def _collect(client: TestClient, out: list, path: str = WS) -> None:
    """Reads a page's websocket until the route is over."""
    with client.websocket_connect(path) as ws:
        while True:
            message = json.loads(ws.receive_text())
            out.append(message)
            if message["status"] in ("finished", "stopped") and message["route"] is not None:
                return


def test_full_route_with_method_both_stops_within_0_1_m_and_returns_home(taught):
    doc = yaml.safe_load((taught / "waypoints.yaml").read_text(encoding="utf-8"))
    truth = {w["name"]: w["truth"] for w in doc["waypoints"]}
    maps = _digests(taught)
    server = build_server(taught, method="both", particles=300, speed_up=math.inf, dwell=0.5)
    pages: list[list] = [[], []]
    with TestClient(server.app, base_url=BASE) as client:
        threads = [threading.Thread(target=_collect, args=(client, p)) for p in pages]
        for t in threads:
            t.start()
        _wait(client, lambda s: server.runner.broadcaster.count == 2, 10)
        response = client.post("/api/routes", json=ROUTE)
        assert response.status_code == 202, response.text
        route_id = response.json()["id"]
        for t in threads:
            t.join(120)
        state = _wait(client, lambda s: s["status"] != "running")
        # the next route starts where this one ended: the same robot and filter go on
        run = server.runner.robot.run
        rest = list(state["pose"])
        again = client.post(
            "/api/routes", json={"start": "P0", "via": ["T1"], "goal": "T2", "home": "T2"}
        )
        second = _wait(client, lambda s: s["status"] != "running")
        assert again.status_code == 202 and server.runner.robot.run is run
    assert state["status"] == "finished" and state["route"]["id"] == route_id
    # the stop error recomputed from the poses the pages received and the taught truth of G
    first = pages[0]
    outbound = [m for m in first if m["leg"] and m["leg"]["phase"] == "outbound"]
    at_goal = outbound[-1]["pose"]
    error = math.hypot(at_goal[0] - truth["G"][0], at_goal[1] - truth["G"][1])
    assert state["stop_error_m"] == pytest.approx(error, abs=2e-4) and error < 0.1
    assert outbound[-1]["speed"] == 0.0  # measured at rest
    # the legs in order: out through T1 and T2, the dwell, back the same way to P0
    legs = [(m["leg"]["phase"], m["leg"]["from"], m["leg"]["to"]) for m in first if m["leg"]]
    assert list(dict.fromkeys(legs)) == [
        ("outbound", "P0", "T1"),
        ("outbound", "T1", "T2"),
        ("outbound", "T2", "G"),
        ("dwell", None, None),
        ("return", "G", "T2"),
        ("return", "T2", "T1"),
        ("return", "T1", "P0"),
    ]
    dwell = [m for m in first if m["leg"] and m["leg"]["phase"] == "dwell"]
    assert len(dwell) == 5 and all(m["pose"] == at_goal for m in dwell)  # 0.5 s at 10 Hz
    assert math.hypot(rest[0] - truth["P0"][0], rest[1] - truth["P0"][1]) < 0.2  # home
    assert state["history"] == [
        {
            "id": route_id,
            **{k: ROUTE[k] for k in ("start", "via", "goal", "home")},
            "status": "finished",
            "stop_error_m": state["stop_error_m"],
            "duration_s": state["t"],
        }
    ]
    # both pages saw the same states: every message of one is the other's with that seq
    by_seq = [{m["seq"]: m for m in page} for page in pages]
    common = by_seq[0].keys() & by_seq[1].keys()
    assert len(common) > 500 and len(common) >= 0.95 * len(by_seq[0])
    assert all(by_seq[0][k] == by_seq[1][k] for k in common)
    moving = [m for m in first if m["speed"] > 0]
    assert moving and all(len(m["particles"]) == 200 for m in moving)
    # the second route went on from where the robot rested, not from P0's taught pose
    assert second["status"] == "finished" and len(second["history"]) == 2
    assert second["stop_error_m"] < 0.1
    assert run.result().truth[0][:2] == pytest.approx(rest[:2], abs=1e-4)
    assert run.result().truth[0][:2] != pytest.approx(truth["P0"][:2], abs=1e-3)
    assert _digests(taught) == maps  # the taught maps were never written


def test_second_route_409_and_stop_halts_at_the_acceleration_limit(taught):
    server = build_server(taught, particles=300, speed_up=1.0, dwell=0.5)
    assert isinstance(server.runner.robot, Robot)
    with TestClient(server.app, base_url=BASE) as client:
        assert client.post("/api/routes", json=ROUTE).status_code == 202
        busy = client.post("/api/routes", json={**ROUTE, "start": "T1", "via": ["T2"]})
        running = _wait(client, lambda s: s["speed"] > 0.3, 20)
        halt = client.post("/api/stop", json={})
        state = _wait(client, lambda s: s["status"] != "running", 10)
        time.sleep(0.3)
        later = client.get("/api/state").json()
        after = client.post("/api/routes", json={"start": "T1", "via": ["T2"], "goal": "G"})
        client.post("/api/stop", json={})
        _wait(client, lambda s: s["status"] != "running", 20)
    assert busy.status_code == 409 and "running" in busy.json()["detail"]
    assert halt.json()["stopping"] is True
    assert state["status"] == "stopped" and state["speed"] == 0.0 and state["command"] == [0, 0]
    assert state["stop_error_m"] is None and state["history"][-1]["status"] == "stopped"
    # braking from speed v at 0.5 m/s^2 takes v / 0.5 s, plus the period the stop waits for,
    # timed from the route's clock when the stop was taken (on a loaded machine the robot may
    # drive on between the state read and the stop request, and the stop may be taken a
    # control step late: 1.30 s measured once against 1.25 s, so two steps are allowed)
    assert running["t"] <= halt.json()["t"] <= state["t"]
    assert state["t"] - halt.json()["t"] <= halt.json()["speed"] / 0.5 + 0.45
    assert later["pose"] == state["pose"]  # at rest
    assert after.status_code == 202  # a stopped robot takes a new route


def test_rename_is_atomic_keeps_a_backup_and_refuses_bad_names(folder, monkeypatch):
    path = folder / "waypoints.yaml"
    original = path.read_bytes()
    maps = _digests(folder)
    with _client(folder) as client:
        renamed = client.patch("/api/waypoints/P0", json={"name": "Cell A"})
        listed = client.get("/api/waypoints").json()["waypoints"]
        old_name = client.post("/api/routes", json=ROUTE)
        refusals = {
            "duplicate": client.patch("/api/waypoints/T1", json={"name": "G"}),
            "unknown": client.patch("/api/waypoints/P7", json={"name": "P8"}),
            "comma": client.patch("/api/waypoints/T1", json={"name": "a,b"}),
            "empty": client.patch("/api/waypoints/T1", json={"name": ""}),
            "long": client.patch("/api/waypoints/T1", json={"name": "x" * 65}),
            "space": client.patch("/api/waypoints/T1", json={"name": " T1"}),
            "missing": client.patch("/api/waypoints/T1", json={}),
        }
        # a write that fails on the rename leaves the file as it was and no temporary file
        import kiseki._support.atomic

        def fail(src, dst):
            raise OSError("disk full")

        monkeypatch.setattr(kiseki._support.atomic.os, "replace", fail)
        failed = client.patch("/api/waypoints/T2", json={"name": "Shelf 2"})
        monkeypatch.undo()
    assert renamed.status_code == 200 and renamed.json()["waypoint"]["name"] == "Cell A"
    before = yaml.safe_load(original)
    now = yaml.safe_load(path.read_text(encoding="utf-8"))
    expected = {**before, "waypoints": [dict(w) for w in before["waypoints"]]}
    expected["waypoints"][0]["name"] = "Cell A"
    assert now == expected  # only the name changed
    assert (folder / "waypoints.yaml.bak").read_bytes() == original
    assert [w["name"] for w in listed] == ["Cell A", "T1", "T2", "G"]
    assert old_name.status_code == 422 and "P0" in old_name.json()["detail"]
    expected_status = {"duplicate": 409, "unknown": 404}
    for what, response in refusals.items():
        assert response.status_code == expected_status.get(what, 422), (what, response.text)
        assert isinstance(response.json()["detail"], str)
    assert failed.status_code == 500 and "not changed" in failed.json()["detail"]
    assert yaml.safe_load(path.read_text(encoding="utf-8")) == expected
    leftovers = sorted(p.name for p in folder.iterdir() if p.name.startswith("."))
    assert leftovers == [] and _digests(folder) == maps


def test_token_is_needed_when_set(taught):
    token = "s3cret-token"
    with _client(taught, token=token) as client:
        none = client.get("/api/state")
        wrong = client.get("/api/state", headers={"Authorization": "Bearer nope"})
        right = client.get("/api/state", headers={"Authorization": f"Bearer {token}"})
        post = client.post("/api/routes", json=ROUTE)
        stop = client.post("/api/stop", headers={"Authorization": "Basic s3cret-token"})
        page = client.get("/")
        with pytest.raises(WebSocketDenialResponse) as denied, client.websocket_connect(WS):
            pass
        with client.websocket_connect(f"{WS}?token={token}") as ws:
            by_query = json.loads(ws.receive_text())
        auth = {"Authorization": f"Bearer {token}"}
        with client.websocket_connect(WS, headers=auth) as ws:
            by_header = json.loads(ws.receive_text())
        state = client.get("/api/state", headers=auth).json()
    for response in (none, wrong, post, stop):
        assert response.status_code == 401 and "token" in response.json()["detail"]
    assert denied.value.status_code == 401
    assert right.status_code == 200 and state["status"] == "idle"  # the refused POST did nothing
    assert by_query["status"] == by_header["status"] == "idle"
    assert page.status_code != 401  # the page (no data) loads, then asks for the token


def _serve(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "kiseki.cli", "serve", *args], capture_output=True, text=True
    )


def test_command_refuses_bad_input_in_one_line(taught, tmp_path, project_root):
    corridor = project_root / "data" / "worlds" / "factory_corridor.yaml"
    one = shutil.copytree(taught, tmp_path / "one")
    doc = yaml.safe_load((one / "waypoints.yaml").read_text(encoding="utf-8"))
    doc["waypoints"] = doc["waypoints"][:1]
    (one / "waypoints.yaml").write_text(yaml.safe_dump(doc), encoding="utf-8")
    cases = {
        "no such folder": ["--taught", str(tmp_path / "nothing")],
        "no waypoint file": ["--taught", str(tmp_path)],
        "a route needs two": ["--taught", str(one)],
        "factory_turn.yaml, not this scene": ["--taught", str(taught), "--scene", str(corridor)],
        "method must be": ["--taught", str(taught), "--method", "best"],
        "--speed-up": ["--taught", str(taught), "--speed-up", "0"],
    }
    for words, args in cases.items():
        done = _serve(*args)
        lines = done.stderr.strip().splitlines()
        assert done.returncode == 1 and len(lines) == 1, (args, done.stderr)
        assert lines[0].startswith("kiseki: error:") and words in lines[0], lines[0]


def test_a_dwell_that_is_no_finite_time_and_a_speed_up_not_above_0_are_refused():
    """An infinite dwell was taken (an OverflowError at the goal) and True as 1 s; True as a
    speed-up of 1, text as a TypeError from the comparison."""
    from kiseki.serve.routes import RouteRunner

    for dwell in (-1.0, math.nan, math.inf, True):
        with pytest.raises(ValueError, match=r"^dwell must be a finite number >= 0 s, got "):
            RouteRunner(None, None, dwell=dwell)
    for speed_up in (0.0, -1.0, math.nan, True, "2"):
        with pytest.raises(ValueError, match=r"^speed_up must be > 0 \(inf: as fast as it steps\)"):
            RouteRunner(None, None, speed_up=speed_up)


# The route page's stop at the goal over seeds, with every option of the server at its default
# (method both, 1000 particles; the default seed 0 and the next seven). The criterion: the robot
# stops within the thesis' 0.1 m (sec. 2.2) in most routes, decided by the 95 % Wilson interval
# of the share lying above one half. The thesis' proposal 2 stopped within 0.1 m in 5 of 5 runs,
# whose Wilson interval (0.57-1) lies above one half too; 8 routes are the fewest at which one
# stop outside 0.1 m can still meet the criterion (7/8: lower bound 0.53; 5/6 and 6/7 cannot),
# so the test does not ask for a share the thesis' 5 runs cannot show either.
STOP_SEEDS = range(8)
MOST = 0.5


def _stop_error(taught, seed: int) -> float:
    server = build_server(taught, speed_up=math.inf, seed=seed)  # the rest: the defaults
    with TestClient(server.app, base_url=BASE) as client:
        started = client.post("/api/routes", json={**ROUTE, "home": "G"})  # no way back
        assert started.status_code == 202, started.text
        state = _wait(client, lambda s: s["status"] != "running", timeout=900)
    assert state["status"] == "finished", state["status"]
    return state["stop_error_m"]


def test_most_routes_stop_within_0_1_m_of_the_goal_over_seeds(taught):
    # two routes at a time: the depth rendering and the filter release the GIL
    with ThreadPoolExecutor(2) as pool:
        errors = list(pool.map(lambda s: _stop_error(taught, s), STOP_SEEDS))
    within = sum(e <= 0.1 for e in errors)
    low, _ = wilson_interval(within, len(errors))
    assert low > MOST, f"{within}/{len(errors)} within 0.1 m: {errors}"
