# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Every example runs and says what the map implies."""

from __future__ import annotations

import re
import subprocess
import sys


def test_scan_in_corridor(project_root, tmp_path):
    out = tmp_path / "scan.png"
    done = subprocess.run(
        [sys.executable, str(project_root / "examples" / "scan_in_corridor.py"), str(out)],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr
    ahead, left, right = map(float, re.findall(r"([\d.]+) m", done.stdout))
    # P1 = (7.4, 0) in data/worlds/factory_corridor.yaml: the east wall's inner face is at
    # x = 14.9, the north and south walls' at y = +-1.5; nothing else stands on those lines
    assert abs(ahead - 7.5) < 0.03 and abs(left - 1.5) < 0.03 and abs(right - 1.5) < 0.03
    assert out.read_bytes()[:4] == b"\x89PNG"
