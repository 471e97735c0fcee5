# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Keyboard teaching: key decoding and limits, key scripts, refusal without a terminal, and a
killed keyboard run rebuilt with --resume (the real CLI on a pseudo-terminal:
test_teach_keyboard_terminal.py)."""

from __future__ import annotations

import io
import math
import os
import re
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
import yaml

from kiseki import load_map
from kiseki.apps.teach.keyboard import (
    KeyScript,
    Teleop,
    TerminalKeys,
    decode_keys,
    teach_keyboard,
)
from kiseki.apps.teach.teaching import TeachingRun, recover
from kiseki.sim.scene import load_scene
from kiseki.teach.waypoint_schema import read_waypoint_file

termios = pytest.importorskip("termios")


def test_keys_are_decoded_and_commands_stay_within_the_limits():
    keys, rest = decode_keys(b"wW\x1b[Aa\x1b[D \x1bOBmxq\x1b[")
    assert keys == ["w", "w", "up", "a", "left", "space", "down", "m", "q"] and rest == b"\x1b["
    keys, rest = decode_keys(rest + b"C\x1b")
    assert keys == ["right"] and rest == b"\x1b"
    teleop = Teleop(max_speed=1.0, max_yaw_rate=0.5)
    for _ in range(15):
        teleop.press("w")
    assert teleop.v == 1.0
    for _ in range(8):
        teleop.press("right")
    assert teleop.w == -0.5
    assert teleop.press("down") is None and teleop.v == 0.9
    assert teleop.press("m") == "mark" and teleop.press("q") == "quit"
    teleop.press("space")
    assert (teleop.v, teleop.w) == (0.0, 0.0)
    teleop.press("s")
    assert teleop.v == -0.1  # reverse
    with pytest.raises(ValueError, match="unknown key 'x'"):
        teleop.press("x")


@pytest.mark.parametrize("bad", [0.0, math.nan, math.inf, True])
def test_limits_and_times_that_are_no_positive_finite_number_are_refused(tmp_path, bad):
    """An infinite limit and True (1 m/s, 1 s) were taken; 0 and NaN were refused before too
    (the limits' message named neither limit nor value)."""
    with pytest.raises(
        ValueError, match=r"^the robot's max_speed must be a finite number > 0 m/s, got "
    ):
        Teleop(max_speed=bad, max_yaw_rate=0.5)
    with pytest.raises(
        ValueError, match=r"^the robot's max_yaw_rate must be a finite number > 0 rad/s, got "
    ):
        Teleop(max_speed=1.0, max_yaw_rate=bad)
    with pytest.raises(ValueError, match=r"^dt must be a finite number > 0 s, got "):
        TeachingRun(None, tmp_path / "run", dt=bad)  # refused before the scene is read
    leader, follower = os.openpty()
    try:
        with pytest.raises(ValueError, match=r"^the period must be a finite number > 0 s, got "):
            TerminalKeys(follower, bad)
    finally:
        os.close(leader)
        os.close(follower)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("0 w\n1 m\n", ": a key script must end with q (finish)"),
        ("0 w\n-1 q\n", ":2: time: must be greater than or equal to 0, got '-1'"),
        ("zero w\n1 q\n", ":1: time: must be a number of seconds (a line is TIME KEY"),
        ("0 w\n1 jump\n2 q\n", ":2: keys[0]: must be one of w, a, s, d, up, "),
        ("0 w\n1 jump\n2 q\n", "m, q, got 'jump'"),
        ("2 w\n1 q\n", ":2: time: must not decrease (the line before is at 2 s), got 1"),
        ("1\n2 q\n", ":1: keys: a line is TIME KEY [KEY ...]: no key after the time, got []"),
        ("0 w\n\n# c\n nan q\n", ":4: time: must be a finite number of seconds, got 'nan'"),
        ("0 w\n3600.5 q\n", ":2: time: must be less than or equal to 3600, got '3600.5'"),
    ],
)
def test_bad_key_scripts(tmp_path, text, message):
    path = tmp_path / "keys.txt"
    path.write_text(text)
    with pytest.raises(ValueError) as err:
        KeyScript(path)
    assert str(err.value).startswith(str(path)) and message in str(err.value)
    with pytest.raises(FileNotFoundError, match="key script not found"):
        KeyScript(tmp_path / "none.txt")


def test_a_key_script_teaches_like_the_operator(tmp_path, project_root):
    scene = load_scene(project_root / "data" / "worlds" / "factory_turn.yaml")
    keys = tmp_path / "keys.txt"
    # 0.5 m/s ahead for 5 s, mark; stop and turn left at 0.5 rad/s for 2 s; 0.3 m/s for 2 s
    keys.write_text(
        "# time keys\n0.0 w w w w w\n5.0 m space\n5.0 a a a a a\n7.0 space w w w\n9.0 m q\n"
    )
    status = io.StringIO()
    with KeyScript(keys) as source:
        result = teach_keyboard(scene, tmp_path / "t", source, seed=3, stream=status)
    assert [m["name"] for m in result.marks] == ["P0", "P1"]
    assert result.steps == 91  # t = 0.0 ... 9.0 s
    p0, p1 = result.marks
    # 50 steps: 0.05, 0.10, ... 0.5 m/s (0.5 m/s^2 ramp), then 0.5 m/s; no turn yet
    assert p0["truth"][0] == pytest.approx(0.275 + 2.0, abs=1e-6) and abs(p0["truth"][1]) < 1e-9
    # the turn at 1 rad/s^2: 0.1 ... 0.5 rad/s, 0.5 rad/s until 7.0 s (0.9 rad in 20 steps),
    # then 0.4 ... 0 rad/s (0.1 rad)
    assert p1["truth"][2] == pytest.approx(1.0, abs=1e-6)
    assert p1["truth"][1] > p0["truth"][1] + 0.2  # it drove off to the left
    lines = status.getvalue().splitlines()
    assert "m mark a waypoint" in lines[1] and lines[-1].startswith("step 90 | odom ")
    assert lines[-1].endswith("| v +0.3 w +0.0 | waypoints 2 (P1)")
    again = recover(scene, result.log, tmp_path / "r")
    assert again.marks == result.marks and again.steps == result.steps
    for band, path in again.maps.items():
        np.testing.assert_array_equal(load_map(path).cells, load_map(result.maps[band]).cells)


def test_a_teaching_without_a_mark_writes_its_maps_and_no_waypoint_file(tmp_path, project_root):
    """An empty waypoint list was written, which playback and serve then refused as invalid;
    one left by an earlier teaching in the folder belongs to other maps and goes."""
    scene = load_scene(project_root / "data" / "worlds" / "factory_turn.yaml")
    keys = tmp_path / "keys.txt"
    keys.write_text("0.0 w\n1.0 m q\n")
    with KeyScript(keys) as source:
        marked = teach_keyboard(scene, tmp_path / "t", source, stream=io.StringIO())
    assert marked.waypoints == tmp_path / "t" / "waypoints.yaml" and marked.waypoints.is_file()
    # each map's entry ties the waypoints to its image and to the geometry its YAML gives it
    entries = yaml.safe_load(marked.waypoints.read_text())["maps"]
    for band, path in marked.maps.items():
        saved = yaml.safe_load(path.read_text())
        assert (entries[band]["resolution"], entries[band]["origin"]) == (
            saved["resolution"],
            saved["origin"],
        )
    keys.write_text("0.0 w\n1.0 q\n")
    with KeyScript(keys) as source:
        bare = teach_keyboard(scene, tmp_path / "t", source, overwrite=True, stream=io.StringIO())
    assert (bare.marks, bare.waypoints) == ([], None)
    assert sorted(p.name for p in (tmp_path / "t").iterdir()) == [
        "map_band.pgm", "map_band.yaml", "map_plane.pgm", "map_plane.yaml", "map_truth.json",
        "teach.mcap",
    ]  # fmt: skip
    assert all(load_map(path).cells.size > 0 for path in bare.maps.values())
    # playback's message says why there is none (it said "run kiseki teach first")
    with pytest.raises(FileNotFoundError) as caught:
        read_waypoint_file(tmp_path / "t" / "waypoints.yaml")
    assert str(caught.value) == (
        f"{tmp_path / 't' / 'waypoints.yaml'}: no waypoint file (kiseki teach writes one when a "
        "waypoint is marked)"
    )


def test_the_readme_key_script_runs(tmp_path, project_root):
    readme = (project_root / "README.md").read_text(encoding="utf-8")
    section = readme[readme.index("### Teaching from the keyboard") :]
    script = re.search(r"```text\n(.*?)```", section, re.S).group(1)
    (tmp_path / "keys.txt").write_text(script)
    scene = load_scene(project_root / "data" / "worlds" / "factory_turn.yaml")
    with KeyScript(tmp_path / "keys.txt") as keys:
        result = teach_keyboard(scene, tmp_path / "t", keys, stream=io.StringIO())
    assert [m["name"] for m in result.marks] == ["P0", "P1"] and result.steps == 91
    assert result.marks[1]["truth"][2] > 0.5  # it turned left in place at 0.2 rad/s for 4 s


# --------------------------------------------------------------------------------------------
# The real CLI in a pseudo-terminal
# --------------------------------------------------------------------------------------------


def test_keyboard_needs_a_terminal_or_a_key_script(tmp_path, project_root):
    scene = project_root / "data" / "worlds" / "factory_turn.yaml"
    cli = [sys.executable, "-m", "kiseki.cli", "teach", str(scene), "-o", str(tmp_path / "t")]
    done = subprocess.run(
        [*cli, "--keyboard"], stdin=subprocess.DEVNULL, capture_output=True, text=True
    )
    assert done.returncode == 1
    assert done.stderr.strip() == (
        "kiseki: error: --keyboard needs a terminal on stdin (or --keys FILE of timed keys)"
    )
    assert not (tmp_path / "t").exists()
    keys = tmp_path / "keys.txt"
    keys.write_text("0 w\n1 q\n")
    done = subprocess.run([*cli, "--keys", str(keys)], capture_output=True, text=True)
    assert done.returncode == 1 and "--keys FILE goes with --keyboard" in done.stderr
    keys.write_text("0 w\n1 fly\n2 q\n")
    done = subprocess.run([*cli, "--keyboard", "--keys", str(keys)], capture_output=True, text=True)
    assert done.returncode == 1 and "keys.txt:2: keys[0]: must be one of w, a," in done.stderr
    assert done.stderr.strip().endswith("got 'fly'")
    (tmp_path / "t").mkdir()
    (tmp_path / "t" / "teach.mcap").write_bytes(b"")  # an earlier run's log is not replaced
    keys.write_text("0 w\n1 q\n")
    done = subprocess.run([*cli, "--keyboard", "--keys", str(keys)], capture_output=True, text=True)
    assert done.returncode == 1 and "a teaching log exists; --resume" in done.stderr
    assert (tmp_path / "t" / "teach.mcap").read_bytes() == b""


def test_a_killed_keyboard_run_is_recovered(tmp_path, project_root):
    scene = project_root / "data" / "worlds" / "factory_turn.yaml"
    keys = tmp_path / "keys.txt"
    keys.write_text("0 w w w\n2.0 m\n3.0 a\n600 q\n")  # the kill comes long before q
    cli = [sys.executable, "-m", "kiseki.cli", "teach", str(scene), "-o", str(tmp_path / "t")]
    status = tmp_path / "status.txt"
    with status.open("w") as stream:
        proc = subprocess.Popen([*cli, "--keyboard", "--keys", str(keys)], stdout=stream)
        deadline = time.monotonic() + 120
        shown: list[int] = []
        while time.monotonic() < deadline and (not shown or max(shown) < 60):
            time.sleep(0.05)
            shown = [int(n) for n in re.findall(r"step +(\d+) \|", status.read_text())]
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait()
    shown = [int(n) for n in re.findall(r"step +(\d+) \|", status.read_text())]
    assert shown and max(shown) >= 60, "the keyboard run showed no progress before the kill"
    done = subprocess.run([*cli, "--resume"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    steps = int(re.search(r"(\d+) steps", done.stdout.replace("\n", " ")).group(1))
    # the status counts a step once it is logged: at most the last second (10 steps) is lost
    assert max(shown) + 1 - 10 <= steps < 6000
    doc = yaml.safe_load((tmp_path / "t" / "waypoints.yaml").read_text())
    assert [w["name"] for w in doc["waypoints"]] == ["P0"]
    assert doc["waypoints"][0]["truth"][0] > 0.3  # marked after 2 s at up to 0.3 m/s
    assert (tmp_path / "t" / "map_band.yaml").is_file()
