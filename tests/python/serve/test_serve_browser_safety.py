# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The route page's STOP and the server's refusals in a real browser (Debian's chromium driven
by Playwright), on a 3 m corridor taught here and served by `kiseki serve` as a subprocess:

- STOP halts the robot, and from the click on Start the page draws only this route's robot:
  never the previous route's pose or status as this one's, never a state older than one it drew,
  and after "stopped" only the pose it stopped at; idle, under CPU load (two busy processes),
  and with STOP pressed while the start is still on its way to a starved server (the server
  process paused), where the two requests may reach the server in either order.
- a page of another site (served from a second local port) can neither start nor stop a route
  on the loopback server, nor listen to the robot.

What the page shows is recorded by a MutationObserver on the status badge and the pose tile."""

from __future__ import annotations

import contextlib
import math
import os
import signal
import subprocess
import sys
import threading
import time
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer

import pytest
import yaml

from _helpers.serve_pages import (
    CHROMIUM,
    api,
    free_port,
    pick_route,
    playwright_or_skip,
    shown_pose,
    start_server,
    stop_server,
)

sync_playwright, expect = playwright_or_skip()

ROUTE = {"start": "P0", "via": ["P1"], "goal": "P2", "home": "P0"}
P0 = (0.0, 0.0)
OBSERVE = """() => {
  window.shown = [];
  const pose = document.getElementById('pose');
  const note = () => window.shown.push({t: performance.now(), status: document.body.dataset.status,
      x: pose.dataset.x, y: pose.dataset.y});
  new MutationObserver(note).observe(document.body,
      {attributes: true, subtree: true, attributeFilter: ['data-status', 'data-x', 'data-y']});
  note();
}"""


@pytest.fixture(scope="module")
def served(tmp_path_factory, project_root):
    """(process, base URL) of kiseki serve on the corridor cut to 3 m (P0, P1, P2 on x)."""
    from kiseki.apps.teach import teach
    from kiseki.sim.scene import load_scene

    root = tmp_path_factory.mktemp("safety")
    doc = yaml.safe_load((project_root / "data" / "worlds" / "factory_corridor.yaml").read_text())
    doc["route"]["waypoints"] = [[0.0, 0.0], [1.5, 0.0], [3.0, 0.0]]
    (root / "corridor.yaml").write_text(yaml.safe_dump(doc))
    teach(load_scene(root / "corridor.yaml"), root / "t", seed=1)
    command = [sys.executable, "-m", "kiseki.cli", "serve", "--taught", str(root / "t"),
               "--port", str(free_port()), "--speed-up", "4", "--dwell", "1", "--seed", "1",
               "--particles", "500"]  # fmt: skip
    process, base = start_server(command, root / "serve.log")
    yield process, base
    stop_server(process)


@pytest.fixture(scope="module")
def browser():
    with sync_playwright() as p:
        chromium = p.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox"])
        yield chromium
        chromium.close()


def settle(base: str) -> dict:
    api(base, "POST", "api/stop")
    deadline = time.monotonic() + 30
    while (state := api(base, "GET", "api/state")[1])["status"] == "running":
        assert time.monotonic() < deadline, "the robot did not stop"
        time.sleep(0.1)
    return state


def away(base: str, metres: float = 0.6) -> dict:
    """A route stopped once the robot is `metres` from P0: its pose there is not the next
    route's, whose start places the robot at P0 (the failure in CI showed such a pose)."""
    settle(base)
    assert api(base, "POST", "api/routes", ROUTE)[0] == 202
    deadline = time.monotonic() + 30
    while not (p := api(base, "GET", "api/state")[1]["pose"]) or math.dist(p[:2], P0) < metres:
        assert time.monotonic() < deadline, "the robot did not leave P0"
        time.sleep(0.05)
    return settle(base)


def ended(base: str, route: int, timeout: float = 10.0) -> dict:
    """The state once route `route` has started and ended (its STOP taken)."""
    deadline = time.monotonic() + timeout
    while True:
        state = api(base, "GET", "api/state")[1]
        if state["route"] and state["route"]["id"] == route and state["status"] != "running":
            return state
        assert time.monotonic() < deadline, f"the STOP was lost: the robot drives on, {state}"
        time.sleep(0.1)


def open_page(browser, base):
    page = browser.new_page(viewport={"width": 1280, "height": 800})
    page.js_errors = []
    page.on("pageerror", lambda err: page.js_errors.append(str(err)))
    page.goto(base)
    page.wait_for_selector("body[data-connection=live]")
    page.evaluate(OBSERVE)
    return page


def now(page) -> float:
    return page.evaluate("performance.now()")


@contextlib.contextmanager
def busy(processes: int):
    """`processes` busy loops beside the test (the CI machine that failed was loaded)."""
    loops = [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(processes)]
    try:
        yield
    finally:
        for loop in loops:
            loop.kill()
            loop.wait()


def check_what_was_drawn(page, previous: dict, clicked: float, stopped_at: float) -> tuple:
    """The page's record from the click on Start: asserts it and returns the stop pose."""
    shown = [s for s in page.evaluate("window.shown") if s["t"] >= clicked]
    poses = [(s["t"], (float(s["x"]), float(s["y"]))) for s in shown if s["x"]]
    assert poses, "the page drew no pose of the route"
    # the first pose drawn is this route's start, not the previous route's stop pose
    assert math.dist(poses[0][1], P0) < 0.1, (poses[0], previous["pose"])
    # "stopped" is shown only after the click on STOP, and from then on one pose only
    ends = [s["t"] for s in shown if s["status"] == "stopped"]
    assert ends and min(ends) >= stopped_at, (shown[:5], stopped_at)
    rest = {p for t, p in poses if t >= min(ends)}
    assert len(rest) == 1, rest
    (still,) = rest
    # no pose drawn after the click on STOP lies behind one drawn before it on the route
    before = max(math.dist(p, P0) for t, p in poses if t < stopped_at)
    assert math.dist(still, P0) >= before - 1e-3, (still, before)
    # the page's own record: the states it drew, never an older one than the last
    drawn = page.evaluate("window.kiseki.drawn")
    seqs = [d["seq"] for d in drawn if d["epoch"] == drawn[-1]["epoch"]]
    assert seqs == sorted(seqs)
    return still


@pytest.mark.parametrize("loops", [0, 2], ids=["idle", "loaded"])
def test_stop_halts_the_robot_and_the_page_draws_only_its_route(browser, served, loops):
    process, base = served
    previous = away(base)
    page = open_page(browser, base)
    with busy(loops):
        pick_route(page, ROUTE)
        clicked = now(page)
        page.click("#start-route")
        deadline = time.monotonic() + 30
        while not ((p := shown_pose(page)) and math.dist(p, P0) > 0.3):
            assert time.monotonic() < deadline, "the page did not show the robot moving"
            page.wait_for_timeout(50)
        stopped_at = now(page)
        page.click("#stop")
        expect(page.locator("body")).to_have_attribute("data-status", "stopped", timeout=10_000)
        page.wait_for_timeout(1000)
        state = api(base, "GET", "api/state")[1]
        time.sleep(0.5)
        later = api(base, "GET", "api/state")[1]
    still = check_what_was_drawn(page, previous, clicked, stopped_at)
    assert state["route"]["id"] == previous["route"]["id"] + 1 and state["status"] == "stopped"
    assert tuple(state["pose"][:2]) == still == tuple(later["pose"][:2])  # at rest, as drawn
    assert shown_pose(page) == still and not page.js_errors
    page.close()


def test_a_stop_pressed_while_the_start_is_on_its_way_is_not_lost(browser, served):
    """The server paused (SIGSTOP) for 0.6 s around the clicks on Start and STOP: the page
    shows "starting" meanwhile, not the previous route's "stopped", and the STOP is sent
    again once the start is answered (the server took it first, and then the start, twice in
    four runs of the landed page, and the robot drove on)."""
    process, base = served
    previous = away(base)
    page = open_page(browser, base)
    pick_route(page, ROUTE)
    clicked = now(page)
    os.kill(process.pid, signal.SIGSTOP)
    try:
        page.click("#start-route")
        stopped_at = now(page)
        page.click("#stop")
        page.wait_for_timeout(600)
        waiting = page.locator("body").get_attribute("data-status")
    finally:
        os.kill(process.pid, signal.SIGCONT)
    state = ended(base, previous["route"]["id"] + 1)
    assert state["status"] == "stopped" and state["detail"] == "stopped"
    assert math.dist(state["pose"][:2], P0) < 0.3  # stopped as it set off
    assert waiting == "starting"  # not the previous route's "stopped"
    expect(page.locator("body")).to_have_attribute("data-status", "stopped", timeout=10_000)
    page.wait_for_timeout(500)
    shown = [s for s in page.evaluate("window.shown") if s["t"] >= clicked]
    assert all(s["status"] != "stopped" or s["t"] > stopped_at + 500 for s in shown), shown
    assert shown_pose(page) == tuple(state["pose"][:2]) and not page.js_errors
    page.close()


EVIL_PAGE = """<!doctype html><meta charset="utf-8"><title>another site</title>
<form id="stop" method="POST" action="{base}api/stop"><input name="x" value="1"></form>
<script>
const route = {{"start": "P0", "via": ["P1"], "goal": "P2", "home": "P0"}};
async function attack(kind) {{
  const body = JSON.stringify(route);
  try {{
    if (kind === "blob") {{  // a "simple" request: no preflight, no Content-Type at all
      await fetch("{base}api/routes", {{method: "POST", mode: "no-cors", body: new Blob([body])}});
    }} else if (kind === "text") {{
      await fetch("{base}api/routes", {{method: "POST", mode: "no-cors",
        headers: {{"Content-Type": "text/plain"}}, body}});
    }} else if (kind === "json") {{  // preflighted
      await fetch("{base}api/routes", {{method: "POST",
        headers: {{"Content-Type": "application/json"}}, body}});
    }} else if (kind === "stop") {{
      await fetch("{base}api/stop", {{method: "POST", mode: "no-cors"}});
    }}
    return "sent";
  }} catch (err) {{
    return "blocked";
  }}
}}
function listen() {{
  return new Promise((done) => {{
    const ws = new WebSocket("{base}".replace("http", "ws") + "ws");
    ws.onmessage = (e) => done("heard " + e.data.slice(0, 40));
    ws.onerror = () => done("refused");
    ws.onclose = () => done("refused");
    setTimeout(() => done("silent"), 3000);
  }});
}}
</script>"""


@contextlib.contextmanager
def another_site(base: str):
    """A page of another origin (a second local HTTP server): its URL."""
    text = EVIL_PAGE.format(base=base).encode()

    class Page(BaseHTTPRequestHandler):
        def do_GET(self):  # noqa: N802 (http.server's name)
            self.send_response(200)
            self.send_header("Content-Type", "text/html")
            self.end_headers()
            self.wfile.write(text)

        def log_message(self, *args):
            pass

    server = ThreadingHTTPServer(("127.0.0.1", free_port()), Page)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}/"
    finally:
        server.shutdown()
        server.server_close()


def test_a_page_of_another_site_cannot_start_stop_or_listen(browser, served):
    _, base = served
    idle = settle(base)
    with another_site(base) as url:
        page = browser.new_page()
        page.goto(url)
        results = {k: page.evaluate(f"attack('{k}')") for k in ("blob", "text", "json")}
        heard = page.evaluate("listen()")
        after_start = api(base, "GET", "api/state")[1]
        assert api(base, "POST", "api/routes", ROUTE)[0] == 202  # the worker's own route
        results["stop"] = page.evaluate("attack('stop')")
        with page.expect_navigation():
            page.eval_on_selector("#stop", "form => form.submit()")
        answer = page.content()
        time.sleep(0.3)
        running = api(base, "GET", "api/state")[1]
        page.close()
    settle(base)
    assert running["status"] == "running" and running["detail"] is None, running
    assert "another site" in answer  # the form's POST got the 403
    assert heard in ("refused", "silent"), heard
    assert results["json"] == "blocked"  # the preflight is refused
    assert after_start["status"] == idle["status"] and after_start["route"] == idle["route"]
