# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Write-then-rename (kiseki._support.atomic): every temporary file is synced before any rename and
the folder after them, the renames go in the order given, stale temporary files of a killed
writer are removed (nothing else), and a reworded error keeps its type and errno."""

from __future__ import annotations

import errno
import os
import time
from pathlib import Path

import numpy as np
import pytest

from kiseki import OccupancyGrid, save_map
from kiseki._support.atomic import STALE_SECONDS, atomic_write, atomic_write_all, reworded


def _text(content: str):
    return lambda tmp: Path(tmp).write_text(content, encoding="utf-8")


def test_each_temporary_file_is_synced_before_the_renames_and_the_folder_after(
    tmp_path, monkeypatch
):
    events: list[tuple[str, int]] = []
    real_fsync, real_replace = os.fsync, os.replace

    def fsync(fd):
        events.append(("fsync", os.fstat(fd).st_ino))
        return real_fsync(fd)

    def replace(src, dst):
        events.append(("replace", os.stat(src).st_ino))
        return real_replace(src, dst)

    monkeypatch.setattr(os, "fsync", fsync)
    monkeypatch.setattr(os, "replace", replace)
    grid = OccupancyGrid(np.full((4, 5), 100, np.int8), resolution=0.5)
    save_map(grid, tmp_path / "m.yaml")
    monkeypatch.undo()

    image, yaml_file = (tmp_path / "m.pgm").stat().st_ino, (tmp_path / "m.yaml").stat().st_ino
    folder = tmp_path.stat().st_ino
    renames = [ino for kind, ino in events if kind == "replace"]
    assert renames == [image, yaml_file]  # the image first: no YAML without its image
    first_rename = events.index(("replace", image))
    synced_before = {ino for kind, ino in events[:first_rename] if kind == "fsync"}
    assert {image, yaml_file} <= synced_before
    assert ("fsync", folder) in events[events.index(("replace", yaml_file)) :]


def test_stale_temporaries_of_the_target_are_removed_and_nothing_else(tmp_path):
    target = tmp_path / "waypoints.yaml"
    old = time.time() - 2 * STALE_SECONDS
    stale = tmp_path / ".waypoints.k2_x9abc.yaml"  # as mkstemp names them: 8 characters
    recent = tmp_path / ".waypoints.q7rt0zz1.yaml"  # maybe a live writer's: kept
    keep = {
        tmp_path / ".foo": None,  # unrelated hidden files
        tmp_path / ".waypoints.toolong99.yaml": old,  # 9 characters: not mkstemp's
        tmp_path / ".waypoints.abcdefgh.yml": old,  # another suffix
        tmp_path / ".other.abcdefgh.yaml": old,  # another target's
        tmp_path / "waypoints.abcdefgh.yaml": old,  # not hidden
    }
    for path in [stale, recent, *keep]:
        path.write_text("partial", encoding="utf-8")
    os.utime(stale, (old, old))
    for path, mtime in keep.items():
        if mtime is not None:
            os.utime(path, (mtime, mtime))

    atomic_write(target, _text("waypoints: []\n"))

    assert target.read_text(encoding="utf-8") == "waypoints: []\n"
    assert not stale.exists()
    assert recent.exists() and all(path.exists() for path in keep)
    left = sorted(p.name for p in tmp_path.iterdir())
    assert left == sorted([target.name, recent.name, *(p.name for p in keep)])


def test_a_failed_write_says_a_previous_file_is_kept_only_when_there_is_one(tmp_path):
    def full(tmp):
        raise OSError(errno.ENOSPC, "No space left on device")

    target = tmp_path / "map.yaml"
    with pytest.raises(OSError) as new:
        atomic_write(target, full)
    assert str(new.value) == f"{target}: no space left on device; not written"
    assert new.value.errno == errno.ENOSPC
    target.write_text("old", encoding="utf-8")
    with pytest.raises(OSError) as kept:
        atomic_write_all([(tmp_path / "a.txt", _text("a")), (target, full)])
    assert str(kept.value).endswith("; not written (a previous one is kept)")
    assert target.read_text(encoding="utf-8") == "old" and not (tmp_path / "a.txt").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["map.yaml"]


def test_reworded_keeps_the_type_and_errno():
    missing = reworded(FileNotFoundError(errno.ENOENT, "No such file", "x.csv"), "x.csv: gone")
    assert type(missing) is FileNotFoundError and missing.errno == errno.ENOENT
    assert str(missing) == "x.csv: gone"

    class PickyError(OSError):
        def __init__(self, a, b, c):
            super().__init__(a, b)

    odd = reworded(PickyError(errno.EIO, "I/O", None), "it broke")
    assert type(odd) is OSError and odd.errno == errno.EIO and str(odd) == "it broke"
    with pytest.raises(TypeError, match="ValueError"):
        reworded(ValueError("no"), "x")
