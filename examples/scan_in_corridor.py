# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Load the corridor map kept in data/, cast one laser scan at P1 and draw it.

Run from the repository root: python examples/scan_in_corridor.py [OUT.png]
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import kiseki
from kiseki.grid import beam_angles
from kiseki.plots import render_map

ROOT = Path(__file__).resolve().parents[1]


def main(out: Path) -> None:
    grid = kiseki.load_map(ROOT / "data" / "maps" / "factory_corridor.yaml")
    pose = np.array([[7.4, 0.0, 0.0]])  # P1, facing along the corridor
    angles = beam_angles(541, np.deg2rad(270))  # a 0.5 deg laser over 270 deg
    ranges = grid.cast_scans(pose, angles, max_range=30.0)[0]
    print(f"ahead: {ranges[270]:.2f} m, left: {ranges[450]:.2f} m, right: {ranges[90]:.2f} m")
    hits = ranges < 30.0
    points = pose[0, :2] + ranges[hits, None] * np.column_stack(
        [np.cos(angles[hits]), np.sin(angles[hits])]
    )
    render_map(grid, out, trajectory=pose, points=points, title="one scan at P1")
    print(f"wrote {out}")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("scan_in_corridor.png"))
