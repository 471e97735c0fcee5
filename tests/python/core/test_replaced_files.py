# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""An output folder's entries that a command would replace: found by its declared patterns
(files, sub-folders, globs, links, names with glob characters), refused in one line naming the
folder and the first of them."""

from __future__ import annotations

import os

import pytest

from kiseki._support.replaced_files import existing_outputs, refuse_replacing

PATTERNS = ("config.yaml", "sdem_*.pcd", "tables/", "report.md")


def test_only_the_entries_the_command_writes_are_found_in_pattern_order(tmp_path):
    for name in ("notes.txt", "sdem_001.pcd", "sdem_000.pcd", "report.md", "config.yml"):
        (tmp_path / name).write_text("x")
    (tmp_path / "tables").mkdir()
    (tmp_path / "figures").mkdir()
    got = [p.relative_to(tmp_path).as_posix() for p in existing_outputs(tmp_path, PATTERNS)]
    assert got == ["sdem_000.pcd", "sdem_001.pcd", "tables", "report.md"]
    assert existing_outputs(tmp_path / "missing", PATTERNS) == []


def test_a_link_is_an_entry_even_when_broken(tmp_path):
    os.symlink(tmp_path / "nowhere", tmp_path / "config.yaml")
    os.symlink(tmp_path / "nowhere", tmp_path / "sdem_000.pcd")  # under a pattern too
    assert existing_outputs(tmp_path, PATTERNS) == [
        tmp_path / "config.yaml",
        tmp_path / "sdem_000.pcd",
    ]


def test_a_folder_whose_name_holds_glob_characters_is_searched_literally(tmp_path):
    odd = tmp_path / "run[1]"
    odd.mkdir()
    (odd / "report.md").write_text("x")
    (tmp_path / "run1").mkdir()  # what the unescaped pattern run[1] would match instead
    assert existing_outputs(odd, PATTERNS) == [odd / "report.md"]


def test_the_refusal_names_the_folder_the_first_file_and_how_many_more(tmp_path):
    (tmp_path / "config.yaml").write_text("mine")
    (tmp_path / "report.md").write_text("mine")
    with pytest.raises(FileExistsError) as caught:
        refuse_replacing(tmp_path, PATTERNS, "--out", "give a new or empty folder")
    assert str(caught.value) == (
        f"--out {tmp_path} holds config.yaml (and 1 more), which this command would replace: "
        "give a new or empty folder"
    )
    assert (tmp_path / "config.yaml").read_text() == "mine"
    refuse_replacing(tmp_path, ("trajectory.csv",), "--out", "unused")  # nothing to replace
