# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Which requests the route server answers, before any route or token is looked at (an ASGI
middleware, so HTTP requests and websocket handshakes pass the same checks):

- on loopback the ``Host`` must name the bound address and port (``127.0.0.1:PORT`` or
  ``localhost:PORT`` when bound to 127.0.0.1, ``[::1]:PORT`` or ``localhost:PORT`` when bound to
  ::1, any of the three when bound to localhost): another name is a DNS rebinding attack, a
  site whose name an attacker pointed at 127.0.0.1 (403). Beyond loopback the access token
  guards every request and the address may be reached by any name.
- an ``Origin`` (browsers send it with every POST, PATCH and websocket handshake) must be this
  server's own, ``http(s)://`` + the ``Host``: another site's page cannot start or stop a
  route, rename a waypoint or listen to the robot (403). Requests without one (curl, scripts)
  pass.

The API's own rules (token, JSON bodies) follow in :mod:`kiseki.serve.app`."""

from __future__ import annotations

from urllib.parse import urlsplit

from starlette.datastructures import Headers
from starlette.responses import JSONResponse
from starlette.websockets import WebSocket

__all__ = ["RequestGuard", "loopback_hosts"]

_NAMES = {
    "127.0.0.1": ("127.0.0.1", "localhost"),
    "::1": ("[::1]", "localhost"),
    "localhost": ("localhost", "127.0.0.1", "[::1]"),
}


def loopback_hosts(host: str, port: int) -> frozenset[str] | None:
    """The ``Host`` values a server bound to `host`:`port` answers to, or None (any) when
    `host` is not a loopback name."""
    names = _NAMES.get(host.strip("[]").lower())
    if names is None:
        return None
    hosts = {f"{name}:{port}" for name in names}
    if port == 80:  # browsers leave out the default port
        hosts |= set(names)
    return frozenset(hosts)


def _same_origin(origin: str, host: str) -> bool:
    parts = urlsplit(origin)
    return parts.scheme in ("http", "https") and parts.netloc.lower() == host.lower() != ""


class RequestGuard:
    """The checks above around an ASGI `app`; `hosts` None accepts any Host."""

    def __init__(self, app, hosts: frozenset[str] | None) -> None:
        self.app, self.hosts = app, hosts

    async def __call__(self, scope, receive, send) -> None:
        if scope["type"] not in ("http", "websocket"):
            return await self.app(scope, receive, send)
        headers = Headers(scope=scope)
        host, origin = headers.get("host", ""), headers.get("origin")
        if self.hosts is not None and host.lower() not in self.hosts:
            where = sorted(self.hosts)[0]
            problem = f"this server answers to http://{where}/, not to host {host[:80]!r}"
        elif origin is not None and not _same_origin(origin, host):
            problem = f"requests from another site ({origin[:80]}) are refused"
        else:
            return await self.app(scope, receive, send)
        response = JSONResponse({"detail": problem}, status_code=403)
        if scope["type"] == "http":
            return await response(scope, receive, send)
        websocket = WebSocket(scope, receive, send)
        try:
            await websocket.send_denial_response(response)
        except RuntimeError:  # the server cannot answer a handshake with HTTP: close it
            await websocket.close(code=1008, reason="refused")
