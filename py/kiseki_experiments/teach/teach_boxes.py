# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Exp. 3's unknown boxes (the thesis' cardboard boxes, moved between runs): a copy of a scene
with boxes placed at random beside the route for playback only, and how many of them stand
beside the final leg."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import yaml

from kiseki._support.inputs import YAML_LIMIT, read_input_text
from kiseki._support.yaml import safe_load_12
from kiseki.core import Random

__all__ = ["BOX_OFFSET_M", "BOX_SIZE_M", "boxes_beside_final_leg", "with_boxes"]


BOX_SIZE_M = (0.4, 0.4, 0.6)  # Exp. 3's unknown boxes (the thesis' cardboard boxes)
BOX_OFFSET_M = (0.8, 1.1)  # their centres' distance beside the route


def with_boxes(scene_file: Path, count: int, seed: int, tmp: Path) -> Path:
    """A copy of the scene with `count` unknown BOX_SIZE_M boxes, playback only, placed at
    random BOX_OFFSET_M beside the route (kept 0.6 m clear of it so the robot can pass)."""
    doc = safe_load_12(read_input_text(scene_file, "scene files", YAML_LIMIT))
    rng = Random(seed)
    pts = np.asarray(doc["route"]["waypoints"], dtype=float)
    placed = 0
    while placed < count:
        i = int(rng.below(len(pts) - 1))
        f = rng.uniform(0.15, 0.85, 1)[0]
        side = 1 if rng.uniform(0, 1, 1)[0] < 0.5 else -1
        a, b = pts[i], pts[i + 1]
        normal = np.array([-(b - a)[1], (b - a)[0]]) / np.linalg.norm(b - a)
        c = a + f * (b - a) + side * rng.uniform(*BOX_OFFSET_M, 1)[0] * normal
        doc["objects"].append(
            {
                "type": "box",
                "center": [float(c[0]), float(c[1])],
                "size": list(BOX_SIZE_M),
                "only_in": "playback",
            }
        )
        placed += 1
    out = tmp / scene_file.name
    out.write_text(yaml.safe_dump(doc), encoding="utf-8")
    return out


def boxes_beside_final_leg(scene_file: Path) -> dict:
    """How many of the playback-only boxes stand beside the route's final leg, left and right
    (the cameras see them on the way to the goal)."""
    doc = safe_load_12(read_input_text(scene_file, "scene files", YAML_LIMIT))
    a, b = (np.asarray(p, dtype=float) for p in doc["route"]["waypoints"][-2:])
    along = (b - a) / np.linalg.norm(b - a)
    left = right = 0
    for o in doc["objects"]:
        if o.get("only_in") != "playback":
            continue
        d = np.asarray(o["center"], dtype=float) - a
        if 0.0 <= d @ along <= np.linalg.norm(b - a):
            side = along[0] * d[1] - along[1] * d[0]
            left, right = left + int(side > 0), right + int(side < 0)
    return {"final_leg_boxes_left": left, "final_leg_boxes_right": right}
