# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The command line as a package (kiseki.cli): the root lists its commands without importing
them, each command loads only its own module, old names are hidden aliases that warn once, the
help paragraphs reflow to the terminal's width, and the options' defaults are the config
types'."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
import typer
import typer.main
from typer.core import TyperGroup

from kiseki.apps.teach import PlaybackConfig
from kiseki.cli import ALIASES, COMMANDS, app
from kiseki.cli._help import reflow
from kiseki.cli._lazy import LazyGroup
from kiseki.filters import GlobalConfig, LocalizeConfig
from kiseki.mapping import MapBuildConfig
from kiseki.speed import SpeedLimiterConfig
from kiseki.terrain.mapper import MapperConfig


def run(*args, cwd: Path | None = None, columns: int = 200) -> subprocess.CompletedProcess:
    env = {**os.environ, "COLUMNS": str(columns)}
    return subprocess.run(
        [sys.executable, "-m", "kiseki.cli", *map(str, args)],
        capture_output=True,
        text=True,
        cwd=cwd,
        env=env,
    )


def root_and_context():
    root = typer.main.get_command(app)
    return root, typer.Context(root)


def listed_names(help_text: str) -> list[str]:
    """The command names of the Commands panel of a rich help page."""
    panel = help_text.split("Commands")[1]
    names = []
    for line in panel.splitlines():
        cells = line.strip("│ ").split()
        if line.startswith("│ ") and not line.startswith("│  ") and cells:
            names.append(cells[0])
    return names


# --- the root lists every command from its table, and loads only the one that runs ---


def test_help_lists_every_command_with_its_line_and_no_alias():
    done = run("--help")
    assert done.returncode == 0, done.stderr
    assert listed_names(done.stdout) == list(COMMANDS)
    assert not set(ALIASES) & set(listed_names(done.stdout))
    flat = " ".join(done.stdout.replace("│", " ").split())
    for entry in COMMANDS.values():
        assert " ".join(entry.help.split()) in flat


def test_each_table_line_is_its_commands_own_first_paragraph():
    root, _ = root_and_context()
    lazy = [group for _, group in every_command(root) if isinstance(group, LazyGroup)]
    assert {g.table is COMMANDS for g in lazy} == {True, False}  # the root and `kiseki map`
    for group in lazy:
        ctx = typer.Context(group)
        for name, entry in group.table.items():
            command = group.get_command(ctx, name)
            assert command is not None and command.name == name
            assert command.help.split("\n\n")[0] == entry.help, name
            assert isinstance(command, TyperGroup) == entry.group, name


def loaded_modules(*args: str) -> set[str]:
    """The kiseki.cli, kiseki_experiments and matplotlib modules a fresh interpreter loads to run
    ``kiseki ARGS``."""
    code = (
        "import runpy, sys\n"
        f"sys.argv = ['kiseki', *{list(args)!r}]\n"
        "try:\n"
        "    runpy.run_module('kiseki.cli', run_name='__main__')\n"
        "except SystemExit:\n"
        "    pass\n"
        "names = [m for m in sys.modules if m.startswith(('kiseki.cli', 'kiseki_exp', 'matpl'))]\n"
        "print('MODULES', *names, file=sys.stderr)\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    (line,) = [x for x in done.stderr.splitlines() if x.startswith("MODULES")]
    return set(line.split()[1:])


def test_help_imports_no_command_module_and_a_command_only_its_own():
    # modules named in the table: none loads for the listing
    modules = {entry.module for entry in COMMANDS.values()}
    help_loads = loaded_modules("--help")
    assert "kiseki.cli" in help_loads and not help_loads & modules
    localize_loads = loaded_modules("localize", "--help")
    assert "kiseki.cli.localize" in localize_loads
    assert not (localize_loads & modules) - {"kiseki.cli.localize"}
    assert not any(m.startswith("kiseki_experiments") for m in localize_loads)
    # within a group too: `kiseki map info` loads neither from-log's log readers nor matplotlib
    info_loads = loaded_modules("map", "info", "--help")
    assert {"kiseki.cli.map", "kiseki.cli.map_info"} <= info_loads
    assert not {"kiseki.cli.map_from_log", "kiseki.cli.map_render"} & info_loads
    assert not any(m.startswith("matplotlib") for m in info_loads)
    # listing the experiments imports every experiment, and still no matplotlib: a figure
    # imports it when it is drawn
    listed = loaded_modules("experiment", "list")
    assert "kiseki_experiments.teach.layouts_report" in listed
    assert not any(m.startswith("matplotlib") for m in listed)


def test_an_unknown_command_is_a_usage_error():
    done = run("nonsense")
    assert done.returncode == 2
    assert "No such command 'nonsense'" in done.stderr


# --- the old names ---


# every old name and the command it became (a new alias is added here too)
OLD_NAMES = [("report", ("experiment", "report"))]


def test_the_old_names_are_the_alias_table():
    assert {old: alias.new for old, alias in ALIASES.items()} == dict(OLD_NAMES)
    assert not set(ALIASES) & set(COMMANDS)  # an alias never hides a command


@pytest.mark.parametrize(("old", "new_words"), OLD_NAMES)
def test_an_old_name_warns_once_and_runs_the_new_command(tmp_path, old, new_words):
    new = " ".join(new_words)
    warning = f"kiseki: warning: 'kiseki {old}' is deprecated; use 'kiseki {new}'"
    (tmp_path / "results").mkdir()
    by_new = run(*new_words, "--json", "-o", "new.md", cwd=tmp_path)
    by_old = run(old, "--json", "-o", "old.md", cwd=tmp_path)
    assert by_new.returncode == by_old.returncode == 0, (by_new.stderr, by_old.stderr)
    assert by_new.stderr == ""
    assert by_old.stderr.splitlines() == [warning]
    assert by_old.stdout.replace("old.md", "new.md") == by_new.stdout
    assert (tmp_path / "old.md").read_text() == (tmp_path / "new.md").read_text()
    # an error of the new command: its one line and its exit status, after the one warning
    by_new = run(*new_words, "--results", "missing", cwd=tmp_path)
    by_old = run(old, "--results", "missing", cwd=tmp_path)
    assert by_new.returncode == by_old.returncode == 1
    assert by_old.stderr.splitlines() == [warning, *by_new.stderr.splitlines()]
    # a usage error: click's exit status 2, still after one warning
    by_old = run(old, "--no-such-option", cwd=tmp_path)
    assert by_old.returncode == 2
    assert by_old.stderr.splitlines()[0] == warning
    assert sum(line.startswith("kiseki: warning:") for line in by_old.stderr.splitlines()) == 1
    # its help is the new command's
    by_old = run(old, "--help", cwd=tmp_path)
    assert by_old.returncode == 0 and f"kiseki.cli {new} [OPTIONS]" in by_old.stdout


# --- help paragraphs reflow ---


def test_reflow_joins_the_lines_of_each_paragraph_only():
    text = """First line
    goes on.

    Second paragraph
    also.

    \b
    kept
    as written"""
    assert reflow(text) == "First line goes on.\n\nSecond paragraph also.\n\n\b\nkept\nas written"
    assert reflow(None) is None and reflow("") == ""


def every_command(command, path=()):
    """(words, command) for every command below and including ``command`` (the root's
    commands through its lookup, as a user's call would load them)."""
    found = [(path, command)]
    ctx = typer.Context(command)
    if isinstance(command, TyperGroup):
        for name in command.list_commands(ctx):
            found += every_command(command.get_command(ctx, name), (*path, name))
    return found


def test_no_help_paragraph_of_any_command_keeps_a_line_break():
    root, _ = root_and_context()
    commands = every_command(root)
    assert len(commands) >= 30  # the groups and their commands
    for words, command in commands:
        for paragraph in (command.help or "").split("\n\n"):
            assert "\n" not in paragraph or paragraph.startswith("\b"), words


@pytest.mark.parametrize(
    ("args", "sentence"),
    [
        (["--help"], "measure the taught maps against the scene's truth"),
        (["localize", "--help"], "(written to OUTPUT.json too); with --json the same numbers"),
        (["magnetic", "--help"], "map of the route (nodes every 0.1 m) and of two paths"),
        (["terrain", "--help"], "at each stop a tilting-laser sweep becomes an S-DEM"),
    ],
)
def test_help_sentences_are_not_broken_mid_paragraph(args, sentence):
    done = run(*args, columns=200)
    assert done.returncode == 0, done.stderr
    assert any(sentence in line for line in done.stdout.splitlines()), done.stdout


# --- the defaults are the config types' ---


def option_default(words: tuple[str, ...], option: str):
    root, _ = root_and_context()
    command = root
    for word in words:
        command = command.get_command(typer.Context(command), word)
    (param,) = [p for p in command.params if p.name == option]
    return param.default


def test_the_options_defaults_are_the_config_types():
    # the one default method of localization (position tracking and global)
    assert LocalizeConfig.method == GlobalConfig.method == "likelihood-field"
    assert option_default(("localize",), "method") == LocalizeConfig.method
    assert option_default(("localize",), "seed") == LocalizeConfig.seed
    for option in ("particles", "beams", "recovery", "threads", "tracking_particles"):
        # None: the config's own default (LocalizeConfig, or GlobalConfig with --global)
        assert option_default(("localize",), option) is None, option
    assert option_default(("map", "from-log"), "resolution") == MapBuildConfig.resolution
    assert option_default(("map", "from-log"), "usable_range") == MapBuildConfig.usable_range
    assert option_default(("playback",), "method") == PlaybackConfig.method
    assert option_default(("serve",), "particles") == PlaybackConfig.particles
    assert option_default(("demo",), "particles") == PlaybackConfig.particles
    assert option_default(("speed", "limits"), "v_max") == SpeedLimiterConfig.v_max
    assert option_default(("speed", "limits"), "half_angle") == pytest.approx(90.0)
    assert option_default(("terrain", "run"), "removal") == MapperConfig.removal
    # the command's documented default search, held by the config (the experiments set theirs)
    assert option_default(("terrain", "run"), "search") == MapperConfig.search == "coarse-to-fine"
