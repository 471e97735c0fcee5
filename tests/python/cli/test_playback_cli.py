# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""`kiseki playback --waypoints FILE --map MAP`: a route played back from a hand-written
waypoint file on a copy of its map, the printed stop checked against the run's own log and the
waypoints, and another map refused."""

from __future__ import annotations

import hashlib
import re
import shutil
import subprocess
import sys

import numpy as np
import pytest
import yaml

from kiseki.io.ros_map import save_map
from kiseki.io.runlog import read_run
from kiseki.sim.scene import load_scene
from kiseki.teach.local_maps import BANDS


def kiseki(*args, cwd):
    return subprocess.run(
        [sys.executable, "-m", "kiseki.cli", *map(str, args)],
        cwd=cwd,
        capture_output=True,
        text=True,
    )


def test_playback_from_waypoints_on_a_copy_of_the_map(tmp_path, project_root):
    scene_file = project_root / "data" / "worlds" / "factory_corridor.yaml"
    scene = load_scene(scene_file)
    # the taught maps replaced by the scene's truth in each height band, the waypoints by the
    # thesis' P1 and P2 (map frame = world frame here)
    digests = {}
    (tmp_path / "t").mkdir()
    for band, (lo, hi) in BANDS.items():
        save_map(scene.ground_truth(lo, hi), tmp_path / "t" / f"map_{band}.yaml")
        digests[band] = hashlib.sha1((tmp_path / "t" / f"map_{band}.pgm").read_bytes()).hexdigest()
    marks = [
        {"id": i, "name": n, "x": x, "y": 0.0, "theta": 0.0, "truth": [x, 0.0, 0.0]}
        for i, (n, x) in enumerate([("P1", 7.4), ("P2", 13.0)])
    ]
    doc = {
        "maps": {b: {"file": f"map_{b}.yaml", "image_sha1": d} for b, d in digests.items()},
        "waypoints": marks,
    }
    (tmp_path / "t" / "waypoints.yaml").write_text(yaml.safe_dump(doc, sort_keys=False))
    (tmp_path / "copy").mkdir()
    for name in ("map_band.yaml", "map_band.pgm"):
        shutil.copy(tmp_path / "t" / name, tmp_path / "copy" / name)
    common = [scene_file, "--route", "P1,P2", "--waypoints", "t/waypoints.yaml", "--seed", 1]
    done = kiseki(
        "playback", *common, "--map", "copy/map_band.yaml", "--log", "r.mcap", cwd=tmp_path
    )
    assert done.returncode == 0, done.stderr
    text = " ".join(done.stdout.split())
    number = r"(-?\d+\.\d+)"
    found = re.search(
        rf"estimated stop \({number}, {number}\) in the map, {number} m from P2; true stop "
        rf"\({number}, {number}\), {number} m from where P2 was taught; goal reached: True",
        text,
    )
    assert found, text
    ex, ey, e_dist, tx, ty, t_dist = (float(v) for v in found.groups())
    # the printed figures against the waypoint and the run's log: the estimate stopped within
    # the 0.1 m rule of P2, and the robot truly rests where the log's last pose is
    assert e_dist == pytest.approx(np.hypot(ex - 13.0, ey), abs=2e-3) and e_dist <= 0.1
    last = read_run(tmp_path / "r.mcap").messages("/ground_truth")[-1][1]["pose"]["position"]
    assert (tx, ty) == pytest.approx((last["x"], last["y"]), abs=1e-3)
    assert t_dist == pytest.approx(np.hypot(tx - 13.0, ty), abs=2e-3) and t_dist <= 0.1
    # the plane map is not the band map the method needs, and an edited copy is no taught map
    done = kiseki("playback", *common, "--map", "t/map_plane.yaml", cwd=tmp_path)
    assert done.returncode == 1 and "is the 'plane' map of" in done.stderr
    (tmp_path / "copy" / "map_band.pgm").write_bytes(
        (tmp_path / "t" / "map_band.pgm").read_bytes()[:-1] + b"\x00"
    )
    done = kiseki("playback", *common, "--map", "copy/map_band.yaml", cwd=tmp_path)
    assert done.returncode == 1 and "is not the one" in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1
    # teach records each map's resolution and origin with its image's digest: the same image
    # at another resolution or origin (the YAML edited) puts the waypoints elsewhere and is
    # refused too (only the image was checked; the robot was played back on it)
    shutil.copy(tmp_path / "t" / "map_band.pgm", tmp_path / "copy" / "map_band.pgm")
    taught = yaml.safe_load((tmp_path / "t" / "map_band.yaml").read_text())
    for band, entry in doc["maps"].items():
        saved = yaml.safe_load((tmp_path / "t" / f"map_{band}.yaml").read_text())
        entry.update(resolution=saved["resolution"], origin=saved["origin"])
    (tmp_path / "t" / "waypoints.yaml").write_text(yaml.safe_dump(doc, sort_keys=False))
    before = f"resolution {taught['resolution']:g} m and origin {taught['origin']}"
    for key, value in (("resolution", 2 * taught["resolution"]), ("origin", [0.0, 0.0, 0.0])):
        edited = {**taught, key: value}
        (tmp_path / "copy" / "map_band.yaml").write_text(yaml.safe_dump(edited))
        done = kiseki("playback", *common, "--map", "copy/map_band.yaml", cwd=tmp_path)
        now = f"resolution {edited['resolution']:g} m and origin {edited['origin']}"
        assert (done.returncode, done.stderr.strip()) == (
            1,
            f"kiseki: error: copy/map_band.yaml: {now}, but t/waypoints.yaml was taught on "
            f"{before}",
        )
