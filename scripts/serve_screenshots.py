# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Re-makes docs/serve/*.png, the route-instruction page's screenshots, and measures the latency
from a click on "Start route" to the first pose drawn on the page.

    .venv/bin/python scripts/serve_screenshots.py [--taught DIR] [--out docs/serve] [--runs 5]

Without --taught it teaches data/worlds/factory_turn.yaml (seed 3) into a temporary folder. It
starts `kiseki serve` on a free port and drives Debian's headless chromium with Playwright.
"""

from __future__ import annotations

import argparse
import json
import shutil
import socket
import statistics
import subprocess
import sys
import tempfile
import time
import urllib.request
from pathlib import Path

from playwright.sync_api import sync_playwright

ROOT = Path(__file__).resolve().parents[1]
ROUTE = {"start": "P0", "via": ["T1", "T2"], "goal": "G", "home": "P0"}


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def get_state(base: str) -> dict:
    with urllib.request.urlopen(base + "api/state", timeout=5) as response:
        return json.loads(response.read())


def post(base: str, path: str) -> None:
    request = urllib.request.Request(base + path, data=b"{}", method="POST")
    request.add_header("Content-Type", "application/json")
    urllib.request.urlopen(request, timeout=5).close()


def start_server(taught: Path, port: int, log: Path) -> subprocess.Popen:
    command = [sys.executable, "-m", "kiseki.cli", "serve", "--taught", str(taught),
               "--speed-up", "4", "--dwell", "3", "--seed", "1"]  # fmt: skip
    out = open(log, "w")  # noqa: SIM115 (the server's output for the whole run)
    process = subprocess.Popen([*command, "--port", str(port)], stdout=out, stderr=out)
    base = f"http://127.0.0.1:{port}/"
    for _ in range(150):
        try:
            get_state(base)
            return process
        except OSError:
            time.sleep(0.2)
    process.kill()
    raise SystemExit(f"kiseki serve did not start:\n{log.read_text()}")


def pick_route(page) -> None:
    page.click("#clear-route")
    page.click(f".marker[data-waypoint='{ROUTE['start']}']")
    for name in ROUTE["via"]:
        page.click(f".marker[data-waypoint='{name}']")
    page.click(".role[data-role=goal]")
    page.click(f".marker[data-waypoint='{ROUTE['goal']}']")
    page.click(f".marker[data-waypoint='{ROUTE['home']}']")


def latency_ms(page, base: str) -> dict:
    """One click on start -> the 202 and the first pose drawn (performance.now() in the page),
    then a stop: the route always starts from rest at P0, with a new filter."""
    page.evaluate("window.kiseki.lastLatency = null")
    page.click("#start-route")
    page.wait_for_function("window.kiseki.lastLatency !== null", timeout=30_000)
    timing = page.evaluate("window.kiseki.lastLatency")
    post(base, "api/stop")
    page.wait_for_selector("body:not([data-status=running])", timeout=30_000)
    return timing


def shoot(base: str, out: Path, runs: int) -> dict:
    out.mkdir(parents=True, exist_ok=True)
    chromium = shutil.which("chromium") or "/usr/bin/chromium"
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=chromium, args=["--no-sandbox"])
        page = browser.new_page(viewport={"width": 1280, "height": 800})
        page.goto(base)
        page.wait_for_selector("body[data-connection=live]")
        pick_route(page)
        page.screenshot(path=out / "route.png")
        page.click("#start-route")
        page.wait_for_function(
            "(() => { const leg = window.kiseki.state.leg; return leg && leg.phase === 'outbound'"
            " && leg.index >= 1; })()",
            timeout=180_000,
        )
        page.wait_for_timeout(1500)  # past the turn at T1
        page.screenshot(path=out / "running.png")
        page.wait_for_selector("body[data-status=finished]", timeout=600_000)
        # a second route for the history: P0 -> T1 -> T2 and home
        page.click("#clear-route")
        page.click(".marker[data-waypoint='P0']")
        page.click(".marker[data-waypoint='T1']")
        page.click(".role[data-role=goal]")
        page.click(".marker[data-waypoint='T2']")
        page.click(".marker[data-waypoint='P0']")
        page.click("#start-route")
        page.wait_for_selector("body[data-status=running]")
        page.wait_for_selector("body[data-status=finished]", timeout=600_000)
        page.wait_for_timeout(500)
        page.screenshot(path=out / "history.png", full_page=True)
        pick_route(page)
        timings = [latency_ms(page, base) for _ in range(runs)]
        browser.close()
    return {
        name: {
            "runs": len(timings),
            "median": round(statistics.median(t[name] for t in timings), 1),
            "max": round(max(t[name] for t in timings), 1),
        }
        for name in ("click_to_accepted_ms", "click_to_first_pose_ms")
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--taught", type=Path, help="a kiseki teach folder (default: teach now)")
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "serve")
    parser.add_argument("--runs", type=int, default=10, help="clicks for the latency")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        taught = args.taught
        if taught is None:
            from kiseki.apps.teach import teach
            from kiseki.sim.scene import load_scene

            taught = Path(tmp) / "teach"
            teach(load_scene(ROOT / "data" / "worlds" / "factory_turn.yaml"), taught, seed=3)
        port = free_port()
        server = start_server(taught, port, Path(tmp) / "serve.log")
        try:
            figures = shoot(f"http://127.0.0.1:{port}/", args.out, args.runs)
        finally:
            server.terminate()
            server.wait(10)
    print(json.dumps(figures, indent=2))


if __name__ == "__main__":
    main()
