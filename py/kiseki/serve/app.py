# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The web API over a taught run (FastAPI). Errors are JSON ``{"detail": "..."}``.

- ``GET /api/waypoints``: ``{"waypoints": [{"id", "name", "x", "y", "theta"}], "map": {"method",
  "band", "width", "height", "resolution", "origin": [x, y, theta], "image": "/api/map"}}``
- ``GET /api/map``: the taught map as PNG (ROS image: top row = largest y); ``?format=json``:
  the map's metadata and ``cells`` (row-major from the bottom row; -1 unknown, 0 free,
  100 occupied)
- ``POST /api/routes`` ``{"start", "via": [...], "goal", "home"}`` (``via`` optional, at most
  :data:`MAX_VIA` names; ``home`` the start when omitted; names at most 64 characters): 202
  ``{"id", "route": {...}}``; 409 while a route runs; 422 for an unknown waypoint, a leg
  through occupied space, a field beyond its limit or a malformed body
- ``GET /api/state``: ``{"status": "idle"|"running"|"finished"|"stopped", "route", "leg":
  {"phase": "outbound"|"dwell"|"return", "index", "from", "to"}, "pose", "estimate",
  "speed", "command", "t", "stop_error_m", "dwell_left_s", "detail", "history": [...] (the
  last 50 finished routes), "epoch", "seq"}``
- ``POST /api/stop`` (body ``{}``): the robot brakes at once; ``{"stopping": bool, "status",
  "route", "t", "speed", "epoch", "seq"}`` (the route's clock and the robot's speed when the
  stop was taken)
- ``PATCH /api/waypoints/{name}`` ``{"name": NEW}``: 200 ``{"waypoint"}``; 404 unknown, 409 a
  duplicate name or a route running, 422 a bad name
- ``/ws``: the state (``"type": "state"``, ``"epoch"``, ``"seq"``, ``"particles"`` [[x, y,
  theta], ...]) on connecting and at every control period of a route, the same text to every
  page; ``seq`` orders the states of one ``epoch`` (a page drops a state older than its own)

Requests: :mod:`kiseki.serve.guard` first refuses (403) a Host other than the bound loopback
address and an Origin of another site; then, with a token (any address but loopback), every
``/api/`` request needs ``Authorization: Bearer TOKEN`` (401) and the websocket the header, the
subprotocol ``kiseki.token.TOKEN`` (how the page sends it) or ``?token=TOKEN``; a POST, PUT,
PATCH or DELETE must send ``Content-Type: application/json`` (415: a form cannot) and at most
64 KiB (413; counted as the body arrives, with Content-Length or chunked: :class:`BodyLimit`).
The page itself (static files, no data) loads without the token so that it can
ask for it.
"""

from __future__ import annotations

import asyncio
import contextlib
import hmac
from contextlib import asynccontextmanager
from pathlib import Path
from typing import Annotated

from fastapi import FastAPI, Request, WebSocket, WebSocketDisconnect
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse, Response
from fastapi.staticfiles import StaticFiles
from pydantic import BaseModel, ConfigDict, Field

from kiseki.serve.guard import RequestGuard
from kiseki.serve.routes import RouteBusyError, RouteRefusedError, RouteRequest, RouteRunner
from kiseki.serve.taught import TaughtRun, WaypointError
from kiseki.teach.waypoint_schema import MAX_NAME_LENGTH

__all__ = ["MAX_BODY_BYTES", "MAX_VIA", "STATIC", "BodyLimit", "create_app"]

STATIC = Path(__file__).resolve().parent / "static"
MAX_VIA = 100  # via-points of one route
MAX_BODY_BYTES = 64 * 1024  # a route of MAX_VIA longest names is 7 KiB
SUBPROTOCOL = "kiseki"  # the websocket's; the page offers it with "kiseki.token.TOKEN"
_CHANGES = ("POST", "PUT", "PATCH", "DELETE")

Name = Annotated[str, Field(min_length=1, max_length=MAX_NAME_LENGTH)]


class RouteBody(BaseModel):
    model_config = ConfigDict(extra="forbid", str_strip_whitespace=True)
    start: Name
    via: Annotated[list[Name], Field(max_length=MAX_VIA)] = []
    goal: Name
    home: Name | None = None


class RenameBody(BaseModel):
    model_config = ConfigDict(extra="forbid")
    name: Annotated[str, Field(max_length=MAX_NAME_LENGTH)]


def _error(status: int, detail: str, **headers: str) -> JSONResponse:
    return JSONResponse({"detail": detail}, status_code=status, headers=headers or None)


def _validation_detail(err: RequestValidationError) -> str:
    parts = []
    for e in err.errors():
        where = ".".join(str(p) for p in e.get("loc", ()))
        message = "invalid JSON" if e.get("type") == "json_invalid" else e.get("msg", "invalid")
        parts.append(f"{where}: {message}")
    return "; ".join(parts) or "invalid request"


def _too_large() -> JSONResponse:
    return _error(413, f"the body is limited to {MAX_BODY_BYTES} bytes")


class BodyLimit:
    """Reads the body of a change to the API (a POST, PUT, PATCH or DELETE to ``/api/``) before
    the app does, counting its bytes as they arrive, with Content-Length or chunked alike: once
    more than :data:`MAX_BODY_BYTES` have come, 413 and nothing more is read; else the app gets
    the body as it was read (at most 64 KiB held)."""

    def __init__(self, app) -> None:
        self.app = app

    async def __call__(self, scope, receive, send) -> None:
        path = scope.get("path", "")
        if (
            scope["type"] != "http"
            or scope["method"] not in _CHANGES
            or not (path == "/api" or path.startswith("/api/"))
        ):
            return await self.app(scope, receive, send)
        pieces, size, more = [], 0, True
        while more:
            message = await receive()
            if message["type"] != "http.request":  # the client went away: no one to answer
                return None
            pieces.append(message.get("body", b""))
            size += len(pieces[-1])
            if size > MAX_BODY_BYTES:
                return await _too_large()(scope, receive, send)
            more = message.get("more_body", False)
        body, given = b"".join(pieces), False

        async def replay():
            nonlocal given
            if given:
                return await receive()  # http.disconnect, once the client goes
            given = True
            return {"type": "http.request", "body": body, "more_body": False}

        return await self.app(scope, replay, send)


def _bearer(value: str | None) -> str | None:
    if value and value[:7].lower() == "bearer ":
        return value[7:].strip()
    return None


def create_app(
    taught: TaughtRun,
    runner: RouteRunner,
    token: str | None = None,
    static: Path = STATIC,
    hosts: frozenset[str] | None = None,
) -> FastAPI:
    """The app; `token` None (loopback) needs no authorization; `hosts`: the Host values it
    answers to (:func:`kiseki.serve.guard.loopback_hosts`; None: any)."""

    def authorized(given: str | None) -> bool:
        return token is None or (given is not None and hmac.compare_digest(given, token))

    @asynccontextmanager
    async def lifespan(_app: FastAPI):
        yield
        runner.close()

    app = FastAPI(title="kiseki", lifespan=lifespan, docs_url=None, redoc_url=None)

    @app.exception_handler(RequestValidationError)
    async def invalid(_request: Request, err: RequestValidationError) -> JSONResponse:
        return _error(422, _validation_detail(err))

    app.add_middleware(BodyLimit)  # inside check_request: after the token and the type

    @app.middleware("http")
    async def check_request(request: Request, call_next):
        path = request.url.path
        if not (path == "/api" or path.startswith("/api/")):
            return await call_next(request)
        if not authorized(_bearer(request.headers.get("authorization"))):
            return _error(401, "missing or wrong access token", **{"WWW-Authenticate": "Bearer"})
        if request.method in _CHANGES:
            kind = request.headers.get("content-type", "").split(";")[0].strip().lower()
            if kind != "application/json":
                return _error(415, f"{request.method} takes a JSON body (Content-Type: "
                              f"application/json), got {kind[:40] or 'none'!r}")  # fmt: skip
            size = request.headers.get("content-length", "0")  # chunked: BodyLimit counts
            if not size.isdigit() or int(size) > MAX_BODY_BYTES:
                return _too_large()
        return await call_next(request)

    @app.get("/api/waypoints")
    def waypoints() -> dict:
        return taught.public()

    @app.get("/api/map")
    def map_image(format: str = "png") -> Response:  # noqa: A002 (the query's name)
        if format == "json":
            return JSONResponse(taught.map_json())
        if format != "png":
            return _error(422, f"format must be png or json, got {format!r}")
        return Response(taught.map_png(), media_type="image/png")

    @app.post("/api/routes", status_code=202)
    def start_route(body: RouteBody):
        request = RouteRequest(body.start, body.goal, list(body.via), body.home)
        try:
            route = runner.submit(request)
        except RouteRefusedError as err:
            return _error(422, str(err))
        except RouteBusyError as err:
            return _error(409, str(err))
        return {"id": route["id"], "route": route}

    @app.get("/api/state")
    def state() -> dict:
        return runner.state()

    @app.post("/api/stop")
    def stop() -> dict:
        return runner.stop()

    @app.patch("/api/waypoints/{name}")
    def rename(name: str, body: RenameBody):
        if runner.state()["status"] == "running":
            return _error(409, "a route is running; rename its waypoints when it is over")
        try:
            return {"waypoint": taught.rename(name, body.name)}
        except WaypointError as err:
            return _error(err.status, str(err))
        except OSError as err:  # the file is as it was (atomic write)
            return _error(500, f"the waypoint file was not changed: {err}")

    @app.websocket("/ws")
    async def live(websocket: WebSocket) -> None:
        offered = websocket.scope.get("subprotocols") or []
        given = (
            _bearer(websocket.headers.get("authorization"))
            or next((p[13:] for p in offered if p.startswith("kiseki.token.")), None)
            or websocket.query_params.get("token")
        )
        if not authorized(given):
            try:
                await websocket.send_denial_response(_error(401, "missing or wrong access token"))
            except RuntimeError:  # the server cannot send an HTTP response on a websocket
                await websocket.close(code=1008, reason="missing or wrong access token")
            return
        await websocket.accept(SUBPROTOCOL if SUBPROTOCOL in offered else None)
        key, queue = runner.broadcaster.subscribe()
        reader = asyncio.create_task(_until_closed(websocket))
        try:
            await websocket.send_text(runner.message())
            while not reader.done():
                getter = asyncio.create_task(queue.get())
                await asyncio.wait({getter, reader}, return_when=asyncio.FIRST_COMPLETED)
                if not getter.done():
                    getter.cancel()
                    break
                await websocket.send_text(getter.result())
        except (WebSocketDisconnect, RuntimeError):
            pass
        finally:
            runner.broadcaster.unsubscribe(key)
            reader.cancel()
            with contextlib.suppress(asyncio.CancelledError, Exception):
                await reader

    app.mount("/", StaticFiles(directory=static, html=True, check_dir=False), name="page")
    app.add_middleware(RequestGuard, hosts=hosts)  # outermost: before the token
    return app


async def _until_closed(websocket: WebSocket) -> None:
    """Reads (and ignores) what the page sends until it goes away."""
    with contextlib.suppress(WebSocketDisconnect, RuntimeError):
        while True:
            message = await websocket.receive()
            if message["type"] == "websocket.disconnect":
                return
