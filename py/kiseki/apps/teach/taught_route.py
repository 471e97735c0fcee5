# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""A taught route read back for playback and serving: the waypoints a route names and the map
to drive it on, checked to be the map the waypoints were taught with (its image's SHA-1 and the
resolution and origin its YAML gives it, both recorded by teaching in the waypoint file)."""

from __future__ import annotations

import hashlib
import math
import os
from pathlib import Path

from kiseki._support.inputs import read_input
from kiseki.io.ros_map import MAX_IMAGE_BYTES, read_map_metadata
from kiseki.teach.waypoint_schema import read_waypoint_file

__all__ = ["load_route", "load_taught", "waypoints_file_hash"]


def waypoints_file_hash(map_yaml: Path) -> str:
    """SHA-1 of the map image a map YAML names: ties a waypoint file to the map it was taught
    with. The YAML is read through its model (:func:`kiseki.io.ros_map.read_map_metadata`): a
    MapFormatError names the file, the key and the value; an OSError the image."""
    image = read_map_metadata(map_yaml).image
    return hashlib.sha1(read_input(image, "map images", MAX_IMAGE_BYTES)).hexdigest()


def load_taught(folder: str | os.PathLike, band: str, route: list[str]) -> tuple[Path, list[dict]]:
    """The map of a local-map band and the route's waypoints from a teaching folder, checking
    that the map is the one the waypoints were taught with."""
    return load_route(Path(folder) / "waypoints.yaml", band, route)


def _check_geometry(map_path: Path, taught, waypoints: Path) -> None:
    """The map's resolution and origin are those it was taught with (the waypoints are poses in
    its frame): an edited YAML puts the same image elsewhere or at another scale."""
    if taught.resolution is None:
        return  # a waypoint file from before the geometry was recorded (the schema: both or none)
    meta = read_map_metadata(map_path)
    now = (float(meta.resolution), [float(v) for v in meta.origin])
    then = (taught.resolution, list(taught.origin))
    # equal but for the digits a hand-saved YAML may round: a millionth of the resolution, a
    # thousandth of a cell and of a radian
    same = math.isclose(now[0], then[0], rel_tol=1e-6) and all(
        abs(a - b) <= 1e-3 * (then[0] if k < 2 else 1.0)
        for k, (a, b) in enumerate(zip(now[1], then[1], strict=True))
    )
    if not same:
        raise ValueError(
            f"{map_path}: resolution {now[0]:g} m and origin {now[1]}, but {waypoints} was "
            f"taught on resolution {then[0]:g} m and origin {then[1]}"
        )


def load_route(
    waypoints: str | os.PathLike,
    band: str,
    route: list[str],
    map_file: str | os.PathLike | None = None,
) -> tuple[Path, list[dict]]:
    """The route's waypoints from a waypoint file and the map to play it back on: `map_file`,
    or the `band` map named in the waypoint file. The map must be the one the waypoints were
    taught with (its image's SHA-1 is in the waypoint file), and of the method's band."""
    path = Path(waypoints)
    doc = read_waypoint_file(path)
    if band not in doc.maps:
        raise ValueError(f"{path}: no {band!r} map was taught")
    map_path = path.parent / doc.maps[band].file if map_file is None else Path(map_file)
    if not map_path.is_file():
        named = f" (named in {path})" if map_file is None else ""
        raise FileNotFoundError(f"{map_path}: the taught map is missing{named}")
    try:
        digest = waypoints_file_hash(map_path)
    except OSError as e:  # the image (a bad YAML is a MapFormatError naming file, key, value)
        raise ValueError(
            f"{map_path}: cannot read the image it names ({e.filename}: {e.strerror})"
        ) from e
    if digest != doc.maps[band].image_sha1:
        others = [b for b, m in doc.maps.items() if m.image_sha1 == digest]
        if others:
            raise ValueError(
                f"{map_path}: this is the {others[0]!r} map of {path}; the method needs the "
                f"{band!r} map"
            )
        raise ValueError(f"{map_path}: this map is not the one {path} was taught with")
    _check_geometry(map_path, doc.maps[band], path)
    by_name = doc.by_name()
    unknown = [n for n in route if n not in by_name]
    if unknown:
        raise ValueError(
            f"{path}: no waypoint named {', '.join(unknown)} (known: {', '.join(by_name)})"
        )
    if len(route) < 2 or len(set(route)) != len(route):
        raise ValueError("a route needs at least two different waypoints")
    return map_path, [by_name[n] for n in route]
