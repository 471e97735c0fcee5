# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Which scene a taught route belongs to: the SHA-1 of the scene file's bytes, recorded by
teaching in its log and its waypoint file. Playback in a scene file whose bytes differ is
refused unless the caller names the changed scene as a variant (an experiment's deliberately
changed copy, such as Exp. 3's boxes), which playback then records with both hashes. A scene's
own ``playback`` variant is in the same file, so it needs no label."""

from __future__ import annotations

import hashlib
import os
import re
from dataclasses import dataclass
from pathlib import Path

__all__ = ["TaughtScene", "check_scene", "scene_digest", "taught_scene_of"]

_LABEL = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,63}")


def scene_digest(path: str | os.PathLike) -> str:
    """SHA-1 of a scene file's bytes: ties a teaching log to the scene it was taught in."""
    return hashlib.sha1(Path(path).read_bytes()).hexdigest()


@dataclass(frozen=True)
class TaughtScene:
    """The scene file a route was taught in, as recorded then, and its SHA-1."""

    file: str
    sha1: str


def taught_scene_of(waypoints: str | os.PathLike) -> TaughtScene | None:
    """The taught scene recorded in a waypoint file (one :func:`kiseki.teach.teaching.load_route`
    accepted), else in the metadata of the teaching log it names (waypoint files written before
    the scene was recorded in them); None when neither records it (a hand-made file)."""
    from kiseki.teach.waypoint_schema import read_waypoint_file

    doc = read_waypoint_file(waypoints)
    if doc.scene_sha1 is not None:
        return TaughtScene(doc.scene_file or "", doc.scene_sha1)
    if not doc.log or not (log := Path(waypoints).parent / doc.log).is_file():
        return None
    from kiseki.sim.mcap_log import read_run

    try:
        meta = read_run(log).metadata
    except (OSError, ValueError):
        return None  # an unreadable log: the waypoint file alone cannot tell
    if not isinstance(meta.get("scene_sha1"), str):
        return None
    return TaughtScene(str(meta.get("scene_file", "")), meta["scene_sha1"])


def check_scene(
    taught: TaughtScene | None, scene_path: str | os.PathLike, variant: str | None = None
) -> dict[str, str]:
    """The scene identity to record with a playback: ``scene_sha1``, and ``taught_scene_file``
    and ``taught_scene_sha1`` when the taught scene is known, and ``variant`` when one is named.
    Raises ValueError when the scene file's bytes differ from the taught scene's and no
    `variant` label names the change, or when the label is not 1-64 letters, digits, '_', '.'
    or '-'."""
    if variant is not None and not (isinstance(variant, str) and _LABEL.fullmatch(variant)):
        raise ValueError(
            f"a scene variant label must be 1-64 letters, digits, '_', '.' or '-', got {variant!r}"
        )
    record = {"scene_sha1": scene_digest(scene_path)}
    if taught is not None:
        record["taught_scene_file"] = taught.file
        record["taught_scene_sha1"] = taught.sha1
        if taught.sha1 != record["scene_sha1"] and variant is None:
            raise ValueError(
                f"{scene_path} is not the scene the route was taught in "
                f"({taught.file or 'unnamed'}; the files' SHA-1s differ): give that scene, or "
                "name the changed scene with --variant LABEL to play back in it on purpose"
            )
    if variant is not None:
        record["variant"] = variant
    return record
