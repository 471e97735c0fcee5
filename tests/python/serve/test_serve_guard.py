# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What kiseki serve refuses and keeps (FastAPI's test client, on a 3 m corridor taught the way
a user teaches it: `cd ROOT; kiseki teach worlds/corridor.yaml -o t`): on loopback another Host
(DNS rebinding) and another site's Origin get 403, on HTTP and the websocket alike; changes take
only JSON; the route's fields have limits; the history of finished routes survives a restart;
the taught run finds its scene from any working directory."""

from __future__ import annotations

import asyncio
import json
import shutil
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml
from fastapi.testclient import TestClient
from starlette.testclient import WebSocketDenialResponse

from kiseki.apps.teach import teach
from kiseki.apps.teach.teaching import recover
from kiseki.serve import build_server
from kiseki.sim.scene import load_scene
from kiseki.teach.scene_identity import check_scene, scene_digest, taught_scene_of
from kiseki.teach.waypoint_schema import MAX_NAME_LENGTH, read_waypoint_file

BASE = "http://127.0.0.1:8000"  # the address build_server serves by default
WS = "ws://127.0.0.1:8000/ws"
EVIL = {"Origin": "http://evil.example"}
SHORT = {"start": "P0", "goal": "P1", "home": "P1"}  # 1.5 m out, no way back
TEXT = {"Content-Type": "text/plain"}


@pytest.fixture(scope="module")
def root(tmp_path_factory, project_root) -> Path:
    """ROOT/worlds/corridor.yaml (the factory corridor cut to 3 m) taught into ROOT/t from
    ROOT, the scene named relative to that working directory."""
    root = tmp_path_factory.mktemp("guard")
    doc = yaml.safe_load((project_root / "data" / "worlds" / "factory_corridor.yaml").read_text())
    doc["route"]["waypoints"] = [[0.0, 0.0], [1.5, 0.0], [3.0, 0.0]]
    (root / "worlds").mkdir()
    (root / "worlds" / "corridor.yaml").write_text(yaml.safe_dump(doc))
    with pytest.MonkeyPatch.context() as patch:
        patch.chdir(root)
        teach(load_scene(Path("worlds/corridor.yaml")), Path("t"), seed=1)
    return root


def client(folder: Path, base: str = BASE, **options) -> TestClient:
    options = {"particles": 100, "speed_up": float("inf"), "dwell": 0.1, **options}
    return TestClient(build_server(folder, **options).app, base_url=base)


def wait_over(client: TestClient, timeout: float = 60.0) -> dict:
    end = time.monotonic() + timeout
    while (state := client.get("/api/state").json())["status"] == "running":
        assert time.monotonic() < end, state
        time.sleep(0.05)
    return state


def test_loopback_answers_only_to_the_names_of_its_address(root):
    with client(root / "t") as c:
        answers = {
            host: c.get("/api/state", headers={"Host": host}).status_code
            for host in ("127.0.0.1:8000", "localhost:8000", "evil.example", "evil.example:8000",
                         "127.0.0.1:8001", "[::1]:8000", "")
        }  # fmt: skip
        page = c.get("/", headers={"Host": "evil.example"})
        evil = {"Host": "evil.example"}
        with pytest.raises(WebSocketDenialResponse) as ws, c.websocket_connect(WS, headers=evil):
            pass
        refused = c.get("/api/state", headers={"Host": "evil.example"}).json()["detail"]
    assert answers == {"127.0.0.1:8000": 200, "localhost:8000": 200, "evil.example": 403,
                       "evil.example:8000": 403, "127.0.0.1:8001": 403, "[::1]:8000": 403,
                       "": 403}  # fmt: skip
    assert page.status_code == 403 and ws.value.status_code == 403
    assert "http://127.0.0.1:8000/" in refused and "evil.example" in refused
    with client(root / "t", "http://[::1]:8000", host="::1") as c:
        assert c.get("/api/state").status_code == 200
        assert c.get("/api/state", headers={"Host": "127.0.0.1:8000"}).status_code == 403
    # beyond loopback the token guards: any name reaches the server
    with client(root / "t", "http://kiseki.lan:8000", host="0.0.0.0", token="t0ken") as c:
        auth = {"Authorization": "Bearer t0ken"}
        assert c.get("/api/state", headers=auth).status_code == 200


def test_another_sites_pages_cannot_start_stop_rename_or_listen(root, tmp_path):
    folder = shutil.copytree(root / "t", tmp_path / "t")
    before = (folder / "waypoints.yaml").read_bytes()
    with client(folder, speed_up=1.0, scene=root / "worlds" / "corridor.yaml") as c:
        start = c.post("/api/routes", json=SHORT, headers=EVIL)
        idle = c.get("/api/state").json()
        rename = c.patch("/api/waypoints/P0", json={"name": "X"}, headers=EVIL)
        with pytest.raises(WebSocketDenialResponse) as ws, c.websocket_connect(WS, headers=EVIL):
            pass
        own = c.post("/api/routes", json=SHORT, headers={"Origin": BASE})  # the page's own
        stop = c.post("/api/stop", json={}, headers=EVIL)
        running = c.get("/api/state").json()
        c.post("/api/stop", json={})
        wait_over(c)
    assert start.status_code == 403 and "another site" in start.json()["detail"]
    assert idle["status"] == "idle" and idle["route"] is None
    assert rename.status_code == 403 and (folder / "waypoints.yaml").read_bytes() == before
    assert ws.value.status_code == 403
    assert own.status_code == 202
    assert stop.status_code == 403 and running["status"] == "running"
    assert running["detail"] is None  # the refused stop did not touch the route
    with client(root / "t", host="0.0.0.0", token="t0ken") as c:  # the token is not enough
        auth = {"Authorization": "Bearer t0ken"}
        assert c.post("/api/stop", json={}, headers={**auth, **EVIL}).status_code == 403


def test_changes_take_only_a_json_body(root):
    with client(root / "t") as c:
        answers = [
            c.post("/api/routes", data=SHORT),  # a form
            c.post("/api/routes", content=json.dumps(SHORT), headers=TEXT),
            c.post("/api/routes", files={"start": ("a", b"P0")}),  # multipart
            c.post("/api/stop"),  # no body and no type: what a no-cors fetch sends
            c.post("/api/stop", data={"x": "1"}),
        ]
        state = c.get("/api/state").json()
        ok = c.post("/api/stop", json={})
    for response in answers:
        assert response.status_code == 415, response.text
        assert "application/json" in response.json()["detail"]
    assert state["status"] == "idle" and ok.status_code == 200


def test_the_routes_fields_have_limits_and_a_refusal_says_which(root):
    with client(root / "t") as c:
        many = c.post("/api/routes", json={**SHORT, "via": ["P2"] * 101})
        long_name = c.post("/api/routes", json={**SHORT, "goal": "G" * 65})
        huge = c.post("/api/routes", json={**SHORT, "via": ["x" * 60] * 2000})
        rename = c.patch("/api/waypoints/P0", json={"name": "n" * 10_000})
        state = c.get("/api/state").json()
    assert many.status_code == 422 and "via" in many.json()["detail"]
    assert "at most 100 items" in many.json()["detail"]
    assert long_name.status_code == 422 and "at most 64 characters" in long_name.json()["detail"]
    assert huge.status_code == 413 and "65536 bytes" in huge.json()["detail"]
    assert rename.status_code == 422 and "at most 64 characters" in rename.json()["detail"]
    for response in (many, long_name, huge, rename):
        assert len(response.text) < 300, response.text  # the value is not echoed back
    assert state["status"] == "idle"


PIECE = 64 * 1024  # one piece of a chunked upload


def padded(spaces: int, pulled: list | None = None):
    """SHORT as JSON after `spaces` bytes of whitespace, in pieces (httpx sends a generator
    with Transfer-Encoding: chunked, no Content-Length); `pulled` counts the pieces taken."""
    for _ in range(spaces // PIECE):
        if pulled is not None:
            pulled.append(PIECE)
        yield b" " * PIECE
    yield json.dumps(SHORT).encode()


def test_the_body_limit_holds_for_a_chunked_body(root):
    """Was read whole and parsed: the limit looked only at Content-Length."""
    json_type = {"Content-Type": "application/json"}
    with client(root / "t") as c:
        chunked = c.post("/api/routes", content=padded(1 << 20), headers=json_type)
        state = c.get("/api/state").json()
        small = c.post("/api/stop", content=iter([b"{}"]), headers=json_type)  # chunked, small
    assert "content-length" not in chunked.request.headers
    assert chunked.request.headers["transfer-encoding"] == "chunked"
    assert chunked.status_code == 413, chunked.text
    assert chunked.json()["detail"] == "the body is limited to 65536 bytes"
    assert state["status"] == "idle" and state["route"] is None  # nothing was started
    assert small.status_code == 200, small.text


def test_a_chunked_body_is_not_read_past_the_limit(root):
    """Uvicorn hands the app a chunked body piece by piece as it arrives: 50 MB of whitespace
    are refused after the second 64 KiB piece, not read to the end."""
    server = build_server(root / "t", particles=10)
    pulled: list[int] = []
    pieces = padded(50 * 1024 * 1024, pulled)
    sent: list[dict] = []

    async def receive() -> dict:
        piece = next(pieces, None)
        return {"type": "http.request", "body": piece or b"", "more_body": piece is not None}

    async def send(message: dict) -> None:
        sent.append(message)

    headers = [(b"host", b"127.0.0.1:8000"), (b"content-type", b"application/json"),
               (b"transfer-encoding", b"chunked")]  # fmt: skip
    scope = {
        "type": "http", "asgi": {"version": "3.0"}, "http_version": "1.1", "method": "POST",
        "scheme": "http", "path": "/api/routes", "raw_path": b"/api/routes", "root_path": "",
        "query_string": b"", "headers": headers, "client": ("127.0.0.1", 40000),
        "server": ("127.0.0.1", 8000),
    }  # fmt: skip
    try:
        asyncio.run(server.app(scope, receive, send))
    finally:
        server.runner.close()
    start = next(m for m in sent if m["type"] == "http.response.start")
    body = b"".join(m.get("body", b"") for m in sent if m["type"] == "http.response.body")
    assert start["status"] == 413, body
    assert json.loads(body) == {"detail": "the body is limited to 65536 bytes"}
    assert sum(pulled) <= 2 * PIECE  # of 50 MiB


def test_a_waypoint_name_may_have_64_characters_everywhere(root, tmp_path):
    """A rename stopped at 32 characters while the waypoint file, a route, the history and the
    README take names of 64."""
    folder = shutil.copytree(root / "t", tmp_path / "t")
    longest = "Cell " + "a" * (MAX_NAME_LENGTH - 5)
    with client(folder, scene=root / "worlds" / "corridor.yaml") as c:
        renamed = c.patch("/api/waypoints/P0", json={"name": longest})
        too_long = c.patch("/api/waypoints/P1", json={"name": longest + "b"})
        listed = [w["name"] for w in c.get("/api/waypoints").json()["waypoints"]]
    assert MAX_NAME_LENGTH == 64
    assert renamed.status_code == 200, renamed.text
    assert too_long.status_code == 422 and "at most 64 characters" in too_long.json()["detail"]
    assert listed == [longest, "P1", "P2"]
    assert read_waypoint_file(folder / "waypoints.yaml").waypoints[0].name == longest


def test_the_history_of_finished_routes_survives_a_restart(root, tmp_path):
    history = tmp_path / "routes.json"
    with client(root / "t", history=history) as c:
        first = c.post("/api/routes", json=SHORT).json()["id"]
        done = wait_over(c)
    doc = json.loads(history.read_text())
    assert doc["kind"] == "kiseki route history" and doc["routes"] == done["history"]
    assert [r["id"] for r in done["history"]] == [first] and done["status"] == "finished"
    with client(root / "t", history=history) as c:  # the server restarted
        kept = c.get("/api/state").json()["history"]
        second = c.post("/api/routes", json={"start": "P1", "goal": "P0", "home": "P0"}).json()
        wait_over(c)
    assert kept == done["history"]
    assert second["id"] == first + 1  # ids go on
    assert [r["id"] for r in json.loads(history.read_text())["routes"]] == [first, first + 1]
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporary left


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ('{"kind": "kiseki route history", "version": 1, "routes": [', "invalid JSON at line 1"),
        ('{"kind": "kiseki route history", "version": 1, "routes": [{"id": 1}]}',
         "routes[0].start: missing"),
        ("[1, 2]", "not a route history"),
    ],
)  # fmt: skip
def test_a_corrupt_history_stops_the_server_in_one_line_and_is_kept(root, tmp_path, text, words):
    history = tmp_path / "routes.json"
    history.write_text(text)
    done = subprocess.run(
        [sys.executable, "-m", "kiseki.cli", "serve", "--taught", str(root / "t"),
         "--port", "8765", "--history", str(history)],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    lines = done.stderr.strip().splitlines()
    assert done.returncode == 1 and len(lines) == 1, done.stderr
    assert str(history) in lines[0] and words in lines[0], lines[0]
    assert history.read_text() == text  # never dropped nor overwritten


def serve(root: Path, tmp_path: Path, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "kiseki.cli", "serve", "--taught", str(root / "t"),
         "--history", str(tmp_path / "routes.json"), *args],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip


def test_a_port_in_use_or_a_bad_host_is_one_line_and_nothing_printed(root, tmp_path):
    """Were uvicorn's "ERROR: [Errno 98] ..." and exit 3 (kiseki's own bugs), after the URL and
    the access token had been printed."""
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        in_use = serve(root, tmp_path, "--port", str(port))
    bad_host = serve(root, tmp_path, "--host", "0.0.0.0.0", "--port", str(port))
    assert (in_use.returncode, in_use.stdout) == (1, ""), in_use.stdout + in_use.stderr
    assert in_use.stderr.splitlines() == [
        f"kiseki: error: --port {port} on 127.0.0.1: address already in use"
    ]
    assert (bad_host.returncode, bad_host.stdout) == (1, ""), bad_host.stdout + bad_host.stderr
    lines = bad_host.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("kiseki: error: --host 0.0.0.0.0: "), lines
    assert not (tmp_path / "routes.json").exists()


def test_serve_listens_on_the_sockets_it_bound(root, tmp_path):
    """The control: on a free port the server starts, answers and stops on SIGTERM."""
    from _helpers.serve_pages import api, free_port, start_server

    port = free_port()
    command = [sys.executable, "-m", "kiseki.cli", "serve", "--taught", str(root / "t"),
               "--port", str(port), "--history", str(tmp_path / "routes.json"),
               "--particles", "10"]  # fmt: skip
    process, base = start_server(command, tmp_path / "serve.log")
    try:
        status, state = api(base, "GET", "api/state")
    finally:
        process.terminate()
        process.wait(30)
    log = (tmp_path / "serve.log").read_text()
    assert status == 200 and state["status"] == "idle"
    assert f"on http://127.0.0.1:{port}/" in log and "ERROR" not in log, log
    assert process.returncode == 143, log  # SIGTERM, as every command ends on it


def test_the_taught_run_finds_its_scene_from_any_folder(root, tmp_path, monkeypatch):
    scene = (root / "worlds" / "corridor.yaml").resolve()
    recorded = yaml.safe_load((root / "t" / "waypoints.yaml").read_text())["scene_file"]
    assert recorded == "../worlds/corridor.yaml"  # from the taught folder
    monkeypatch.chdir(tmp_path)
    assert build_server(root / "t", particles=10).scene == scene  # kiseki serve --taught DIR
    # kiseki playback records and names the taught scene as found, wherever it runs
    identity = check_scene(taught_scene_of(root / "t" / "waypoints.yaml"), scene)
    assert identity["taught_scene_file"] == str(scene)
    # teach --resume from here records the scene from its own output folder
    again = recover(load_scene(scene), root / "t" / "teach.mcap", tmp_path / "r")
    assert again.scene.path() == scene and again.scene.sha1 == scene_digest(scene)
    # a run taught before: the scene recorded from the teaching's working directory
    old = shutil.copytree(root / "t", root / "old")
    doc = yaml.safe_load((old / "waypoints.yaml").read_text())
    doc["scene_file"] = "worlds/corridor.yaml"
    (old / "waypoints.yaml").write_text(yaml.safe_dump(doc, sort_keys=False))
    with pytest.raises(FileNotFoundError, match="give --scene"):
        build_server(old, particles=10)
    assert build_server(old, scene=scene, particles=10).scene == scene
    monkeypatch.chdir(root)  # where it was taught: found as before
    assert build_server(old, particles=10).scene == scene
