# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``kiseki experiment``: the experiments (one per paper table or figure) and the report of
their results."""

from __future__ import annotations

import fnmatch
import json
import sys
from pathlib import Path

import typer
from rich.console import Console
from rich.table import Table

from kiseki._support.atomic import atomic_write
from kiseki._support.guard import guarded
from kiseki._support.inputs import YAML_LIMIT, read_input_text
from kiseki._support.interrupt import interruptible
from kiseki._support.options import RUN_LIMIT, WORKER_LIMIT, Count, Seed
from kiseki._support.table import show_fields
from kiseki.errors import KisekiError
from kiseki_experiments.harness.readme_blocks import update_readme
from kiseki_experiments.harness.registry import all_experiments
from kiseki_experiments.harness.report import write_reproduction
from kiseki_experiments.harness.runner import run_experiment

__all__ = ["app"]

app = typer.Typer(
    no_args_is_help=True,
    help="Experiments: one command per paper table or figure, and the report of their results.",
)
console = Console(soft_wrap=True)  # piped: one line stays one line (grep, awk)


@app.command("list")
@guarded()  # no file
def experiment_list(
    as_json: bool = typer.Option(False, "--json", help="Print a JSON list of objects."),
) -> None:
    """List the registered experiments: a table on a terminal, tab-separated lines (a header,
    then one experiment a line) when piped, or JSON with --json.

    Example: kiseki experiment list | cut -f1"""
    columns = ("name", "paper", "table/figure", "description", "default trials")
    rows = [
        (name, e.paper, e.artefact, e.description, str(e.default_runs))
        for name, e in sorted(all_experiments().items())
    ]
    if as_json:
        keys = ("name", "paper", "artefact", "description", "default_runs")
        items = [dict(zip(keys, row[:4] + (int(row[4]),), strict=True)) for row in rows]
        typer.echo(json.dumps(items, indent=2))
    elif not sys.stdout.isatty():
        for row in (columns, *rows):
            typer.echo("\t".join(" ".join(str(v).split()) for v in row))
    else:
        table = Table(title="kiseki experiments")
        for column in columns:
            table.add_column(column)
        for row in rows:
            table.add_row(*row)
        console.print(table)


@app.command("run")
@guarded(output_folders=("out",))
@interruptible("the finished trials are kept: --resume --out RUN_FOLDER runs only the missing ones")
def experiment_run(
    name: str = typer.Argument(..., help="Experiment name (see: kiseki experiment list)."),
    runs: int | None = typer.Option(
        None, "--runs", parser=Count("--runs", 1, RUN_LIMIT), help="Number of trials."
    ),
    seed: int | None = typer.Option(
        None, "--seed", parser=Seed(), help="Run seed (trial seeds derive from it)."
    ),
    overrides: list[str] = typer.Option([], "--set", help="Config override key=value (repeat)."),
    workers: int | None = typer.Option(
        None,
        "--workers",
        parser=Count("--workers", 1, WORKER_LIMIT),
        help="Local Dask cluster of N workers.",
    ),
    scheduler: str | None = typer.Option(None, "--scheduler", help="Dask scheduler tcp://H:P."),
    out: Path | None = typer.Option(None, "--out", help="Results folder (default results/NAME/…)."),
    resume: bool = typer.Option(
        False,
        "--resume",
        help="Run only the missing trials of a run (with --runs N: extended to N trials first).",
    ),
) -> None:
    """Run an experiment's trials and write its results folder. NAME may be a pattern
    ('speed-*'): every matching experiment runs in turn, each into its own results folder
    (--out/NAME with --out), with its default trials; with --resume, the experiments already
    started are finished and the others started.

    Example: kiseki experiment run '*' --out full --resume"""

    names, pattern = [name], any(c in name for c in "*?[")
    if pattern:
        names = sorted(fnmatch.filter(all_experiments(), name))
        if not names:
            raise KisekiError(f"no experiment matches {name!r} (see: kiseki experiment list)")
        if runs is not None or overrides or (resume and seed is not None):
            raise KisekiError(
                "a pattern runs several experiments: no --runs or --set (and --resume takes "
                "each run's own seed)"
            )
    for each in names:
        where = out / each if out is not None and pattern else out
        again = resume
        if resume and pattern:  # a run stopped part way: finish the started, start the others
            folder = where if where is not None else Path("results") / each / "latest"
            again = (folder / "config.yaml").is_file()
            if not again:
                console.print(f"{each}: no run in {folder} yet: starting one")
        result = run_experiment(each, runs, seed, overrides, workers, scheduler, where, again)
        console.print(
            f"{result.run_dir}: {result.runs} trials ({result.executed} run now, "
            f"{result.failed} failed) in {result.wall_seconds:.1f} s"
        )


@app.command("report")
@guarded(inputs=("results",), outputs=("output", "readme"))
@interruptible()
def report(
    results: Path = typer.Option(Path("results"), help="Results folder of the experiments."),
    output: Path = typer.Option(Path("REPRODUCTION.md"), "-o", "--output", help="File to write."),
    readme: Path | None = typer.Option(
        None,
        help="Also regenerate this Markdown file's marked tables (<!-- claims: NAME --> ... "
        "<!-- /claims -->, <!-- reproduction-summary --> ... <!-- /reproduction-summary -->) "
        "from the same results; every other line is kept.",
    ),
    as_json: bool = typer.Option(False, "--json", help="Print the summary as one JSON object."),
) -> None:
    """Gather the latest result of every experiment into REPRODUCTION.md (each claim: the
    paper's value, kiseki's with its 95 % interval, the verdict) and print a summary (claims by
    verdict, the share decided, the experiments without a result): a table on a terminal,
    tab-separated field/value lines when piped, or JSON with --json.

    Example: kiseki experiment report --results results -o REPRODUCTION.md --readme README.md"""
    if readme is not None:  # read and checked before anything is written
        try:
            markdown = read_input_text(readme, "Markdown files", YAML_LIMIT)
        except UnicodeDecodeError as err:
            raise ValueError(f"{readme}: not UTF-8 text, so not a README ({err.reason})") from None
        text, blocks = update_readme(markdown, readme, results)
    totals, missing = write_reproduction(results, output)
    if readme is not None:
        atomic_write(readme, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))
    decided = totals["decided"] / totals["claims"] if totals["claims"] else 0.0
    summary = {
        "output": str(output),
        "claims": totals["claims"],
        "hold": totals["holds"],
        "fail": totals["fails"],
        "inconclusive": totals["inconclusive"],
        "not_migrated": totals["not_migrated"],
        "decided_share": round(decided, 4),
        "missing": missing,
    }
    if readme is not None:
        summary["readme_blocks"] = len(blocks)
    show_fields(str(output), summary, as_json=as_json, console=console)
