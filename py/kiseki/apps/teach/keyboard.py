# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Keyboard teaching: the operator pushes the simulated robot from a terminal and marks the
waypoints, at the simulation rate (10 Hz), with the same steps, log and outputs as scripted
teaching (:class:`~kiseki.apps.teach.teaching.TeachingRun`), so ``kiseki teach --resume`` rebuilds
a killed keyboard run too.

Keys (like ``teleop_twist_keyboard``, but each press changes the command by one step):
w / Up and s / Down raise and lower the forward speed by 0.1 m/s, a / Left and d / Right the
turn rate (counter-clockwise positive) by 0.1 rad/s, both within the robot's limits; space
stops; m marks a waypoint at the odometry pose, named P0, P1, ...; q finishes and writes the
maps and the waypoint file (no waypoint file when nothing was marked). A push into an obstacle
is not made: the robot stops where it is and the command returns to zero (a line says where).

Keys come from the terminal (cbreak mode, no Enter needed; the terminal's mode is restored on
exit, also on an exception, Ctrl-C or SIGTERM) or from a key script for tests and demos: lines
``TIME KEY [KEY ...]`` with TIME the simulated seconds at which the keys are pressed, KEY one
of w a s d m q or up down left right space, ``#`` comments; the script must end with q and runs
as fast as the simulation can.
"""

from __future__ import annotations

import math
import os
import select
import signal
import sys
import time
from typing import TextIO

from kiseki._support.real_numbers import check_number
from kiseki.apps.teach.teaching import TeachingRun
from kiseki.apps.teach.teaching_files import TeachResult
from kiseki.sim.scene import Scene
from kiseki.teach.key_script_schema import KEYS, read_key_script

__all__ = [
    "HELP",
    "KeyScript",
    "Teleop",
    "TerminalKeys",
    "decode_keys",
    "teach_keyboard",
]

LINEAR_STEP = 0.1  # m/s per key press
ANGULAR_STEP = 0.1  # rad/s per key press
HELP = (
    f"keyboard teaching: w/Up s/Down speed +-{LINEAR_STEP} m/s, a/Left d/Right turn "
    f"+-{ANGULAR_STEP} rad/s,\n"
    "  space stop, m mark a waypoint (P0, P1, ...), q finish and write the maps\n"
)
_ESCAPES = {b"A": "up", b"B": "down", b"C": "right", b"D": "left"}
_CHARS = {b" ": "space", **{k.encode(): k for k in "wasdmq"}}


def decode_keys(data: bytes) -> tuple[list[str], bytes]:
    """Key names from terminal bytes (letters, space, arrow escape sequences ESC [ X and
    ESC O X; upper-case letters count as lower-case) and the undecoded tail (an escape
    sequence cut by the read). Other bytes are ignored."""
    keys: list[str] = []
    i = 0
    while i < len(data):
        b = data[i : i + 1]
        if b == b"\x1b":
            if i + 2 >= len(data):
                return keys, data[i:]  # maybe the start of an arrow: wait for the rest
            if data[i + 1 : i + 2] in (b"[", b"O") and data[i + 2 : i + 3] in _ESCAPES:
                keys.append(_ESCAPES[data[i + 2 : i + 3]])
                i += 3
                continue
            i += 1
            continue
        key = _CHARS.get(b.lower())
        if key is not None:
            keys.append(key)
        i += 1
    return keys, b""


class Teleop:
    """The velocity command the keys set: each press changes it by one step, within the
    robot's limits (max_speed m/s, max_yaw_rate rad/s)."""

    def __init__(self, max_speed: float, max_yaw_rate: float) -> None:
        check_number(max_speed, "the robot's max_speed", 0.0, low_open=True, unit="m/s")
        check_number(max_yaw_rate, "the robot's max_yaw_rate", 0.0, low_open=True, unit="rad/s")
        self.max_speed, self.max_yaw_rate = float(max_speed), float(max_yaw_rate)
        self.v = 0.0
        self.w = 0.0

    def press(self, key: str) -> str | None:
        """Applies a key; returns "mark" or "quit" for those keys, else None."""
        if key in ("w", "up", "s", "down"):
            step = LINEAR_STEP if key in ("w", "up") else -LINEAR_STEP
            self.v = round(min(max(self.v + step, -self.max_speed), self.max_speed), 6)
        elif key in ("a", "left", "d", "right"):
            step = ANGULAR_STEP if key in ("a", "left") else -ANGULAR_STEP
            self.w = round(min(max(self.w + step, -self.max_yaw_rate), self.max_yaw_rate), 6)
        elif key == "space":
            self.v = self.w = 0.0
        elif key == "m":
            return "mark"
        elif key == "q":
            return "quit"
        else:
            raise ValueError(f"unknown key {key!r} (known: {', '.join(KEYS)})")
        return None


class KeyScript:
    """Timed keys from a file (see the module docstring); :meth:`wait` hands out the keys due
    at a simulated time at once, without waiting for the wall clock."""

    def __init__(self, path: str | os.PathLike) -> None:
        self._events = read_key_script(path)
        self._next = 0

    def wait(self, t: float) -> list[str]:
        """The keys pressed at simulated times up to t (half a millisecond of slack)."""
        keys = []
        while self._next < len(self._events) and self._events[self._next][0] <= t + 5e-4:
            keys.append(self._events[self._next][1])
            self._next += 1
        return keys

    def __enter__(self) -> KeyScript:
        return self

    def __exit__(self, *exc) -> None:
        pass


class TerminalKeys:
    """Keys from a terminal in cbreak mode (no Enter, no echo; Ctrl-C still interrupts).
    :meth:`wait` paces the loop: it returns the keys pressed until one period (the run's dt)
    after the last call (at once if the simulation fell behind). The terminal's mode is
    restored on exit."""

    def __init__(self, fd: int, period: float) -> None:
        try:
            # here, not at the top: termios and tty exist on POSIX only
            import termios
            import tty
        except ImportError:
            raise RuntimeError("keyboard teaching needs a POSIX terminal (termios)") from None
        if not os.isatty(fd):
            raise ValueError("keyboard teaching needs a terminal on stdin")
        check_number(period, "the period", 0.0, low_open=True, unit="s")
        self._termios, self._tty = termios, tty
        self.fd, self.period = fd, float(period)
        self._saved = None
        self._old_handlers: dict[int, object] = {}
        self._received: int | None = None
        self._deadline = 0.0
        self._pending = b""

    def __enter__(self) -> TerminalKeys:
        self._saved = self._termios.tcgetattr(self.fd)
        # Ctrl-C (SIGINT) and SIGTERM only set a flag, which `wait` turns into
        # KeyboardInterrupt / SystemExit(143) at a safe point: an exception raised by the
        # handler itself may surface inside a C extension that clears it (a pybind11 argument
        # conversion does), and the interrupt would be lost.
        for signum in (signal.SIGINT, signal.SIGTERM):
            try:
                self._old_handlers[signum] = signal.signal(signum, self._receive)
            except ValueError:  # not the main thread: leave the defaults
                break
        self._tty.setcbreak(self.fd, self._termios.TCSANOW)
        self._deadline = time.monotonic()
        return self

    def __exit__(self, *exc) -> None:
        if self._saved is not None:
            self._termios.tcsetattr(self.fd, self._termios.TCSADRAIN, self._saved)
            self._saved = None
        for signum, handler in self._old_handlers.items():
            signal.signal(signum, handler)
        self._old_handlers = {}

    def _receive(self, signum, frame) -> None:
        self._received = signum

    def _raise_if_signalled(self) -> None:
        if self._received == signal.SIGINT:
            raise KeyboardInterrupt
        if self._received is not None:
            raise SystemExit(128 + self._received)

    def wait(self, t: float) -> list[str]:
        del t  # the wall clock paces the terminal
        now = time.monotonic()
        self._deadline = max(self._deadline + self.period, now)
        keys: list[str] = []
        while True:
            self._raise_if_signalled()
            timeout = self._deadline - time.monotonic()
            ready, _, _ = select.select([self.fd], [], [], max(timeout, 0.0))
            self._raise_if_signalled()
            if ready:
                data = os.read(self.fd, 64)
                if not data:
                    raise RuntimeError("the terminal closed")
                got, self._pending = decode_keys(self._pending + data)
                keys += got
            if timeout <= 0:
                return keys


def _status(run: TeachingRun, teleop: Teleop) -> str:
    x, y, th = run.odom
    last = f" ({run.marks[-1]['name']})" if run.marks else ""
    return (
        f"step {run.steps - 1} | odom {x:.2f} {y:.2f} {math.degrees(th):.1f} deg | "
        f"v {teleop.v:+.1f} w {teleop.w:+.1f} | waypoints {len(run.marks)}{last}"
    )


def teach_keyboard(
    scene: Scene,
    out: str | os.PathLike,
    keys: KeyScript | TerminalKeys,
    seed: int = 0,
    dt: float = 0.1,
    overwrite: bool = False,
    stream: TextIO | None = None,
    merge: str = "thesis",
) -> TeachResult:
    """Teaches from keys (see the module docstring): one :meth:`TeachingRun.step` per period
    with the velocity command the keys set, a waypoint P<n> at each m, until q. A status line
    (step, odometry pose, command, waypoints) goes to `stream`: refreshed in place on a
    terminal, one line a second and at each key otherwise."""
    stream = stream if stream is not None else sys.stdout
    in_place = stream.isatty()
    with TeachingRun(scene, out, seed, dt, overwrite, {"mode": "keyboard"}, merge) as run:
        stream.write(HELP)
        stream.flush()
        try:
            _drive(run, keys, Teleop(*run.limits), stream, in_place)
        finally:
            if in_place:  # whatever comes next starts on a line of its own
                stream.write("\n")
                stream.flush()
        return run.finish()


def _drive(run: TeachingRun, keys, teleop: Teleop, stream: TextIO, in_place: bool) -> None:
    """The loop: the keys due, the status of the logged step, then one step, until q."""
    while True:
        pressed, done = False, False
        for key in keys.wait(run.t):
            pressed = True
            action = teleop.press(key)
            if action == "mark":
                run.mark(f"P{len(run.marks)}")
            elif action == "quit":
                done = True
                break
        # the status counts a step once it is logged
        if in_place:
            stream.write("\r" + _status(run, teleop) + "\x1b[K")
            stream.flush()
        elif (run.steps - 1) % 10 == 0 or pressed:
            stream.write(_status(run, teleop) + "\n")
            stream.flush()
        if done:
            return
        contact = run.step(teleop.v, teleop.w)
        if contact is not None:  # the cart stopped at the obstacle: so does the operator's push
            teleop.press("space")
            x, y = contact.contact
            start = "\r" if in_place else ""
            stream.write(
                f"{start}bumped into an obstacle at ({x:.2f}, {y:.2f}) m: the robot stopped; "
                "back off (s) before turning (a, d)\n"
            )
            stream.flush()
