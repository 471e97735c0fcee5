# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The finished routes of a served taught run, kept across restarts in a JSON file (``kiseki
serve --history FILE``; by default ``route_history.json`` in the taught folder)::

    {"kind": "kiseki route history", "version": 1,
     "routes": [{"id": 1, "start": "P0", "via": ["T1"], "goal": "G", "home": "P0",
                 "status": "finished", "stop_error_m": 0.041, "duration_s": 61.2}, ...]}

Read at start, checked by its model (a file that is not a route history is an error naming the
file and the field, never dropped or overwritten), and rewritten whole and atomically after
every route (:mod:`kiseki._support.atomic`: the file is the old history or the new one, never
half)."""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Annotated, Literal

from pydantic import Field

from kiseki._support.atomic import atomic_write
from kiseki._support.schema import FileModel, NonNegativeFloat, PositiveInt, parse
from kiseki.teach.waypoint_schema import MAX_NAME_LENGTH, MAX_WAYPOINTS

__all__ = ["KIND", "RouteHistory"]

KIND = "kiseki route history"
MAX_ROUTES = 1_000_000  # one route a minute for two years
Name = Annotated[str, Field(strict=True, min_length=1, max_length=MAX_NAME_LENGTH)]


class FinishedRoute(FileModel):
    id: PositiveInt
    start: Name
    via: Annotated[list[Name], Field(max_length=MAX_WAYPOINTS)]
    goal: Name
    home: Name
    status: Literal["finished", "stopped"]
    stop_error_m: NonNegativeFloat | None
    duration_s: NonNegativeFloat


class HistoryFile(FileModel):
    kind: Literal["kiseki route history"]
    version: Literal[1]
    routes: Annotated[list[FinishedRoute], Field(max_length=MAX_ROUTES)]


class RouteHistory:
    """The finished routes (oldest first), read from `path` when it exists and written back
    after each :meth:`append`; `path` None keeps them in memory only."""

    def __init__(self, path: str | os.PathLike | None = None) -> None:
        self.path = None if path is None else Path(path)
        self.routes: list[dict] = [] if self.path is None else _read(self.path)

    @property
    def next_id(self) -> int:
        """The id of the next route: ids go on from the history's."""
        return max((r["id"] for r in self.routes), default=0) + 1

    def append(self, route: dict) -> None:
        """Adds a finished route and rewrites the file (atomically); the route is kept in
        memory when the write fails (OSError, raised)."""
        checked = parse(FinishedRoute, route, "a finished route").model_dump(mode="json")
        self.routes.append(checked)
        if self.path is not None:
            text = json.dumps({"kind": KIND, "version": 1, "routes": self.routes}, indent=1)
            atomic_write(self.path, lambda tmp: Path(tmp).write_text(text + "\n", "utf-8"))


def _read(path: Path) -> list[dict]:
    """The routes of the history file at `path` ([] when there is none yet); ValueError
    naming the file when it is not a route history."""
    if not path.exists():
        return []
    if not path.is_file():
        raise ValueError(f"{path}: the route history is not a file")
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except UnicodeDecodeError:
        raise ValueError(f"{path}: not a route history (not UTF-8 text)") from None
    except json.JSONDecodeError as err:
        raise ValueError(
            f"{path}: not a route history (invalid JSON at line {err.lineno}: {err.msg}); "
            "move it away to start a new one"
        ) from None
    if not isinstance(doc, dict) or doc.get("kind") != KIND:
        raise ValueError(f'{path}: not a route history (no "kind": "{KIND}")')
    routes = parse(HistoryFile, doc, path).routes
    ids = [r.id for r in routes]
    if len(set(ids)) != len(ids):
        raise ValueError(f"{path}: not a route history (route ids repeat)")
    return [r.model_dump(mode="json") for r in routes]
