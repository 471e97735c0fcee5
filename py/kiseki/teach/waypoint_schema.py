# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The model of a taught run's waypoint file (``waypoints.yaml``, written by ``kiseki teach``
and read by ``kiseki playback`` and ``kiseki serve``; it may have been edited by hand)::

    log: teach.mcap                  # the teaching log (optional)
    merge: thesis                    # the maps' merge rule (optional)
    scene_file: ../data/worlds/x.yaml  # the scene taught in (from this folder; older files:
    scene_sha1: 0123...                # from the teaching's working directory) and its SHA-1
    maps:                            # band -> the taught map's YAML and its image's SHA-1
      band: {file: map_band.yaml, image_sha1: 0123..., resolution: 0.1, origin: [x, y, yaw]}
    waypoints:                       # the marks: name, odometry pose, true pose (optional)
      - {id: 0, name: P0, x: 0.0, y: 0.0, theta: 0.0, truth: [0.0, 0.0, 0.0]}

A problem is one line naming the file, the field and the value
(``waypoints.yaml: waypoints[3].x: must be a valid number, got 'abc' (waypoint 'P3')``)."""

from __future__ import annotations

import os
import re
from collections import Counter
from pathlib import Path
from typing import Annotated, Any

from pydantic import AfterValidator, Field, field_validator, model_validator

from kiseki._support.inputs import check_input
from kiseki._support.schema import (
    INT32_MAX,
    FileModel,
    FiniteFloat,
    PositiveFloat,
    SchemaError,
    parse,
)
from kiseki._support.yaml import read_yaml_file

__all__ = [
    "MAX_BANDS",
    "MAX_NAME_LENGTH",
    "MAX_WAYPOINTS",
    "TaughtMap",
    "Waypoint",
    "WaypointFile",
    "read_waypoint_file",
]

MAX_WAYPOINTS = 10_000  # a route's legs are checked against the map one by one
MAX_NAME_LENGTH = 64
MAX_BANDS = 16

_HEX40 = re.compile(r"[0-9a-f]{40}")


def _sha1(text: str) -> str:
    if not _HEX40.fullmatch(text):
        raise ValueError("must be a SHA-1 (40 lower-case hex digits)")
    return text


Sha1 = Annotated[str, Field(strict=True), AfterValidator(_sha1)]
Name = Annotated[str, Field(strict=True, min_length=1, max_length=MAX_NAME_LENGTH)]
Text = Annotated[str, Field(strict=True, max_length=4096)]


def _mapping(value: Any, what: str) -> Any:
    if not isinstance(value, dict):
        raise ValueError(f"must be a mapping of {what}")
    return value


class TaughtMap(FileModel):
    """One band's taught map: its ROS map YAML (beside the waypoint file), the SHA-1 of its
    image and the resolution and origin its YAML gave the image, which tie the waypoints to the
    map they were taught with (waypoint files written before the geometry was recorded have
    none: only their image is checked)."""

    file: Annotated[str, Field(strict=True, min_length=1, max_length=4096)]
    image_sha1: Sha1
    resolution: PositiveFloat | None = None
    origin: tuple[FiniteFloat, FiniteFloat, FiniteFloat] | None = None

    @model_validator(mode="before")
    @classmethod
    def _is_mapping(cls, value: Any) -> Any:
        return _mapping(value, "file and image_sha1")

    @model_validator(mode="after")
    def _geometry_whole(self) -> TaughtMap:
        if (self.resolution is None) != (self.origin is None):
            raise ValueError("resolution and origin are recorded together (or neither)")
        return self


class Waypoint(FileModel):
    """A mark: its name, the odometry pose where it was marked (map frame) and, in simulation,
    the true pose (optional: a waypoint without it is still a waypoint)."""

    # a label (teach numbers the marks from 0); int32 as every int of kiseki's files
    id: Annotated[int, Field(strict=True, ge=0, le=INT32_MAX)] | None = None
    name: Name
    x: FiniteFloat
    y: FiniteFloat
    theta: FiniteFloat
    truth: tuple[FiniteFloat, FiniteFloat, FiniteFloat] | None = None

    @model_validator(mode="before")
    @classmethod
    def _is_mapping(cls, value: Any) -> Any:
        return _mapping(value, "name, x, y, theta")

    @field_validator("truth", mode="before")
    @classmethod
    def _three(cls, value: Any) -> Any:
        if value is not None and not (isinstance(value, list | tuple) and len(value) == 3):
            raise ValueError("must be the true pose [x, y, theta]")
        return value

    def as_dict(self) -> dict:
        """The waypoint as the rest of kiseki takes it (no ``truth`` key when none is
        recorded, ``truth`` a list)."""
        out = self.model_dump(exclude_none=True)
        if "truth" in out:
            out["truth"] = list(out["truth"])
        return out


class WaypointFile(FileModel):
    """A whole waypoint file (see the module docstring)."""

    log: Text | None = None
    merge: Text | None = None
    scene_file: Text | None = None
    scene_sha1: Sha1 | None = None
    maps: Annotated[dict[Name, TaughtMap], Field(max_length=MAX_BANDS)]
    waypoints: Annotated[list[Waypoint], Field(min_length=1, max_length=MAX_WAYPOINTS)]

    @field_validator("waypoints")
    @classmethod
    def _unique(cls, marks: list[Waypoint]) -> list[Waypoint]:
        counts = Counter(w.name for w in marks)
        repeated = sorted(n for n, count in counts.items() if count > 1)
        if repeated:
            raise ValueError(f"waypoint names must be unique ({', '.join(repeated)} repeat)")
        return marks

    def by_name(self) -> dict[str, dict]:
        return {w.name: w.as_dict() for w in self.waypoints}


def _with_names(err: SchemaError, doc: dict, path: Path) -> SchemaError:
    """The error with the name of the waypoint each problem is in, when it has one."""
    marks = doc.get("waypoints")

    def named(problem: str) -> str:
        if not problem.startswith("waypoints[") or not isinstance(marks, list):
            return problem
        index = problem[len("waypoints[") : problem.index("]")]
        mark = marks[int(index)] if index.isdigit() and int(index) < len(marks) else None
        name = mark.get("name") if isinstance(mark, dict) else None
        return f"{problem} (waypoint {name!r})" if isinstance(name, str) and name else problem

    problems = [named(p) for p in err.errors]
    more = f" (and {len(problems) - 1} more)" if len(problems) > 1 else ""
    return SchemaError(f"{path}: {problems[0]}{more}", problems)


def read_waypoint_file(path: str | os.PathLike) -> WaypointFile:
    """The checked waypoint file at `path`: FileNotFoundError when there is none, ValueError
    (a :class:`~kiseki._support.schema.SchemaError` for a field) naming the file otherwise."""
    path = Path(path)
    check_input(path)
    if not path.is_file():
        raise FileNotFoundError(
            f"{path}: no waypoint file (kiseki teach writes one when a waypoint is marked)"
        )
    doc = read_yaml_file(path, "kiseki waypoint file")
    if not isinstance(doc, dict) or not ({"waypoints", "maps"} & set(doc)):
        raise ValueError(f"{path}: not a kiseki waypoint file")
    try:
        return parse(WaypointFile, doc, path)
    except SchemaError as err:
        raise _with_names(err, doc, path) from None
