# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What the failure-injection tests (tests/python/boundaries/test_full_disk.py, test_kill_9.py,
test_read_only.py) share: shell steps run in a user + mount namespace with a small tmpfs, a
folder's digests, the one error line of a refused command, and the checks that a resumed
teaching run or experiment equals an uninterrupted one."""

from __future__ import annotations

import hashlib
import re
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[3]
KISEKI = f"{sys.executable} -m kiseki.cli"
MAP = ROOT / "data" / "maps" / "factory_corridor.yaml"
CHUNK = 128 * 1024  # kiseki.io.runlog.DEFAULT_CHUNK_SIZE: the most a kill or full disk loses
SWEEP = ["corridor-scans", "--runs", "4", "--seed", "3"]  # an experiment sweep, 0.4 s a trial

# shell functions for the steps run inside the namespace: `run NAME CMD...` keeps CMD's exit
# status, stdout and stderr in $OUT/NAME.{rc,out,err}; `fill` fills the disk, `free N` gives N
# pages back; `snap NAME` copies the disk (without the filler) to $OUT/NAME
PRELUDE = """
mount -t tmpfs -o size=$SIZE tmpfs "$DISK"
PAGE=$(getconf PAGESIZE)
run() {
  name=$1; shift; set +e
  "$@" >"$OUT/$name.out" 2>"$OUT/$name.err"; echo $? >"$OUT/$name.rc"; set -e
}
fill() { head -c 1G /dev/zero >"$DISK/filler" 2>/dev/null || true; }
free() { truncate -s -$(( $1 * PAGE )) "$DISK/filler"; }
snap() { mkdir "$OUT/$1"; tar -C "$DISK" --exclude=./filler -cf - . | tar -C "$OUT/$1" -xf -; }
"""


TIMEOUT = 600  # s, for any one command: a hang fails the test instead of holding up the suite
# a tqdm update; spaces after it blank out the rest of a longer update before it
PROGRESS = r"[\w-]+: +(\d+%\|.*\| )?\d+(/\d+)? ?(step|trial)?s? ?\[.*\] *"


def namespace_refusal() -> str | None:
    if shutil.which("unshare") is None:
        return "unshare (util-linux) is not installed"
    # the probe mounts a tmpfs, as the tests do: some hosts allow the namespaces but not mounts
    probe = subprocess.run(
        ["unshare", "--user", "--map-root-user", "--mount", "mount", "-t", "tmpfs", "-o",
         "size=64k", "tmpfs", "/mnt"],
        capture_output=True,
        text=True,
        timeout=60,
    )  # fmt: skip
    if probe.returncode != 0:
        return f"user + mount namespaces are not permitted here: {probe.stderr.strip()}"
    return None


class Steps:
    """The outputs of shell steps run in a namespace with a `size` tmpfs at $DISK."""

    def __init__(self, tmp_path: Path, script: str, size: str) -> None:
        self.out = tmp_path / "out"
        self.out.mkdir()
        disk = tmp_path / "disk"
        disk.mkdir()
        (tmp_path / "steps.sh").write_text(PRELUDE + textwrap.dedent(script))
        env = {"PATH": "/usr/bin:/bin", "SIZE": size, "DISK": str(disk), "OUT": str(self.out)}
        env |= {"KISEKI": KISEKI, "PY": sys.executable, "HOME": str(tmp_path)}
        done = subprocess.run(
            ["unshare", "--user", "--map-root-user", "--mount", "sh", "-eu", tmp_path / "steps.sh"],
            env=env,
            cwd=ROOT,
            capture_output=True,
            text=True,
            timeout=TIMEOUT,
        )
        assert done.returncode == 0, done.stderr
        self.disk = disk

    def rc(self, name: str) -> int:
        return int((self.out / f"{name}.rc").read_text())

    def err(self, name: str) -> str:
        return (self.out / f"{name}.err").read_bytes().decode()  # keeps the \r of a bar

    def stdout(self, name: str) -> str:
        return (self.out / f"{name}.out").read_text()

    def one_line_error(self, name: str, *needles: str) -> str:
        """The step failed with exit status 1 and one line (no traceback) naming `needles`;
        besides it, stderr holds only a progress bar's carriage-return updates."""
        err = self.err(name)
        assert self.rc(name) == 1, err
        lines = re.findall(r"kiseki: error: [^\r\n]*", err)
        assert len(lines) == 1 and "Traceback" not in err, err
        rest = re.split(r"[\r\n]+", err.replace(lines[0], ""))
        assert all(re.fullmatch(PROGRESS, part) for part in rest if part), err
        for needle in needles:
            assert needle in lines[0], lines[0]
        return lines[0]


def digests(folder: Path) -> dict[str, str]:
    """Relative path -> SHA-256 of every file under a folder (hidden ones too)."""
    return {
        str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


def check_taught_prefix(folder: Path, stdout: str, taught: dict) -> int:
    """A folder rebuilt from a cut teaching log holds the uninterrupted run's first steps: its
    logged poses and its waypoints exactly; returns the number of steps."""
    import warnings

    import yaml

    from kiseki.io.runlog import TruncatedRunWarning, read_run

    steps = int(re.search(r"(\d+) steps", " ".join(stdout.split())).group(1))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TruncatedRunWarning)
        poses = read_run(folder / "teach.mcap").poses("/ground_truth")[1]
    assert steps <= len(poses) <= steps + 1  # a step's pose is logged before its images
    np.testing.assert_array_equal(poses, taught["poses"][: len(poses)])
    marks = yaml.safe_load((folder / "waypoints.yaml").read_text())["waypoints"]
    assert marks == taught["marks"][: len(marks)]
    # no more than the chunk being written is lost
    per_step = (taught["folder"] / "teach.mcap").stat().st_size / taught["steps"]
    assert steps * per_step >= (folder / "teach.mcap").stat().st_size - 2 * CHUNK
    return steps


def same_results(run: Path, reference: Path) -> None:
    import pandas as pd

    for name in ("trials.parquet", "claims.csv"):
        assert (run / name).read_bytes() == (reference / name).read_bytes(), name
    assert not [p.name for p in run.rglob(".*")]  # no temporary file or folder
    assert sorted(p.name for p in (run / "figures").iterdir()) == ["precision_vs_offset.png"]
    pd.testing.assert_frame_equal(
        pd.read_csv(run / "tables" / "summary.csv"),
        pd.read_csv(reference / "tables" / "summary.csv"),
    )
