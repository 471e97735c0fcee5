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
import re
import shutil
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

from kiseki import load_map, save_map

ROOT = Path(__file__).resolve().parents[3]
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


TIMEOUT = 600  # s, for any one command: a hang fails the test instead of holding up the suite
# a tqdm update; spaces after it blank out the rest of a longer update before it
PROGRESS = r"[\w-]+: +(\d+%\|.*\| )?\d+(/\d+)? ?(step|trial)?s? ?\[.*\] *"


def _namespace_refusal() -> str | None:
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
    line = steps.one_line_error("full", f"{steps.disk / 'm.pgm'}: no space left on device")
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


CHUNK = 128 * 1024  # kiseki.io.runlog.DEFAULT_CHUNK_SIZE: the most a kill or full disk loses


@pytest.fixture(scope="module")
def scene(tmp_path_factory) -> Path:
    """The factory corridor with a route of 5 m instead of 13 m (about 110 steps)."""
    text = (ROOT / "data" / "worlds" / "factory_corridor.yaml").read_text()
    route = "waypoints: [[0.0, 0.0], [7.4, 0.0], [13.0, 0.0]]"
    assert route in text
    path = tmp_path_factory.mktemp("scene") / "short_corridor.yaml"
    path.write_text(text.replace(route, "waypoints: [[0.0, 0.0], [2.5, 0.0], [5.0, 0.0]]"))
    return path


@pytest.fixture(scope="module")
def taught(tmp_path_factory, scene) -> dict:
    """An uninterrupted teaching run with seed 0 (the CLI runs compared with it pass --seed 0):
    its folder, marks, poses."""
    from kiseki.apps.teach import teach
    from kiseki.io.runlog import read_run
    from kiseki.sim.scene import load_scene

    result = teach(load_scene(scene), tmp_path_factory.mktemp("taught") / "t", seed=0)
    assert [m["name"] for m in result.marks] == ["P0", "P1", "P2"]
    poses = read_run(result.log).poses("/ground_truth")[1]
    return {
        "folder": result.log.parent,
        "marks": result.marks,
        "poses": poses,
        "steps": result.steps,
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


def test_a_full_disk_while_teaching_keeps_the_steps_taught(tmp_path, namespace, scene, taught):
    steps = Steps(
        tmp_path,
        f"""
        run teach $KISEKI teach {scene} -o "$DISK/t" --seed 0
        snap full
        mount -o remount,size=64m "$DISK"
        run resume $KISEKI teach {scene} -o "$DISK/t" --resume
        snap resumed
        """,
        "1m",
    )
    steps.one_line_error("teach", f"{steps.disk}/t/teach.mcap: no space left", "--resume")
    full = digests(steps.out / "full")
    assert list(full) == ["t/teach.mcap"]  # no map, no temporary file
    assert steps.rc("resume") == 0, steps.err("resume")
    resumed = steps.out / "resumed" / "t"
    assert digests(resumed)["teach.mcap"] == full["t/teach.mcap"]  # --resume only reads it
    n = check_taught_prefix(resumed, steps.stdout("resume"), taught)
    assert 0 < n < taught["steps"]


def test_a_full_disk_while_rebuilding_a_taught_run_keeps_it(tmp_path, namespace, scene, taught):
    # --resume --merge evidence rebuilds other maps; with a seeded number of pages free (less
    # than the 20 its six files take together: one map's image takes 8) it fails part-way and
    # must leave the run as it was
    frees = np.random.default_rng(2).choice(20, 2, replace=False)
    steps = Steps(
        tmp_path,
        f"""
        cp -a {taught["folder"]} "$DISK/t"
        for free in {" ".join(map(str, frees))}; do
            rm -f "$DISK/filler"
            fill
            free $free
            run resume$free $KISEKI teach {scene} -o "$DISK/t" --resume --merge evidence
        done
        snap after
        """,
        "8m",
    )
    for free in frees:
        steps.one_line_error(f"resume{free}", f"{steps.disk}/t/", "no space left on device")
    assert digests(steps.out / "after" / "t") == digests(taught["folder"])


def test_kill_9_while_teaching_keeps_the_steps_taught(tmp_path, scene, taught):
    # killed once the log has grown to a seeded share of the uninterrupted run's log
    size = (taught["folder"] / "teach.mcap").stat().st_size
    share = np.random.default_rng(11).uniform(0.1, 0.8)
    cli = [*KISEKI.split(), "teach", str(scene), "-o", str(tmp_path / "t"), "--seed", "0"]
    proc = subprocess.Popen(cli, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    log = tmp_path / "t" / "teach.mcap"
    deadline = time.monotonic() + 120
    while proc.poll() is None and time.monotonic() < deadline:
        if log.exists() and log.stat().st_size >= share * size:
            break
        time.sleep(0.01)
    assert proc.poll() is None, "the teaching run ended before the kill point"
    proc.kill()
    assert proc.wait() == -signal.SIGKILL  # killed mid-run, not finished
    killed = digests(tmp_path / "t")
    assert list(killed) == ["teach.mcap"]
    # --resume takes the seed the log records (--seed does not apply with it)
    resume = [*cli[: cli.index("--seed")], "--resume"]
    done = subprocess.run(resume, capture_output=True, text=True, timeout=TIMEOUT)
    assert done.returncode == 0, done.stderr
    assert digests(tmp_path / "t")["teach.mcap"] == killed["teach.mcap"]
    n = check_taught_prefix(tmp_path / "t", done.stdout, taught)
    assert n * size / taught["steps"] >= share * size - 2 * CHUNK


SWEEP = ["corridor-scans", "--runs", "4", "--seed", "3"]


@pytest.fixture(scope="module")
def swept(tmp_path_factory) -> Path:
    """An uninterrupted experiment sweep (about 0.4 s a trial)."""
    out = tmp_path_factory.mktemp("swept") / "e"
    done = subprocess.run(
        [*KISEKI.split(), "experiment", "run", *SWEEP, "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=TIMEOUT,
    )
    assert done.returncode == 0, done.stderr
    return out


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


def test_kill_9_in_an_experiment_sweep_keeps_the_finished_trials(tmp_path, swept):
    # killed a seeded share of a trial after a seeded number of trials has finished
    rng = np.random.default_rng(23)
    after, share = int(rng.integers(1, 4)), rng.uniform(0.0, 1.0)
    import pandas as pd

    per_trial = pd.read_parquet(swept / "timings.parquet")["trial_seconds"].mean()
    cli = [*KISEKI.split(), "experiment", "run"]
    proc = subprocess.Popen(
        [*cli, *SWEEP, "--out", str(tmp_path / "e")],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    log = tmp_path / "e" / "trials.jsonl"
    deadline = time.monotonic() + 120
    while proc.poll() is None and time.monotonic() < deadline:
        if log.exists() and log.read_bytes().count(b"\n") >= after:
            time.sleep(share * per_trial)
            break
        time.sleep(0.005)
    assert proc.poll() is None, "the sweep ended before the kill point"
    proc.kill()
    assert proc.wait() == -signal.SIGKILL
    kept = log.read_bytes()
    finished = kept.count(b"\n")
    assert after <= finished <= 4
    resumed = subprocess.run(
        [*cli, "corridor-scans", "--resume", "--out", str(tmp_path / "e")],
        capture_output=True,
        text=True,
        timeout=TIMEOUT,
    )
    assert resumed.returncode == 0, resumed.stderr
    assert f"({4 - finished} run now" in " ".join(resumed.stdout.split())  # rich wraps at 80
    assert log.read_bytes().startswith(kept)  # the finished trials kept as they were
    same_results(tmp_path / "e", swept)


def test_a_full_disk_in_an_experiment_keeps_trials_and_results(tmp_path, namespace, swept):
    # two pages free: the config and the trial log fit, the results do not; then, with the
    # results written, a full disk while writing them again must leave them as they were
    run = '$KISEKI experiment run corridor-scans --resume --out "$DISK/e"'
    steps = Steps(
        tmp_path,
        f"""
        fill
        free 2
        run full $KISEKI experiment run {" ".join(SWEEP)} --out "$DISK/e"
        snap full
        rm "$DISK/filler"
        run resume {run}
        snap done
        fill
        run again {run}
        snap again
        """,
        "1m",
    )
    line = steps.one_line_error("full", f"{steps.disk}/e", "No space left on device", "--resume")
    assert "/." not in line  # no temporary name
    full = digests(steps.out / "full")
    assert sorted(full) == ["e/config.yaml", "e/trials.jsonl"]  # nothing half-written
    assert (steps.out / "full" / "e" / "trials.jsonl").read_bytes().count(b"\n") == 4
    assert steps.rc("resume") == 0, steps.err("resume")
    assert "(0 run now" in " ".join(steps.stdout("resume").split())
    same_results(steps.out / "done" / "e", swept)
    steps.one_line_error("again", f"{steps.disk}/e", "No space left on device")
    assert digests(steps.out / "again") == digests(steps.out / "done")


def test_a_read_only_results_folder_is_refused_before_any_work(
    tmp_path, namespace, scene, taught, swept
):
    # a read-only filesystem (root ignores a folder's mode bits, not a read-only mount) holding
    # a finished experiment run and a taught run, and an empty folder for new results
    steps = Steps(
        tmp_path,
        f"""
        cp -a {taught["folder"]} "$DISK/t"
        cp -a {swept} "$DISK/e"
        mkdir "$DISK/empty"
        snap before
        mount -o remount,ro "$DISK"
        run new $KISEKI experiment run {" ".join(SWEEP)} --out "$DISK/empty/e"
        run resume $KISEKI experiment run corridor-scans --resume --out "$DISK/e"
        cd "$DISK/empty"
        run default $KISEKI experiment run {" ".join(SWEEP)}
        cd -
        run teach $KISEKI teach {scene} -o "$DISK/empty/t"
        run reteach $KISEKI teach {scene} -o "$DISK/t" --resume
        run map $KISEKI map convert {MAP} -o "$DISK/empty/m.yaml"
        snap after
        """,
        "16m",
    )
    for name in ("new", "resume", "default", "teach", "reteach", "map"):
        line = steps.one_line_error(name, "not writable")
        assert str(steps.disk) in line, line
        # refused before the work: no progress bar was drawn
        assert steps.err(name).strip() == line, steps.err(name)
    assert digests(steps.out / "after") == digests(steps.out / "before")
