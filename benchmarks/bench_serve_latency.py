# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""kiseki serve's latency (printed, never asserted): from a POST /api/routes to the first
websocket message whose pose has moved, at real time, with the server on a real socket (uvicorn)
and a websocket client as a page would hold one. Each trial starts a route, waits for the first
moving pose, stops the robot and waits for it to rest; the robot is placed at the start anew.

Needs a taught run (kiseki demo writes results/demo/teach). Run:
python benchmarks/bench_serve_latency.py [--taught results/demo/teach] [--trials 10]
"""

from __future__ import annotations

import argparse
import json
import socket
import statistics
import threading
import time
from pathlib import Path

import httpx
import uvicorn
from websockets.sync.client import connect

from kiseki.serve import build_server
from timing import machine_line  # beside this file


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _trial(base: str, ws, route: dict) -> tuple[float, float]:
    """Seconds from the POST to the route's first message and to its first moved pose."""
    t0 = time.perf_counter()
    response = httpx.post(f"{base}/api/routes", json=route)
    response.raise_for_status()
    route_id, first_message, start_pose = response.json()["id"], None, None
    while True:
        message = json.loads(ws.recv())
        if message["route"] is None or message["route"]["id"] != route_id:
            continue
        now = time.perf_counter() - t0
        first_message = first_message or now
        pose = message["pose"]
        if pose is None or message["leg"] is None:
            continue
        if start_pose is None:
            start_pose = pose
        elif pose != start_pose:  # moved or turned
            return first_message, now


def _until_over(ws) -> None:
    """Reads the page's messages (as a page does) until the route is over."""
    while json.loads(ws.recv())["status"] == "running":
        pass


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--taught", type=Path, default=Path("results/demo/teach"))
    parser.add_argument("--method", default="both")
    parser.add_argument("--particles", type=int, default=1000)
    parser.add_argument("--trials", type=int, default=10)
    parser.add_argument("--continued", type=int, default=3, help="routes going on (~15 s each)")
    args = parser.parse_args()
    print(machine_line(), flush=True)
    server = build_server(args.taught, method=args.method, particles=args.particles)
    names = [w["name"] for w in server.taught.waypoints]
    route = {"start": names[0], "via": names[1:-1], "goal": names[-1]}
    port = _free_port()
    uv = uvicorn.Server(uvicorn.Config(server.app, "127.0.0.1", port, log_level="warning"))
    thread = threading.Thread(target=uv.run, daemon=True)
    thread.start()
    while not uv.started:
        time.sleep(0.01)
    base = f"http://127.0.0.1:{port}"
    firsts, moved, on_firsts, on_moved = [], [], [], []
    try:
        with connect(f"ws://127.0.0.1:{port}/ws") as ws:
            for _ in range(args.trials):
                first, move = _trial(base, ws, route)
                firsts.append(first)
                moved.append(move)
                httpx.post(f"{base}/api/stop")
                _until_over(ws)
        # routes that go on from where the previous one rested (same robot and filter): the
        # worker's case, without the new placement's collision check of the scene
        with connect(f"ws://127.0.0.1:{port}/ws") as ws:
            a, b = names[0], names[1]
            for k in range(args.continued + 1):
                start, goal = (a, b) if k % 2 == 0 else (b, a)
                first, move = _trial(base, ws, {"start": start, "goal": goal, "home": goal})
                if k > 0:  # the first one places the robot
                    on_firsts.append(first)
                    on_moved.append(move)
                _until_over(ws)
    finally:
        uv.should_exit = True
        thread.join(5)
    ms = [1000 * v for v in moved]
    print(
        f"kiseki serve ({args.method}, {args.particles} particles, real time, {args.trials} "
        f"trials, route {' -> '.join(names)})"
    )
    print(
        f"  POST -> first route message: median {1000 * statistics.median(firsts):.0f} ms, "
        f"max {1000 * max(firsts):.0f} ms"
    )
    print(
        f"  POST -> first moving pose:   median {statistics.median(ms):.0f} ms, "
        f"min {min(ms):.0f} ms, max {max(ms):.0f} ms (one control period is 100 ms)"
    )
    if on_moved:
        ms = [1000 * v for v in on_moved]
        print(
            f"  continued routes ({len(ms)}): POST -> first route message median "
            f"{1000 * statistics.median(on_firsts):.0f} ms; -> first moving pose median "
            f"{statistics.median(ms):.0f} ms, max {max(ms):.0f} ms"
        )


if __name__ == "__main__":
    main()
