# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Writes data/maps/factory_corridor.{yaml,pgm}: the 2-D ground truth of the simulated factory
corridor (data/worlds/factory_corridor.yaml) in the 0.35-0.45 m band, the height of the thesis'
fixed scan plane (0.4 m): walls, shelf posts, table legs, the pillar and the 0.1 m partition.

Run from the repository root: python scripts/make_demo_map.py
"""

from __future__ import annotations

from pathlib import Path

import kiseki
from kiseki.sim.scene import load_scene

ROOT = Path(__file__).resolve().parents[1]

if __name__ == "__main__":
    scene = load_scene(ROOT / "data" / "worlds" / "factory_corridor.yaml")
    grid = scene.ground_truth(0.35, 0.45)
    print(kiseki.save_map(grid, ROOT / "data" / "maps" / "factory_corridor.yaml"))
