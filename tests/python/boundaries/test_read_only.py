# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""A read-only results folder: every command that would write there is refused before any
work, with one line naming the folder, and leaves what the folder holds as it was."""

from __future__ import annotations

from _helpers.injection import MAP, SWEEP, Steps, digests


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
