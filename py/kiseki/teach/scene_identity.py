# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Which scene a taught route belongs to: the SHA-1 of the scene file's bytes, recorded by
teaching in its log and its waypoint file. Playback in a scene file whose bytes differ is
refused unless the caller names the changed scene as a variant (an experiment's deliberately
changed copy, such as Exp. 3's boxes), which playback then records with both hashes. A scene's
own ``playback`` variant is in the same file, so it needs no label.

Where the scene file is: a taught run records it relative to the taught folder (the folder of
the waypoint file and the teaching log), or absolute when no relative path leads there, so that
the run can be served, resumed or played back from any working directory. Runs taught before
recorded it relative to the working directory of the teaching; :func:`resolve_scene_file` (the
one resolution that serve, teach --resume and playback use) finds both."""

from __future__ import annotations

import hashlib
import os
import re
from dataclasses import dataclass
from pathlib import Path

from kiseki._support.inputs import YAML_LIMIT, read_input
from kiseki.io.runlog import read_run
from kiseki.teach.waypoint_schema import read_waypoint_file

__all__ = [
    "TaughtScene",
    "check_scene",
    "recorded_scene_file",
    "resolve_scene_file",
    "scene_digest",
    "taught_scene_of",
]

_LABEL = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,63}")


def scene_digest(path: str | os.PathLike) -> str:
    """SHA-1 of a scene file's bytes: ties a teaching log to the scene it was taught in."""
    return hashlib.sha1(read_input(path, "scene files", YAML_LIMIT)).hexdigest()


def recorded_scene_file(scene: str | os.PathLike, folder: str | os.PathLike) -> str:
    """How a taught run in `folder` records its scene file: the path relative to `folder`
    ('/'-separated), or the absolute path when there is none (another drive)."""
    target = Path(scene).resolve()
    try:
        return Path(os.path.relpath(target, Path(folder).resolve())).as_posix()
    except ValueError:  # no relative path between two drives
        return str(target)


def resolve_scene_file(recorded: str | None, folder: str | os.PathLike | None) -> Path | None:
    """The scene file a taught run in `folder` records as `recorded`: an absolute path as it
    is; a relative one under `folder` (how runs are recorded), else under the working directory
    (how older runs were recorded); None when neither is a file (or nothing is recorded)."""
    if not recorded:
        return None
    path = Path(recorded)
    candidates = [path] if path.is_absolute() or folder is None else [Path(folder) / path, path]
    return next((c.resolve() for c in candidates if c.is_file()), None)


@dataclass(frozen=True)
class TaughtScene:
    """The scene file a route was taught in, as recorded then (see :func:`recorded_scene_file`),
    its SHA-1, and the taught folder a relative `file` is relative to."""

    file: str
    sha1: str
    folder: str | None = None

    def path(self) -> Path | None:
        """The scene file, found (:func:`resolve_scene_file`), or None."""
        return resolve_scene_file(self.file, self.folder)

    def shown(self) -> str:
        """The scene file for a message or a log: found, else as recorded."""
        found = self.path()
        return str(found) if found is not None else self.file


def taught_scene_of(waypoints: str | os.PathLike) -> TaughtScene | None:
    """The taught scene recorded in a waypoint file (one
    :func:`kiseki.apps.teach.taught_route.load_route`
    accepted), else in the metadata of the teaching log it names (waypoint files written before
    the scene was recorded in them); None when neither records it (a hand-made file)."""

    doc = read_waypoint_file(waypoints)
    folder = str(Path(waypoints).parent)
    if doc.scene_sha1 is not None:
        return TaughtScene(doc.scene_file or "", doc.scene_sha1, folder)
    if not doc.log or not (log := Path(waypoints).parent / doc.log).is_file():
        return None

    try:
        meta = read_run(log).metadata
    except (OSError, ValueError):
        return None  # an unreadable log: the waypoint file alone cannot tell
    if not isinstance(meta.get("scene_sha1"), str):
        return None
    return TaughtScene(str(meta.get("scene_file", "")), meta["scene_sha1"], str(log.parent))


def check_scene(
    taught: TaughtScene | None, scene_path: str | os.PathLike, variant: str | None = None
) -> dict[str, str]:
    """The scene identity to record with a playback: ``scene_sha1``, and ``taught_scene_file``
    and ``taught_scene_sha1`` when the taught scene is known, and ``variant`` when one is named.
    Raises ValueError when the scene file's bytes differ from the taught scene's and no
    `variant` label names the change, when a label names a scene whose bytes are the taught
    scene's, or when the label is not 1-64 letters, digits, '_', '.' or '-'."""
    if variant is not None and not (isinstance(variant, str) and _LABEL.fullmatch(variant)):
        raise ValueError(
            f"a scene variant label must be 1-64 letters, digits, '_', '.' or '-', got {variant!r}"
        )
    record = {"scene_sha1": scene_digest(scene_path)}
    if taught is not None:
        record["taught_scene_file"] = taught.shown()
        record["taught_scene_sha1"] = taught.sha1
        if taught.sha1 != record["scene_sha1"] and variant is None:
            raise ValueError(
                f"{scene_path} is not the scene the route was taught in "
                f"({taught.shown() or 'unnamed'}; the files' SHA-1s differ): give that scene, or "
                "name the changed scene with --variant LABEL to play back in it on purpose"
            )
        if taught.sha1 == record["scene_sha1"] and variant is not None:
            # the log recorded a variant of a scene that was the taught one, byte for byte
            raise ValueError(
                f"scene variant {variant!r} names a changed scene, but {scene_path} is the scene "
                "the route was taught in (the same SHA-1): play back without a variant label"
            )
    if variant is not None:
        record["variant"] = variant
    return record
