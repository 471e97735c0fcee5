# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``kiseki serve``: the route-instruction page over a taught run (the factory AGV's main job)."""

from __future__ import annotations

import secrets
from pathlib import Path

import typer
import uvicorn
from rich.console import Console

from kiseki._support.guard import Rewrites, guarded
from kiseki._support.options import PARTICLE_LIMIT, Count, Fraction, Seconds, Seed
from kiseki.apps.teach import PlaybackConfig
from kiseki.cli._defaults import default_of
from kiseki.serve import HISTORY_FILE, LOOPBACK, build_server, listening_sockets

__all__ = ["app"]

app = typer.Typer()
console = Console(soft_wrap=True)  # piped: one line stays one line (grep, awk)
# kiseki serve rewrites files of its taught run in place (the waypoint file, on a rename, by
# itself); --history may be the route history there, its default
_SERVED = Rewrites("taught", ("route_history.json",))


@app.command("serve")
@guarded(inputs=(_SERVED, "scene"), outputs=("history",))
def serve_command(
    taught: Path = typer.Option(..., help="Folder written by kiseki teach (or kiseki demo's)."),
    scene: Path | None = typer.Option(
        None, help="Scene YAML the run was taught in (default: the one its log records)."
    ),
    method: str = typer.Option("both", help="conventional, proposal1, proposal2 or both."),
    host: str = typer.Option("127.0.0.1", help="Address to bind; beyond loopback a token."),
    port: int = typer.Option(8000, parser=Count("--port", 1, 65_535), help="TCP port."),
    # at most an hour at the goal (the page waits for the robot's return), and at most 1000x
    # real time (a 10 Hz robot would step 10,000 times a wall-clock second)
    dwell: float = typer.Option(
        5.0,
        parser=Seconds("--dwell", 0, 3600),
        help="Seconds the robot waits at the goal (part taken).",
    ),
    speed_up: float = typer.Option(
        1.0,
        parser=Fraction("--speed-up", 0, 1000, lo_open=True),
        help="Simulated seconds per wall-clock second.",
    ),
    particles: int = typer.Option(
        default_of(PlaybackConfig, "particles"),
        parser=Count("--particles", 1, PARTICLE_LIMIT),
        help="Particles of the localization filter.",
    ),
    seed: int = typer.Option(
        default_of(PlaybackConfig, "seed"), parser=Seed(), help="Seed of the run's noise."
    ),
    history: Path | None = typer.Option(
        None,
        help="JSON file of the finished routes: loaded at start, rewritten (atomically) after "
        "each route (default: route_history.json in the --taught folder).",
    ),
) -> None:
    """Serve the route-instruction page and its JSON API over a taught run: a worker picks
    start, via and goal waypoints, the simulated AGV drives there, stops within 0.1 m, dwells
    and returns home, watched live over a websocket. Binding beyond loopback prints an access
    token that every API request must carry (Authorization: Bearer TOKEN).

    Example: kiseki serve --taught results/demo/teach"""
    token = None if host in LOOPBACK else secrets.token_urlsafe(24)
    history = taught / HISTORY_FILE if history is None else history
    server = build_server(
        taught, scene, method, token, dwell, speed_up, particles, seed,
        host=host, port=port, history=history,
    )  # fmt: skip

    # bound before anything is printed: a port in use or a bad --host is one line, exit 1
    sockets = listening_sockets(host, port)
    names = ", ".join(w["name"] for w in server.taught.waypoints)
    # the token rides in the URL's fragment: the browser never sends it, so no log has it
    url = f"http://{f'[{host}]' if ':' in host else host}:{port}/"
    console.print(
        f"kiseki serve: {taught} ({method}, waypoints {names}; scene {server.scene}; history "
        f"{history}) on {url}{'' if token is None else f'#token={token}'}",
        soft_wrap=True,
    )
    if token is not None:
        console.print(f"access token: {token}  (Authorization: Bearer TOKEN)", soft_wrap=True)
    config = uvicorn.Config(server.app, host=host, port=port, log_level="warning")
    try:
        uvicorn.Server(config).run(sockets=sockets)
    except KeyboardInterrupt:  # Ctrl-C: the server has shut down (as uvicorn.run ends)
        pass
    finally:
        for sock in sockets:
            sock.close()
