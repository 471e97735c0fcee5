# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What the route page's browser tests share: Debian's chromium and Playwright, a free port,
the JSON API called as a script would (no Origin), `kiseki serve` started as a subprocess, the
route picked by taps, and the pose the page shows."""

from __future__ import annotations

import json
import os
import shutil
import socket
import subprocess
import time
import urllib.error
import urllib.request
from pathlib import Path

import pytest

CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
IN_CI = os.environ.get("CI", "").lower() == "true"


def playwright_or_skip():
    """Playwright's ``(sync_playwright, expect)`` for a browser test module: outside CI a
    missing Debian chromium or playwright skips the module with a message; under CI their
    absence is an error."""
    if not Path(CHROMIUM).exists() and not IN_CI:
        pytest.skip(
            "Debian's chromium is not installed (apt-get install chromium; CI runs these tests)",
            allow_module_level=True,
        )
    if not IN_CI:
        pytest.importorskip("playwright.sync_api")
    from playwright.sync_api import expect, sync_playwright

    return sync_playwright, expect


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def api(base: str, method: str, path: str, body: dict | None = None) -> tuple[int, dict]:
    data = json.dumps({} if body is None and method != "GET" else body).encode()
    request = urllib.request.Request(base + path, data=None if method == "GET" else data,
                                     method=method)  # fmt: skip
    request.add_header("Content-Type", "application/json")
    try:
        with urllib.request.urlopen(request, timeout=10) as response:
            return response.status, json.loads(response.read() or b"null")
    except urllib.error.HTTPError as err:
        return err.code, json.loads(err.read() or b"null")


def start_server(command: list[str], log: Path, expect: int = 200):
    """`command` (kiseki serve on 127.0.0.1) started, its output to `log`, once GET /api/state
    answers `expect`: (process, base URL)."""
    port = command[command.index("--port") + 1]
    out = open(log, "w")  # noqa: SIM115 (the process writes it until it ends)
    process = subprocess.Popen(command, stdout=out, stderr=subprocess.STDOUT)
    base = f"http://127.0.0.1:{port}/"
    deadline = time.monotonic() + 30
    while True:
        try:
            if api(base, "GET", "api/state")[0] == expect:
                return process, base
        except OSError:
            pass
        if process.poll() is not None or time.monotonic() > deadline:
            process.kill()
            raise AssertionError(f"kiseki serve did not start:\n{log.read_text()}")
        time.sleep(0.2)


def stop_server(process: subprocess.Popen) -> None:
    process.terminate()
    process.wait(10)


def pick_route(page, route: dict) -> None:
    """Taps the markers: Start, the vias in order, Goal, Home (the role moves on by itself)."""
    page.click(".role[data-role=start]")
    page.click(f".marker[data-waypoint='{route['start']}']")
    for name in route["via"]:
        page.click(f".marker[data-waypoint='{name}']")
    page.click(".role[data-role=goal]")
    page.click(f".marker[data-waypoint='{route['goal']}']")
    page.click(f".marker[data-waypoint='{route['home']}']")


def shown_pose(page) -> tuple[float, float] | None:
    """The true pose the page shows (None when it shows none)."""
    x, y = page.eval_on_selector("#pose", "e => [e.dataset.x, e.dataset.y]")
    return (float(x), float(y)) if x else None
