# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Fuzz the waypoint-file reader kiseki.apps.teach.taught_route.load_route (the file
``kiseki teach`` writes and ``kiseki playback`` reads), with a taught map beside it; see
fuzz_common.py."""

from __future__ import annotations

import hashlib
from pathlib import Path

import yaml
from fuzz_common import PROJECT_DATA, main

from kiseki.apps.teach.taught_route import load_route

CORRIDOR = PROJECT_DATA / "maps" / "factory_corridor"


def waypoint_file(sha1: str) -> dict:
    """A waypoint file as kiseki teach writes it (two bands, three waypoints)."""
    maps = {
        "band": {"file": "map_band.yaml", "image_sha1": sha1},
        "floor": {"file": "map_floor.yaml", "image_sha1": "0" * 40},
    }
    marks = [
        {"id": i, "name": name, "x": x, "y": 0.25 * i, "theta": 0.1 * i, "truth": [x, 0.0, 0.0]}
        for i, (name, x) in enumerate([("P0", 0.0), ("P1", 1.5), ("G", 3.0)])
    ]
    return {"maps": maps, "waypoints": marks}


def sha1() -> str:
    return hashlib.sha1(CORRIDOR.with_suffix(".pgm").read_bytes()).hexdigest()


def seeds(_folder: Path):
    doc = waypoint_file(sha1())
    yield yaml.safe_dump(doc, sort_keys=False).encode()
    yield yaml.safe_dump(doc, sort_keys=False, default_flow_style=True).encode()
    del doc["waypoints"][1]["truth"]
    yield yaml.safe_dump(doc, sort_keys=False).encode()


def prepare(files: Path) -> None:
    (files / "map_band.yaml").write_text(CORRIDOR.with_suffix(".yaml").read_text())
    (files / "factory_corridor.pgm").write_bytes(CORRIDOR.with_suffix(".pgm").read_bytes())


def read(path: Path) -> object:
    return load_route(path, "band", ["P0", "G"])


if __name__ == "__main__":
    main(read, seeds, suffix=".yaml", prepare=prepare, packages=("kiseki", "yaml"))
