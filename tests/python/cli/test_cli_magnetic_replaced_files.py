# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``kiseki magnetic fit`` and ``walk`` keep a user's files in their -o folder: fit replaces its
map folder whole, so a map folder holding anything else is refused (fit swapped it out with the
user's notes.txt and sub-folder, exit 0); walk replaced an existing trajectory.csv without a word,
and now does so only with --overwrite. Each refusal is one line naming the folder and the file,
exit 1, before any work. (navigate: tests/python/cli/test_cli_magnetic_navigate.py.)"""

from __future__ import annotations

import hashlib
import subprocess
from pathlib import Path

import yaml

from _helpers.boundaries_cli import run as run_cli
from _helpers.synthetic_walk import write_walk

# four readings and a given kernel: a fit in milliseconds (nothing to search)
POINTS = "x,y,mx,my,mz\n0,0,1,2,3\n1,0,1,2,4\n0,1,1,3,3\n1,1,2,2,3\n"
CURL_FREE = ("--kernel", "6,0.4,27,1.5")
INDEPENDENT = ("--model", "independent", "--kernel", "3,1,0.1")


def run(*args, cwd=None) -> subprocess.CompletedProcess:
    """The CLI in a process of its own: exit status and stderr as a user sees them."""
    return run_cli("magnetic", *args, cwd=Path.cwd() if cwd is None else cwd)


def invoke(*args):
    """The same command in this process: (exit code, output, exception)."""
    from typer.testing import CliRunner

    from kiseki.cli import app

    done = CliRunner().invoke(app, ["magnetic", *map(str, args)])
    return done.exit_code, done.output, done.exception


def contents(folder: Path) -> dict[str, str]:
    """Every file under ``folder`` (relative name: SHA-256)."""
    return {
        p.relative_to(folder).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


def test_fit_refuses_a_map_folder_holding_a_users_files_and_replaces_its_own(tmp_path):
    (tmp_path / "d.csv").write_text(POINTS)
    assert invoke("fit", tmp_path / "d.csv", "-o", tmp_path / "fitmap", *CURL_FREE)[0] == 0
    fitmap = tmp_path / "fitmap"
    own = sorted(p.name for p in fitmap.iterdir())
    assert "predictor.npz" in own  # the curl-free map's
    (fitmap / "notes.txt").write_text("my notes\n")
    (fitmap / "sub").mkdir()
    (fitmap / "sub" / "f").write_text("mine\n")
    before = contents(fitmap)
    done = run("fit", "d.csv", "-o", "fitmap", *CURL_FREE, cwd=tmp_path)
    assert done.returncode == 1
    assert done.stderr.splitlines() == [
        "kiseki: error: -o fitmap holds notes.txt (and 1 more), which is not part of a magnetic "
        "field map: the map folder is replaced whole; move them out, or give a new folder"
    ]
    assert contents(fitmap) == before
    assert (fitmap / "notes.txt").read_text() == "my notes\n"
    assert (fitmap / "sub" / "f").read_text() == "mine\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d.csv", "fitmap"]  # no temporary
    (fitmap / "notes.txt").unlink()
    code, _, error = invoke("fit", tmp_path / "d.csv", "-o", fitmap, *CURL_FREE)
    assert (code, str(error)) == (
        1,
        f"-o {fitmap} holds sub, which is not part of a magnetic field map: the map folder is "
        "replaced whole; move it out, or give a new folder",
    )
    assert contents(fitmap) == {k: v for k, v in before.items() if k != "notes.txt"}
    # its own earlier map, nothing else: replaced whole (another model: predictor.npz goes)
    (fitmap / "sub" / "f").unlink()
    (fitmap / "sub").rmdir()
    code, output, error = invoke("fit", tmp_path / "d.csv", "-o", fitmap, *INDEPENDENT)
    assert code == 0, (output, error)
    assert sorted(p.name for p in fitmap.iterdir()) == sorted(set(own) - {"predictor.npz"})
    doc = yaml.safe_load((fitmap / "magnetic_map.yaml").read_text())
    assert doc["provenance"]["fit"]["model"] == "independent"


def test_walk_refuses_an_existing_trajectory_unless_told_to_overwrite(tmp_path):
    write_walk(tmp_path / "loop.mat", laps=2.0)  # one lap localized: about a second
    out = tmp_path / "F"
    out.mkdir()
    (out / "trajectory.csv").write_text("my trajectory\n")
    (out / "notes.txt").write_text("my notes\n")
    done = run("walk", "loop.mat", "-o", "F", "--filter", "thesis", cwd=tmp_path)
    assert done.returncode == 1
    assert done.stderr.splitlines() == [
        "kiseki: error: -o F holds trajectory.csv, which this command would replace: give "
        "--overwrite, or another folder"
    ]
    assert (out / "trajectory.csv").read_text() == "my trajectory\n"
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt", "trajectory.csv"]
    code, output, error = invoke(
        "walk", tmp_path / "loop.mat", "-o", out, "--filter", "thesis", "--overwrite"
    )
    assert code == 0, (output, error)
    assert (out / "trajectory.csv").read_text().startswith("t,s_true,s_est,s_odom\n")
    assert (out / "notes.txt").read_text() == "my notes\n"  # not an output: kept
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt", "trajectory.csv"]
