# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What the output guard's tests (tests/python/cli/test_output_guard*.py) share: a command
run as a user runs it (``python -m kiseki.cli``), the SHA-256 of every file of a folder before
and after, the one error line of a refused command, and the guard a command carries
(kiseki._support.guard)."""

from __future__ import annotations

import hashlib
import subprocess
import sys
from pathlib import Path

CLI = [sys.executable, "-m", "kiseki.cli"]


def run(*args, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([*CLI, *map(str, args)], capture_output=True, text=True, cwd=cwd)


def sha256s(root: Path) -> dict[str, str]:
    """SHA-256 of every file below ``root`` (symlinks followed), by relative name."""
    return {
        p.relative_to(root).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(root.rglob("*"))
        if p.is_file()
    }


def refused(done: subprocess.CompletedProcess, *needles: str) -> str:
    """The one error line of a refused command, holding every needle."""
    assert done.returncode == 1, done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("kiseki: error: "), done.stderr
    for needle in needles:
        assert needle in lines[0], lines[0]
    return lines[0]


def _spec(function):
    from kiseki._support.guard import guard_of

    spec = guard_of(function)
    assert spec is not None
    return spec
