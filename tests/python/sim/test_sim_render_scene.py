# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``kiseki sim render`` draws a run over the scene it was recorded in: a run records its scene
file's SHA-1, and a scene whose bytes differ (another scene, or this one edited) is refused in
one line, as are a missing run file and a missing --scene (they drew the run over any scene,
and named a missing file in Python's words)."""

from __future__ import annotations

import hashlib
import subprocess
import sys
from pathlib import Path

from kiseki.io.runlog import read_run

SCENE = Path(__file__).resolve().parents[3] / "data" / "worlds" / "speed_corner.yaml"
CLI = [sys.executable, "-m", "kiseki.cli", "sim"]


def _sim(*args) -> subprocess.CompletedProcess:
    return subprocess.run([*CLI, *map(str, args)], capture_output=True, text=True)


def test_render_refuses_a_scene_other_than_the_run_s(tmp_path):
    (tmp_path / "cmd.csv").write_text("t,vx,vy,w\n0,0.3,0,0\n1,0,0,0.5\n")
    run = tmp_path / "r.mcap"
    done = _sim("run", SCENE, "-o", run, "--controller", "commands",
                "--commands", tmp_path / "cmd.csv", "--duration", "2")  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert read_run(run).metadata["scene_sha1"] == hashlib.sha1(SCENE.read_bytes()).hexdigest()
    assert _sim("render", run, "-o", tmp_path / "r.gif").returncode == 0
    edited = tmp_path / "edited.yaml"
    edited.write_text(SCENE.read_text() + "\n# edited\n")
    refusals = {
        ("--scene", edited): f"{run} was recorded in {SCENE}, not in {edited} (the scene files "
        "differ): give the scene it was recorded in",
        ("--scene", tmp_path / "none.yaml"): f"--scene {tmp_path / 'none.yaml'}: no such scene "
        "file",
    }
    for extra, message in refusals.items():
        done = _sim("render", run, "-o", tmp_path / "e.gif", *extra)
        assert (done.returncode, done.stderr.strip()) == (1, f"kiseki: error: {message}")
    done = _sim("render", tmp_path / "none.mcap", "-o", tmp_path / "e.gif")
    assert (done.returncode, done.stderr.strip()) == (
        1,
        f"kiseki: error: {tmp_path / 'none.mcap'}: no such run file (an MCAP file of kiseki sim "
        "run)",
    )
    assert not (tmp_path / "e.gif").exists()
