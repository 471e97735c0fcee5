# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""OpenCV's image codecs (GDAL and about 140 more libraries on Debian) are loaded by the first
image read or written, not by `import kiseki`."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
CODECS = "libopencv_imgcodecs"

PROBE = f"""
import sys
def loaded():
    with open("/proc/self/maps") as f:
        return any("{CODECS}" in line for line in f)
import kiseki
print(loaded())
from kiseki.io.ros_map import load_map, save_map
print(loaded())
grid = load_map(sys.argv[1])
print(loaded(), grid.width, grid.height)
"""


@pytest.mark.skipif(not Path("/proc/self/maps").exists(), reason="needs Linux's /proc")
def test_import_loads_no_codecs_and_reading_a_map_does():
    done = subprocess.run(
        [sys.executable, "-c", PROBE, str(ROOT / "data" / "maps" / "factory_corridor.yaml")],
        capture_output=True,
        text=True,
        check=True,
    )
    after_import, after_io_import, after_read = done.stdout.splitlines()
    assert after_import == "False" and after_io_import == "False"
    loaded, width, height = after_read.split()
    assert loaded == "True"
    header = (ROOT / "data" / "maps" / "factory_corridor.pgm").read_bytes()[:64].split()
    assert (int(width), int(height)) == (int(header[1]), int(header[2]))  # the PGM's own size
