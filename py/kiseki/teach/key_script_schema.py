# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The model of a key script (``kiseki teach --keys FILE``: the scripted keys of a keyboard
teaching run, for tests and demos), one line at a time::

    # time keys
    0.0 w w w w w      # TIME (simulated seconds) then the keys pressed then
    5.0 m space
    9.0 m q            # the script ends with q

A problem is one line naming the file, the line number, the field and the value
(``keys.txt:3: keys[1]: must be one of w, a, s, d, ..., got 'jump'``); the script's length is
limited (:data:`MAX_SCRIPT_SECONDS` of simulated time, :data:`MAX_KEYS` keys), with the limit
in the message."""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Annotated, Any

from pydantic import BeforeValidator, Field, field_validator

from kiseki._support.inputs import MIB, check_input, read_input_text
from kiseki._support.numbers_text import parse_float
from kiseki._support.schema import FileModel, parse

__all__ = [
    "KEYS",
    "MAX_KEYS",
    "MAX_KEY_SCRIPT_BYTES",
    "MAX_SCRIPT_SECONDS",
    "KeyLine",
    "read_key_script",
]

KEYS = ("w", "a", "s", "d", "up", "down", "left", "right", "space", "m", "q")
MAX_SCRIPT_SECONDS = 3600.0  # an hour of teaching at 10 Hz: 36,000 steps, each rendered and logged
MAX_KEYS = 100_000
MAX_KEY_SCRIPT_BYTES = 16 * MIB  # MAX_KEYS lines of a time, keys and a comment fit in far less


def _seconds(text: Any) -> Any:
    """A time as written in the script (``5``, ``0.5``, ``1e1``) as a number."""
    if isinstance(text, str):
        try:
            text = parse_float(text.strip())  # 1_0 is not 10
        except ValueError:
            raise ValueError("must be a number of seconds (a line is TIME KEY [KEY ...])") from None
        if not math.isfinite(text):
            raise ValueError("must be a finite number of seconds")
    return text


def _key(name: Any) -> Any:
    if isinstance(name, str) and name.lower() in KEYS:
        return name.lower()  # W and UP are w and up
    raise ValueError(f"must be one of {', '.join(KEYS)}")


Seconds = Annotated[
    float,
    BeforeValidator(_seconds),
    Field(strict=True, ge=0, le=MAX_SCRIPT_SECONDS, allow_inf_nan=False),
]


class KeyLine(FileModel):
    """One line of a key script: the simulated time (s) and the keys pressed then."""

    time: Seconds
    keys: Annotated[list[Annotated[str, BeforeValidator(_key)]], Field(max_length=MAX_KEYS)]

    @field_validator("keys", mode="before")
    @classmethod
    def _some(cls, keys: Any) -> Any:
        if isinstance(keys, list) and not keys:
            raise ValueError("a line is TIME KEY [KEY ...]: no key after the time")
        return keys


def read_key_script(path: str | os.PathLike) -> list[tuple[float, str]]:
    """The (time, key) events of the key script at `path`, in order: FileNotFoundError when
    there is none, ValueError naming the file (and the line, the field and the value)."""
    path = Path(path)
    check_input(path)
    if path.is_dir():  # it read 'not found' of a folder that is there
        raise IsADirectoryError(f"{path}: a folder, not a key script")
    if not path.is_file():
        raise FileNotFoundError(f"{path}: key script not found")
    try:
        text = read_input_text(path, "key scripts", MAX_KEY_SCRIPT_BYTES)
    except UnicodeDecodeError:
        raise ValueError(f"{path}: not a key script (not UTF-8 text)") from None
    events: list[tuple[float, str]] = []
    for number, line in enumerate(text.splitlines(), 1):
        fields = line.split("#", 1)[0].split()
        if not fields:
            continue
        row = parse(KeyLine, {"time": fields[0], "keys": fields[1:]}, f"{path}:{number}")
        if events and row.time < events[-1][0]:
            raise ValueError(
                f"{path}:{number}: time: must not decrease (the line before is at "
                f"{events[-1][0]:g} s), got {row.time:g}"
            )
        if len(events) + len(row.keys) > MAX_KEYS:
            raise ValueError(f"{path}:{number}: a key script holds at most {MAX_KEYS:,} keys")
        events += [(row.time, key) for key in row.keys]
    if not events or events[-1][1] != "q":
        raise ValueError(f"{path}: a key script must end with q (finish)")
    return events
