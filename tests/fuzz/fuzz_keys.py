# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Fuzz the key-script reader kiseki.apps.teach.keyboard.KeyScript (``kiseki teach --keys``) and
the keys it hands out; see fuzz_common.py."""

from __future__ import annotations

from pathlib import Path

from fuzz_common import main

from kiseki.apps.teach.keyboard import KeyScript, Teleop


def seeds(_folder: Path):
    yield b"# time keys\n0.0 w w w w w\n5.0 m space\n5.0 a a a a a\n7.0 space w w w\n9.0 m q\n"
    yield b"0 up UP down left right\n0.5 s d # turn\n1e1 Q\n"


def read(path: Path) -> object:
    script = KeyScript(path)
    teleop = Teleop(max_speed=1.0, max_yaw_rate=1.0)
    keys = script.wait(0.0) + script.wait(float("inf"))
    return [teleop.press(key) for key in keys]


if __name__ == "__main__":
    main(read, seeds, suffix=".keys")
