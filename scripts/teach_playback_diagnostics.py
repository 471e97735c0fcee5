# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Diagnostics of the teaching-and-playback stop errors (exp2-turn), for the notes of its report.

For each seed it teaches the turn route twice -- once as the experiment does (odometry and depth
noise) and once with a perfect teacher (no odometry error, noise-free depth: the map is the true
geometry in the world frame) -- and plays each method back on both maps, with the filter's
default motion noise and with a tenth of it. It prints where the robot rests relative to the
goal (x along the final leg, y to its left) and the estimate's heading error at the stop,
and, per teacher, each taught map against the scene's truth (share of obstacle cells in reach
erased, of visible free cells marked occupied).

    python scripts/teach_playback_diagnostics.py --seeds 0 1 2 --methods conventional proposal2

If the perfect map removes the bias, the taught map causes it; if not, the model or the filter
does. A smaller heading error and sideways stop error with less motion noise shows that the
filter's heading diffuses faster than the odometry's and the flat heading likelihood does not
pin it.
"""

from __future__ import annotations

import argparse
import math
import tempfile
from pathlib import Path

import yaml

from kiseki.apps.teach import PlaybackConfig, playback, teach
from kiseki.core import derive_seed
from kiseki.io.ros_map import load_map
from kiseki.sim.scene import load_scene
from kiseki.teach.local_maps import METHODS

ROOT = Path(__file__).resolve().parents[1]
NO_ODOMETRY_ERROR = {
    k: 0.0
    for k in (
        "left_radius_error",
        "right_radius_error",
        "track_width_error",
        "initial_heading_offset",
        "initial_heading_sd",
        "slip_distance_coeff",
        "slip_rotation_coeff",
    )
}


def perfect_scene(scene_file: Path, tmp: Path) -> Path:
    doc = yaml.safe_load(scene_file.read_text(encoding="utf-8"))
    doc["robot"]["odometry_errors"] = NO_ODOMETRY_ERROR
    for sensor in doc["sensors"]:
        if sensor["type"] == "depth_camera":
            sensor["params"] = {"disparity_sd": 0.0, "disparity_step": 0.0}
    out = tmp / "perfect.yaml"
    out.write_text(yaml.safe_dump(doc), encoding="utf-8")
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default=str(ROOT / "data" / "worlds" / "factory_turn.yaml"))
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    parser.add_argument("--methods", nargs="+", default=["conventional", "proposal1", "proposal2"])
    parser.add_argument("--merge", default="thesis", choices=["thesis", "evidence"])
    args = parser.parse_args()
    scene_file = Path(args.scene)
    default = PlaybackConfig().alphas
    noise = (("default", default), ("tenth", tuple(a / 10 for a in default)))
    print("seed teacher method alphas: stop_dx stop_dy stop_error estimate_heading_error_deg")
    for seed in args.seeds:
        with tempfile.TemporaryDirectory() as tmp:
            tmp = Path(tmp)
            teachers = {"noisy": scene_file, "perfect": perfect_scene(scene_file, tmp)}
            for teacher, file in teachers.items():
                taught = teach(
                    load_scene(file), tmp / teacher, seed=derive_seed(seed, 1), merge=args.merge
                )
                for band, t in taught.truth.items():
                    print(
                        f"{seed} {teacher} map {band}: erased {100 * t['erased_share']:.1f} %, "
                        f"occupied {100 * t['false_occupied_share']:.1f} %",
                        flush=True,
                    )
                goal = taught.marks[-1]
                maps = {band: load_map(p) for band, p in taught.maps.items()}
                scene = load_scene(scene_file, "playback")
                for method in args.methods:
                    for name, alphas in noise:
                        r = playback(
                            scene,
                            maps[METHODS[method][0]],
                            taught.marks,
                            PlaybackConfig(method=method, seed=derive_seed(seed, 2), alphas=alphas),
                        )
                        dx = r.stop_true[0] - goal["truth"][0]
                        dy = r.stop_true[1] - goal["truth"][1]
                        dth = (r.stop_estimate[2] - goal["theta"]) - (
                            r.stop_true[2] - goal["truth"][2]
                        )
                        print(
                            f"{seed} {teacher} {method} {name}: {dx:+.3f} {dy:+.3f} "
                            f"{math.hypot(dx, dy):.3f} {math.degrees(dth):+.2f}",
                            flush=True,
                        )


if __name__ == "__main__":
    main()
