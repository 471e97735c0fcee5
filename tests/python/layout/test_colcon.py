# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""colcon sees the repository as a plain CMake package: build the C++ library, run its ctest."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest


def colcon(*args: str, cwd: Path) -> str:
    exe = Path(sys.executable).parent / "colcon"
    if not exe.exists():
        exe = shutil.which("colcon")
    if exe is None:
        pytest.fail("colcon is not installed (it is a test dependency of kiseki)")
    env = {**os.environ, "CMAKE_BUILD_PARALLEL_LEVEL": "2", "COLCON_HOME": str(cwd / ".colcon")}
    done = subprocess.run([str(exe), *args], cwd=cwd, env=env, capture_output=True, text=True)
    assert done.returncode == 0, f"colcon {' '.join(args)} failed:\n{done.stdout}\n{done.stderr}"
    return done.stdout


def test_colcon_build_and_test(tmp_path, project_root):
    ws = tmp_path / "ws"
    (ws / "src").mkdir(parents=True)
    (ws / "src" / "kiseki").symlink_to(project_root, target_is_directory=True)
    base = ["--base-paths", "src"]
    colcon("build", *base, "--cmake-args", "-DCMAKE_BUILD_TYPE=Release", "-GNinja", cwd=ws)
    assert (ws / "install" / "kiseki" / "lib" / "libkiseki_core.a").is_file()
    assert (ws / "install" / "kiseki" / "include" / "kiseki" / "grid" / "ray_casting.hpp").is_file()
    colcon("test", *base, cwd=ws)
    result = colcon("test-result", "--test-result-base", str(ws / "build"), "--all", cwd=ws)
    summary = re.search(r"Summary: (\d+) tests?, (\d+) errors?, (\d+) failures?", result)
    assert summary, result
    tests, errors, failures = map(int, summary.groups())
    assert tests >= 10 and errors == 0 and failures == 0, result
