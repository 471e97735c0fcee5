# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""A full disk (a small tmpfs mounted in a user + mount namespace) while saving a map, teaching,
rebuilding a taught run's maps and running an experiment: nothing saved, taught or finished may
be lost, no temporary file may be left, and the command fails with one line, no traceback."""

from __future__ import annotations

import json
import os

import numpy as np

from _helpers.injection import MAP, SWEEP, Steps, check_taught_prefix, digests, same_results
from kiseki import load_map, save_map

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
