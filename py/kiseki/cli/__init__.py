# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The ``kiseki`` command line: one command with subcommands.

Names: the factory AGV's main job has top-level verbs, ``kiseki teach``, ``kiseki playback``,
``kiseki localize``, ``kiseki relocalize``, ``kiseki serve`` and ``kiseki demo``; everything
else is ``kiseki GROUP VERB``, the group a noun for what it works on (``kiseki map info``,
``kiseki experiment report``, ``kiseki magnetic teach``). An old name runs for one release as a
hidden alias that prints one warning line (:data:`ALIASES`).

Exit status: errors in what the user gave (a missing or corrupt file, a bad value) print one
line ``kiseki: error: ...`` on stderr and exit with status 1; usage errors (an unknown option, a
missing argument) exit with status 2; an internal error (a bug) prints its traceback and exits
with status 3.
"""

from __future__ import annotations

import signal
import sys
import traceback
import warnings

import typer

from kiseki.cli._lazy import Alias, Entry, LazyGroup
from kiseki.core import library_versions
from kiseki.errors import KisekiError

__all__ = ["ALIASES", "COMMANDS", "EXIT_BAD_INPUT", "EXIT_INTERNAL", "app", "main"]

EXIT_OK, EXIT_BAD_INPUT, EXIT_USAGE, EXIT_INTERNAL = 0, 1, 2, 3

# every command, in the order `kiseki --help` lists them, with its line there (a test checks
# that each line is its command's own first paragraph)
COMMANDS = {
    "demo": Entry(
        "kiseki.cli.demo",
        "The main job: teach the factory route with a turn, measure the taught maps against the "
        "scene's truth, play the route back with each method, and print the thesis' Table "
        "4.5-style comparison.",
        group=False,
    ),
    "teach": Entry(
        "kiseki.cli.teach",
        "Teach a route: push the robot along the scene's route (simulated) or from the keyboard, "
        "build the environment maps with the thesis' merge rules (or --merge evidence), record "
        "the waypoints and measure the maps against the scene's truth (map_truth.json); the run "
        "is logged as it goes.",
        group=False,
    ),
    "playback": Entry(
        "kiseki.cli.playback",
        "Play a taught route back on the particle filter's estimate; stop within 0.1 m of the "
        "goal. Give the teaching folder (--taught) or its waypoint file (--waypoints, and --map "
        "for a map other than the one named there).",
        group=False,
    ),
    "serve": Entry(
        "kiseki.cli.serve",
        "Serve the route-instruction page and its JSON API over a taught run: a worker picks "
        "start, via and goal waypoints, the simulated AGV drives there, stops within 0.1 m, "
        "dwells and returns home, watched live over a websocket. Binding beyond loopback prints "
        "an access token that every API request must carry (Authorization: Bearer TOKEN).",
        group=False,
    ),
    "localize": Entry(
        "kiseki.cli.localize",
        "Localize along a log: position tracking from its first reference pose, or with --global "
        "from a uniform start. Prints the absolute pose error against the log's reference poses "
        "when it has them; with --global also the convergence report (written to OUTPUT.json "
        "too); with --json the same numbers as one JSON object. The settings it ran with are "
        "written beside the output as OUTPUT-STEM.config.yaml.",
        group=False,
    ),
    "relocalize": Entry(
        "kiseki.cli.relocalize",
        "Relocalize from one scan: search the whole map for the poses that explain scan N of a "
        "log best (branch-and-bound correlative matching, scored with the likelihood field), "
        "and print the distinct hypotheses ranked by score, with their error when the log has "
        "reference poses.",
        group=False,
    ),
    "map": Entry("kiseki.cli.map", "Occupancy-grid maps: build, render, inspect."),
    "experiment": Entry(
        "kiseki.cli.experiment",
        "Experiments: one command per paper table or figure, and the report of their results.",
    ),
    "sim": Entry("kiseki.cli.sim", "Simulation: scenes, runs logged to MCAP."),
    "coop": Entry("kiseki.cli.coop", "Cooperative positioning: robots triangulate each other."),
    "speed": Entry(
        "kiseki.cli.speed", "Speed limits that consider occluded regions and passage width."
    ),
    "magnetic": Entry(
        "kiseki.cli.magnetic",
        "Magnetic field maps (fit, predict, render), walks, teaching and navigation.",
    ),
    "terrain": Entry(
        "kiseki.cli.terrain",
        "3-D localization and mapping in rubble: sphere elevation maps, plane removal, "
        "correlation search, OctoMap global maps.",
    ),
}

# old names, kept for one release: each warns once on stderr and runs its new command
ALIASES = {"report": Alias(("experiment", "report"))}


class _Root(LazyGroup):
    table = COMMANDS
    aliases = ALIASES


app = typer.Typer(
    cls=_Root,
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    help="kiseki: mobile-robot localization and navigation toolkit.",
)


def _version_callback(value: bool) -> None:
    if value:
        versions = library_versions()
        others = ", ".join(f"{k} {v}" for k, v in sorted(versions.items()) if k != "kiseki")
        typer.echo(f"kiseki {versions['kiseki']} ({others})")
        raise typer.Exit()


@app.callback()
def _root(
    version: bool = typer.Option(
        False, "--version", callback=_version_callback, is_eager=True, help="Show the version."
    ),
) -> None:
    """kiseki: mobile-robot localization and navigation toolkit."""


def _terminate(signum, frame) -> None:
    """SIGTERM ends a command as Ctrl-C does, through its cleanup: files being written are
    closed properly (a run's MCAP keeps its summary) and temporary files are removed."""
    sys.exit(128 + signum)


def _warn_in_one_line(message, category, filename, lineno, file=None, line=None) -> None:
    """Warnings (a truncated MCAP read, ...) as one line for people, not Python's two."""
    text = str(message).strip().splitlines()
    typer.echo(f"kiseki: warning: {text[0] if text else category.__name__}", err=True)


def main() -> None:
    """Entry point: runs the app and turns input errors into one line and exit status 1.
    Usage errors (an unknown option, a missing argument) exit 2 (click's own); anything else
    is a bug in kiseki: its traceback, one line asking for a report, and exit status 3."""
    signal.signal(signal.SIGTERM, _terminate)
    warnings.showwarning = _warn_in_one_line
    try:
        app()
    except (KisekiError, ValueError, OSError, RuntimeError, IndexError) as err:
        message = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
        typer.echo(f"kiseki: error: {message}", err=True)
        sys.exit(EXIT_BAD_INPUT)
    except Exception as err:  # the last resort: a bug, not the user's input
        traceback.print_exc()
        typer.echo(
            f"kiseki: internal error: {type(err).__name__} (a bug in kiseki: please report it "
            "with the lines above)",
            err=True,
        )
        sys.exit(EXIT_INTERNAL)
