# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The sockets ``kiseki serve`` listens on, bound before it prints its address and token and
handed to uvicorn (``uvicorn.Server(config).run(sockets=...)``): a port in use or an address
that is not this machine's is one line naming --port or --host (exit status 1), not uvicorn's
log line and exit status 3 after the URL was printed."""

from __future__ import annotations

import errno
import socket

from kiseki.errors import KisekiError

__all__ = ["BACKLOG", "listening_sockets"]

BACKLOG = 2048  # uvicorn's default


def listening_sockets(host: str, port: int, backlog: int = BACKLOG) -> list[socket.socket]:
    """Listening TCP sockets on every address `host` names (``localhost``: 127.0.0.1 and ::1;
    ``""``: every interface), bound as asyncio's ``create_server`` binds them (SO_REUSEADDR, an
    IPv6 socket for IPv6 only, an address family the machine lacks skipped). A name that
    resolves to nothing or an address that cannot be bound is a KisekiError in one line."""
    try:
        found = socket.getaddrinfo(
            host or None, port, type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE
        )
    except socket.gaierror as err:
        raise KisekiError(f"--host {host}: no address of that name ({err.strerror})") from None
    except (UnicodeError, ValueError) as err:  # an empty label ("a..b"), a NUL
        raise KisekiError(f"--host {host!r}: not a host name or address ({err})") from None
    sockets: list[socket.socket] = []
    failure: OSError | None = None
    try:
        for family, kind, proto, _, address in dict.fromkeys(found):  # in order, once each
            sock = socket.socket(family, kind, proto)
            sockets.append(sock)
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            if family == socket.AF_INET6:
                sock.setsockopt(socket.IPPROTO_IPV6, socket.IPV6_V6ONLY, 1)
            try:
                sock.bind(address)
            except OSError as err:
                if err.errno != errno.EADDRNOTAVAIL:
                    raise
                failure = err  # e.g. ::1 of localhost without IPv6, as asyncio skips it
                sockets.pop().close()
                continue
            sock.listen(backlog)
        if not sockets:
            raise failure or OSError(errno.EADDRNOTAVAIL, "no address to bind")
    except OSError as err:
        for sock in sockets:
            sock.close()
        raise KisekiError(_why(err, host, port)) from None
    return sockets


def _why(err: OSError, host: str, port: int) -> str:
    if err.errno == errno.EADDRNOTAVAIL:
        return f"--host {host}: not an address of this machine"
    if err.errno in (errno.EACCES, errno.EPERM):
        return f"--port {port} on {host}: permission denied (ports below 1024 need privileges)"
    reason = (err.strerror or str(err)).strip()
    return f"--port {port} on {host}: {reason[:1].lower()}{reason[1:]}"
