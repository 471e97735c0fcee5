# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Figure outputs are checked before the work: an unknown extension, and a .pgf figure on a
machine without the LaTeX engine matplotlib's pgf backend runs (it failed after the work)."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from matplotlib import rcParams

from kiseki._support.outputs import FIGURE_SUFFIXES, check_suffix


def test_pgf_is_refused_up_front_when_its_latex_engine_is_missing(monkeypatch):
    monkeypatch.setattr(shutil, "which", lambda name: None)
    with pytest.raises(ValueError, match=r"--plot p\.pgf: a \.pgf figure needs \w+latex"):
        check_suffix("--plot", Path("p.pgf"), FIGURE_SUFFIXES)
    check_suffix("--plot", Path("p.pdf"), FIGURE_SUFFIXES)  # no engine needed


def test_pgf_is_accepted_when_the_engine_is_there(monkeypatch):
    monkeypatch.setattr(shutil, "which", lambda name: f"/usr/bin/{name}")
    check_suffix("--plot", Path("p.pgf"), FIGURE_SUFFIXES)


@pytest.mark.skipif(
    shutil.which(rcParams["pgf.texsystem"]) is not None, reason="a LaTeX engine is installed"
)
def test_the_cli_refuses_a_pgf_render_before_reading_the_map(tmp_path, project_root):
    done = subprocess.run(
        [sys.executable, "-m", "kiseki.cli", "map", "render",
         str(project_root / "data" / "maps" / "factory_corridor.yaml"), "-o", "m.pgf"],
        cwd=tmp_path, capture_output=True, text=True,
    )  # fmt: skip
    assert done.returncode == 1 and "needs" in done.stderr and "latex" in done.stderr
    assert not list(tmp_path.iterdir())
