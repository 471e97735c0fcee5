# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""A stand-in for `kiseki serve`, speaking its API, for developing the page before the server
landed: the robot slides along straight legs at a fixed speed, with a fake particle cloud.

    python tests/python/fake_serve.py --taught DIR --port 8000
"""

from __future__ import annotations

import argparse
import asyncio
import io
import math
import random
from pathlib import Path

import uvicorn
import yaml
from fastapi import FastAPI, HTTPException, WebSocket, WebSocketDisconnect
from fastapi.responses import FileResponse, Response
from fastapi.staticfiles import StaticFiles
from PIL import Image

STATIC = Path(__file__).resolve().parents[2] / "py" / "kiseki" / "serve" / "static"


def build(taught: Path, speed: float) -> FastAPI:
    doc = yaml.safe_load((taught / "waypoints.yaml").read_text())
    meta = yaml.safe_load((taught / doc["maps"]["band"]["file"]).read_text())
    image = Image.open(taught / meta["image"])
    png = io.BytesIO()
    image.save(png, "PNG")
    wps = {w["name"]: [w["x"], w["y"], w["theta"]] for w in doc["waypoints"]}
    st = {
        "status": "idle",
        "route": None,
        "leg": None,
        "pose": list(wps[next(iter(wps))]),
        "estimate": list(wps[next(iter(wps))]),
        "speed": 0.0,
        "stop_error_m": None,
        "history": [],
        "phase": None,
    }
    task: dict = {}
    app = FastAPI()

    @app.get("/")
    def index():
        return FileResponse(STATIC / "index.html")

    @app.get("/api/waypoints")
    def waypoints():
        return {
            "waypoints": [{"name": n, "pose": p} for n, p in wps.items()],
            "map": {
                "resolution": meta["resolution"],
                "origin": meta["origin"],
                "width": image.width,
                "height": image.height,
            },
        }

    @app.get("/api/map")
    def get_map():
        return Response(png.getvalue(), media_type="image/png")

    @app.get("/api/state")
    def state():
        return st

    async def drive(rid: int, names: list[str], goal_leg: int):
        try:
            for i in range(len(names) - 1):
                st["leg"] = {
                    "index": i,
                    "count": len(names) - 1,
                    "from": names[i],
                    "to": names[i + 1],
                }
                a, b = wps[names[i]], wps[names[i + 1]]
                n = max(1, int(math.hypot(b[0] - a[0], b[1] - a[1]) / speed / 0.05))
                heading = math.atan2(b[1] - a[1], b[0] - a[0])
                for k in range(1, n + 1):
                    t = k / n
                    st["pose"] = [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), heading]
                    st["estimate"] = [st["pose"][0] + 0.03, st["pose"][1] - 0.02, heading]
                    st["speed"] = speed
                    await asyncio.sleep(0.05)
                if i == goal_leg:  # arrived at the goal
                    st["stop_error_m"] = 0.042
                    st["speed"], st["phase"] = 0.0, "dwell"
                    await asyncio.sleep(0.5)
                    st["phase"] = None
            st["status"] = "finished"
        except asyncio.CancelledError:
            st["status"] = "stopped"
        st["speed"] = 0.0
        st["history"].append(
            {
                "id": rid,
                "route": st["route"],
                "status": st["status"],
                "stop_error_m": st["stop_error_m"],
            }
        )

    @app.post("/api/routes", status_code=202)
    async def routes(body: dict):
        if st["status"] == "running":
            raise HTTPException(409, "a route is running: stop it or wait for it to finish")
        via = body.get("via", [])
        names = [body.get("start"), *via, body.get("goal"), *via[::-1], body.get("home")]
        unknown = [n for n in names if n not in wps]
        if unknown:
            raise HTTPException(422, f"unknown waypoint {', '.join(map(str, unknown))}")
        rid = len(st["history"]) + 1
        st.update(status="running", route={"id": rid, **body}, stop_error_m=None)
        task["t"] = asyncio.create_task(drive(rid, names, len(via)))
        return {"id": rid}

    @app.post("/api/stop")
    async def stop():
        if "t" in task and not task["t"].done():
            task["t"].cancel()
            await asyncio.sleep(0)
        return st

    @app.patch("/api/waypoints/{name}")
    def rename(name: str, body: dict):
        if name not in wps:
            raise HTTPException(404, f"no waypoint named {name}")
        wps[body["name"]] = wps.pop(name)
        return {"name": body["name"]}

    @app.websocket("/ws")
    async def ws(socket: WebSocket):
        await socket.accept()
        rng = random.Random(1)
        try:
            while True:
                e = st["estimate"]
                particles = [
                    [e[0] + rng.gauss(0, 0.15), e[1] + rng.gauss(0, 0.15), e[2]] for _ in range(200)
                ]
                await socket.send_json(
                    {
                        k: st[k]
                        for k in (
                            "status",
                            "pose",
                            "estimate",
                            "speed",
                            "leg",
                            "stop_error_m",
                            "phase",
                        )
                    }
                    | {"particles": particles}
                )
                await asyncio.sleep(0.1)
        except WebSocketDisconnect:
            pass

    app.mount("/", StaticFiles(directory=STATIC), name="static")
    return app


if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    parser.add_argument("--taught", type=Path, required=True)
    parser.add_argument("--port", type=int, default=8000)
    parser.add_argument("--speed", type=float, default=2.0)
    args = parser.parse_args()
    uvicorn.run(
        build(args.taught, args.speed), host="127.0.0.1", port=args.port, log_level="warning"
    )
