# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Failure injection: a full disk (a small tmpfs mounted in a user + mount namespace) while
saving a map, teaching and running an experiment; kill -9 at seeded random points of a teaching
run and of an experiment sweep; a read-only results folder. Nothing taught or finished may be
lost, and no command may leave a temporary file or print a traceback."""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from kiseki import load_map, save_map

ROOT = Path(__file__).resolve().parents[2]
KISEKI = f"{sys.executable} -m kiseki.cli"
MAP = ROOT / "data" / "maps" / "factory_corridor.yaml"

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


def _namespace_refusal() -> str | None:
    if shutil.which("unshare") is None:
        return "unshare (util-linux) is not installed"
    probe = subprocess.run(
        ["unshare", "--user", "--map-root-user", "--mount", "true"], capture_output=True, text=True
    )
    if probe.returncode != 0:
        return f"user + mount namespaces are not permitted here: {probe.stderr.strip()}"
    return None


@pytest.fixture(scope="module")
def namespace() -> None:
    reason = _namespace_refusal()
    if reason is not None:
        pytest.skip(f"a small tmpfs needs a user + mount namespace: {reason}")


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
        )
        assert done.returncode == 0, done.stderr
        self.disk = disk

    def rc(self, name: str) -> int:
        return int((self.out / f"{name}.rc").read_text())

    def err(self, name: str) -> str:
        return (self.out / f"{name}.err").read_text()

    def stdout(self, name: str) -> str:
        return (self.out / f"{name}.out").read_text()

    def one_line_error(self, name: str, *needles: str) -> str:
        """The step failed with exit status 1 and one line (no traceback) naming `needles`."""
        err = self.err(name)
        assert self.rc(name) == 1, err
        lines = err.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("kiseki: error: "), err
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


# save_map over a saved map (m) and to a new name (n) with `free` pages left, for each
# `free` in argv; prints what each left on the disk
SAVE_SWEEP = """
import json, os, sys
from pathlib import Path
from kiseki import load_map, save_map

disk, old, new = Path(sys.argv[1]), load_map(sys.argv[2]), load_map(sys.argv[3])
page, results = os.sysconf("SC_PAGE_SIZE"), []
for free in map(int, sys.argv[4:]):
    for p in disk.iterdir():
        p.unlink()
    save_map(old, disk / "m.yaml")
    with open(disk / "filler", "wb", buffering=0) as f:
        try:
            while True:
                f.write(bytes(page))
        except OSError:
            pass
    os.truncate(disk / "filler", os.path.getsize(disk / "filler") - free * page)
    errors = []
    for name in ("m", "n"):
        try:
            save_map(new, disk / f"{name}.yaml")
            errors.append(None)
        except OSError as err:
            errors.append(str(err))
    files = {p.name: p.read_bytes().hex() for p in disk.iterdir() if p.name != "filler"}
    results.append({"free": free, "errors": errors, "files": files})
print(json.dumps(results))
"""


def test_a_full_disk_while_saving_a_map_keeps_the_saved_map(tmp_path, namespace):
    # another map in place of the saved one: a different size and content
    other = load_map(MAP)
    other.cells[:] = np.flipud(other.cells)
    bigger = np.full((other.height * 2, other.width), -1, np.int8)
    bigger[: other.height] = other.cells
    from kiseki.grid import OccupancyGrid

    save_map(OccupancyGrid(bigger, 0.05), tmp_path / "other.yaml")
    (tmp_path / "sweep.py").write_text(SAVE_SWEEP)
    (tmp_path / "old").mkdir()
    save_map(load_map(MAP), tmp_path / "old" / "m.yaml")
    save_map(load_map(tmp_path / "other.yaml"), tmp_path / "old" / "n.yaml")
    frees = " ".join(map(str, sorted(np.random.default_rng(3).choice(24, 8, replace=False))))
    steps = Steps(
        tmp_path,
        f"""
        run first $KISEKI map convert {MAP} -o "$DISK/m.yaml"
        snap before
        fill
        run full $KISEKI map convert {tmp_path / "other.yaml"} -o "$DISK/m.yaml"
        snap after
        rm "$DISK/filler" "$DISK"/m.*
        run sweep $PY {tmp_path / "sweep.py"} "$DISK" {MAP} {tmp_path / "other.yaml"} {frees}
        """,
        "256k",
    )
    assert steps.rc("first") == 0, steps.err("first")
    line = steps.one_line_error("full", str(steps.disk / "m.pgm"), "disk full")
    assert ".m." not in line  # the temporary file is not named
    before = digests(steps.out / "before")
    assert sorted(before) == ["m.pgm", "m.yaml"]
    assert digests(steps.out / "after") == before  # the saved map intact, no temporary file
    # save_map with a few seeded amounts of free space: the saved map m is its old self or the
    # new map, a new map n is whole or absent, never a temporary file; the new map (13 pages of
    # image, 1 of YAML) fits once both files fit together
    assert steps.rc("sweep") == 0, steps.err("sweep")
    old = {p.name: p.read_bytes() for p in (tmp_path / "old").iterdir()}
    new_m = {"m.yaml": old["n.yaml"].replace(b"n.pgm", b"m.pgm"), "m.pgm": old["n.pgm"]}
    page = os.sysconf("SC_PAGE_SIZE")
    need = -(-len(old["n.pgm"]) // page) + 1  # pages of the image and of the YAML
    results = json.loads(steps.stdout("sweep"))
    for r in results:
        files = {name: bytes.fromhex(data) for name, data in r["files"].items()}
        fits = r["free"] >= need
        assert (r["errors"][0] is None) == fits, r
        assert fits or f"{steps.disk}/m." in r["errors"][0]
        m = new_m if fits else {"m.yaml": old["m.yaml"], "m.pgm": old["m.pgm"]}
        n = {"n.yaml": old["n.yaml"], "n.pgm": old["n.pgm"]} if r["errors"][1] is None else {}
        assert files == m | n, r["free"]
    assert {r["errors"][0] is None for r in results} == {True, False}  # both outcomes drawn
