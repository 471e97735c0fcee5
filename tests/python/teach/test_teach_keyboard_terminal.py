# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Keyboard teaching through the real CLI on a pseudo-terminal: keys pressed while it runs,
the terminal mode restored, also on Ctrl-C (moved from test_teach_keyboard.py)."""

from __future__ import annotations

import math
import os
import re
import select
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
import yaml

from kiseki.io.runlog import read_run

termios = pytest.importorskip("termios")


class _Terminal:
    """Runs the CLI with a pseudo-terminal as its controlling terminal, stdin and stdout."""

    def __init__(self, args: list[str]) -> None:
        import fcntl

        self.master, self.slave = os.openpty()
        self.before = termios.tcgetattr(self.slave)
        self.output = b""

        def controlling_terminal() -> None:  # runs in the child after setsid()
            fcntl.ioctl(0, termios.TIOCSCTTY, 0)

        self.proc = subprocess.Popen(
            [sys.executable, "-m", "kiseki.cli", *args],
            stdin=self.slave,
            stdout=self.slave,
            stderr=self.slave,
            start_new_session=True,
            preexec_fn=controlling_terminal,
        )

    def read(self, seconds: float) -> None:
        end = time.monotonic() + seconds
        while (left := end - time.monotonic()) > 0:
            ready, _, _ = select.select([self.master], [], [], left)
            if ready:
                try:
                    self.output += os.read(self.master, 65536)
                except OSError:  # the child closed the terminal
                    return

    def step(self) -> int:
        steps = re.findall(rb"step +(\d+) \|", self.output)
        return int(steps[-1]) if steps else -1

    def wait_for_step(self, step: int, timeout: float = 120.0) -> int:
        """Waits until the status line shows step `step` or later; returns the step shown."""
        end = time.monotonic() + timeout
        while self.step() < step:
            assert time.monotonic() < end, f"no step {step} shown: {self.output[-300:]!r}"
            assert self.proc.poll() is None, f"the CLI ended: {self.output[-500:]!r}"
            self.read(0.05)
        return self.step()

    def press(self, keys: bytes) -> None:
        os.write(self.master, keys)

    def finish(self, timeout: float = 120.0) -> int:
        end = time.monotonic() + timeout
        while self.proc.poll() is None and time.monotonic() < end:
            self.read(0.1)
        self.read(0.2)
        code = self.proc.wait(timeout=5)
        return code

    def close(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait()
        os.close(self.master)
        os.close(self.slave)


def _flags(attrs) -> tuple[bool, bool]:
    return bool(attrs[3] & termios.ICANON), bool(attrs[3] & termios.ECHO)


def test_keyboard_teaching_in_a_terminal(tmp_path, project_root):
    scene = project_root / "data" / "worlds" / "factory_turn.yaml"
    out = tmp_path / "t"
    term = _Terminal(["teach", str(scene), "--keyboard", "-o", str(out), "--seed", "2"])
    try:
        now = term.wait_for_step(0)
        assert b"m mark a waypoint" in term.output  # the key help
        assert _flags(termios.tcgetattr(term.slave)) == (False, False)  # cbreak, no echo
        # each wait counts from the step shown when the keys went out, so a slow machine
        # only makes the moves longer
        term.press(b"wwww\x1b[A")  # 0.5 m/s ahead (Up arrow for the last step)
        now = term.wait_for_step(now + 50)
        term.press(b" ")  # stop
        now = term.wait_for_step(now + 15)
        term.press(b"m")
        now = term.wait_for_step(now + 5)
        term.press(b"aaaaa")  # turn left in place at 0.5 rad/s
        now = term.wait_for_step(now + 12)
        term.press(b" www")  # stop turning, 0.3 m/s ahead
        now = term.wait_for_step(now + 25)
        term.press(b"m")
        term.wait_for_step(now + 2)
        term.press(b"q")
        assert term.finish() == 0, term.output[-500:]
        after = termios.tcgetattr(term.slave)
    finally:
        term.close()
    assert after == term.before and _flags(after) == (True, True)  # the terminal is restored
    text = re.sub(r"\x1b\[[0-9;]*[A-Za-z]", "", term.output.decode(errors="replace"))
    text = " ".join(text.split())  # rich wraps the summary at the terminal's width
    assert "waypoints 2 (P1)" in text and re.search(r"\d+ steps, waypoints P0, P1", text)
    assert (out / "map_band.yaml").is_file() and (out / "map_plane.yaml").is_file()
    doc = yaml.safe_load((out / "waypoints.yaml").read_text())
    p0, p1 = doc["waypoints"]
    assert (p0["name"], p1["name"]) == ("P0", "P1")
    run = read_run(out / "teach.mcap")
    odom = {round(t, 6): m for t, m in run.messages("/odom")}
    times, poses = run.poses("/ground_truth")
    truth = {round(float(t), 6): p for t, p in zip(times, poses, strict=True)}
    marked = [(round(t, 6), m) for t, m in run.messages("/waypoints")]
    assert [m for _, m in marked] == doc["waypoints"]
    for t, mark in marked:
        # a mark is the logged odometry and true pose of the step it was pressed at
        assert (mark["x"], mark["y"], mark["theta"]) == (
            odom[t]["x"],
            odom[t]["y"],
            odom[t]["theta"],
        )
        np.testing.assert_allclose(mark["truth"], truth[t], atol=1e-9)  # via a quaternion
        # odometry drift: the start heading is off by -0.2 deg + N(0, 0.7 deg) (3 sd: 2.3 deg),
        # so under 0.05 m of lateral error per metre driven, plus 0.05 m for slip and the turn
        driven = math.hypot(*mark["truth"][:2])
        assert math.hypot(mark["x"] - mark["truth"][0], mark["y"] - mark["truth"][1]) < (
            0.05 * driven + 0.05
        )
        assert abs(mark["theta"] - mark["truth"][2]) < math.radians(3.0)
    # ahead along +x: at least 48 steps at 0.5 m/s after the 1 s ramp (over 2 m)
    assert p0["truth"][0] > 2.0 and abs(p0["truth"][1]) < 0.01 and abs(p0["truth"][2]) < 0.01
    # a left turn of at least 10 steps: 0.15 rad up the ramp, 0.25 rad at 0.5 rad/s, 0.1 rad
    # braking; then at least 23 steps at up to 0.3 m/s (over 0.5 m) to the left of +x
    assert p1["truth"][2] > 0.45
    assert p1["truth"][1] - p0["truth"][1] > 0.15 and p1["truth"][0] > p0["truth"][0]


@pytest.mark.parametrize("stop", ["ctrl-c", "sigterm"])
def test_an_interrupt_restores_the_terminal_and_keeps_the_log(tmp_path, project_root, stop):
    scene = project_root / "data" / "worlds" / "factory_turn.yaml"
    out = tmp_path / "t"
    term = _Terminal(["teach", str(scene), "--keyboard", "-o", str(out)])
    try:
        now = term.wait_for_step(0)
        term.press(b"ww")
        now = term.wait_for_step(now + 10)
        term.press(b"m")
        term.wait_for_step(now + 15)
        if stop == "ctrl-c":
            term.press(b"\x03")  # SIGINT from the terminal (cbreak mode keeps ISIG)
        else:
            term.proc.send_signal(signal.SIGTERM)
        assert term.finish() == (130 if stop == "ctrl-c" else 143)
        after = termios.tcgetattr(term.slave)
    finally:
        term.close()
    assert after == term.before
    assert b"interrupted" in term.output and b"--resume" in term.output
    assert not (out / "waypoints.yaml").exists()
    done = subprocess.run(
        [sys.executable, "-m", "kiseki.cli", "teach", str(scene), "-o", str(out), "--resume"],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr
    # the log was closed on the way out: every step shown is in it
    steps = int(re.search(r"(\d+) steps", done.stdout.replace("\n", " ")).group(1))
    assert steps >= term.step() + 1
    assert [
        w["name"] for w in yaml.safe_load((out / "waypoints.yaml").read_text())["waypoints"]
    ] == ["P0"]
