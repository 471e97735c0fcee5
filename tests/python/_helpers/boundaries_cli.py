# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What the command-line boundary tests (tests/python/cli/test_boundaries_*.py) share: a command
run as a user runs it (``python -m kiseki.cli``), the digests of a folder's files before and
after, and the one error line of a refused command."""

from __future__ import annotations

import hashlib
import subprocess
import sys
from pathlib import Path


def run(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "kiseki.cli", *map(str, args)],
        capture_output=True,
        text=True,
        cwd=cwd,
    )


def digests(folder: Path) -> dict[str, str]:
    return {
        p.name: hashlib.sha1(p.read_bytes()).hexdigest()
        for p in sorted(folder.iterdir())
        if p.is_file()
    }


def one_error(done: subprocess.CompletedProcess) -> str:
    assert done.returncode == 1, done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("kiseki: error: "), done.stderr
    return lines[0]
