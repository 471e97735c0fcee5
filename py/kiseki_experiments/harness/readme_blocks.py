# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The README's reproduction tables, regenerated from the results the report reads.

A README marks what the report writes with HTML comments, which Markdown does not show:

* ``<!-- claims: NAME -->`` ... ``<!-- /claims -->``: experiment NAME's claims from its latest
  result (the claim, the paper's value, kiseki's with its 95 % interval, the verdict, the
  trials) and the run they come from;
* ``<!-- reproduction-summary -->`` ... ``<!-- /reproduction-summary -->``: one row per
  registered experiment (claims by verdict, the share decided, trials, the trials' time on one
  core, commit) and the totals.

:func:`update_readme` replaces the text between each pair and leaves every other line as it
was, so the prose around a table stays the authors' while the numbers are the run's."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from kiseki_experiments.harness.registry import all_experiments
from kiseki_experiments.harness.report import (
    duration_text,
    markdown_table,
    tally,
    tally_text,
    time_text,
)
from kiseki_experiments.harness.run_reader import read_latest, read_timings, trial_seconds

__all__ = [
    "Result",
    "check_markers",
    "claims_block",
    "gather",
    "summary_block",
    "update_readme",
]

_CLAIMS = re.compile(r"(<!-- claims: ([a-z0-9-]+) -->\n)(.*?)(<!-- /claims -->)", re.S)
_SUMMARY = re.compile(
    r"(<!-- reproduction-summary -->\n)(.*?)(<!-- /reproduction-summary -->)", re.S
)


@dataclass(frozen=True)
class Result:
    """An experiment's latest result: its claims (claims.csv) and where it was run from."""

    name: str
    claims: pd.DataFrame
    trials: int
    failed: int
    commit: str
    seconds: float = math.nan  # the trials' time summed (one core); nan without timings


def gather(results_root: Path) -> dict[str, Result]:
    """The latest result of every registered experiment that has one, by name."""
    if not results_root.is_dir():
        raise FileNotFoundError(f"{results_root}: results folder not found")
    out = {}
    for name in sorted(all_experiments()):
        found = read_latest(results_root, name)
        if found is None:
            continue
        latest, claims, manifest = found
        commit = str(manifest["git"].get("commit") or "unknown")[:7]
        seconds = trial_seconds(read_timings(latest))
        out[name] = Result(
            name, claims, manifest["trials"], manifest["trials_failed"], commit, seconds
        )
    return out


def _interval(row) -> str:
    lo, hi = float(row.ci_low), float(row.ci_high)
    ci = "" if math.isnan(lo) or math.isnan(hi) else f" [{lo:.3g}, {hi:.3g}]"
    return f"{row.measured_value}{ci}"


def claims_block(result: Result | None, name: str) -> str:
    """The text between an experiment's claims markers."""
    if result is None:
        return f"No result yet: `kiseki experiment run {name}`.\n"
    c = result.claims
    table = pd.DataFrame(
        {
            "claim": c["claim"],
            "paper": c["paper_value"],
            "kiseki [95 %]": [_interval(r) for r in c.itertuples(False)],
            "unit": c["unit"],
            "verdict": c["verdict"],
            "trials": c["trials"],
        }
    )
    head = (
        f"`kiseki experiment run {name}`: {result.trials} trials, {result.failed} failed, "
        f"commit {result.commit}; {tally_text(tally(c))}."
    )
    return f"{head}\n\n{markdown_table(table)}\n"


def summary_block(results: dict[str, Result]) -> str:
    """The text between the summary markers: every registered experiment, a row each."""
    rows, frames = [], []
    for name in sorted(all_experiments()):
        r = results.get(name)
        if r is None:
            rows.append({"experiment": name, "claims": "no result yet"})
            continue
        t = tally(r.claims)
        frames.append(r.claims)
        rows.append(
            {
                "experiment": name,
                "claims": t["claims"],
                "hold": t["holds"],
                "fail": t["fails"],
                "inconclusive": t["inconclusive"],
                "decided": f"{100 * t['decided'] / t['claims']:.0f} %" if t["claims"] else "",
                "trials": r.trials,
                "trial time (1 core)": duration_text(r.seconds),
                "commit": r.commit,
            }
        )
    table = pd.DataFrame(rows).astype(object).fillna("")
    empty = pd.DataFrame({"verdict": pd.Series([], dtype=str)})
    total = tally(pd.concat(frames, ignore_index=True) if frames else empty)
    timed = [r.seconds for r in results.values() if not math.isnan(r.seconds)]
    spent = time_text(sum(timed), len(results), len(results) - len(timed))
    return f"{markdown_table(table)}\n\nAll results: {tally_text(total)}; {spent}.\n"


# a line that looks like a marker (a marker quoted inside a line of prose is prose); each must
# be written exactly as _CLAIMS and _SUMMARY read it, or a block is skipped or swallows prose
_MARKER_LINE = re.compile(r"<!--\s*(/?)\s*(claims|reproduction-summary)\b(.*?)-->")
_EXACT = {  # (opening "" or closing "/", kind): the marker's pattern, and how to write it
    ("", "claims"): (r"<!-- claims: [a-z0-9-]+ -->", "<!-- claims: NAME --> (NAME in lower case)"),
    ("/", "claims"): (r"<!-- /claims -->", "<!-- /claims -->"),
    ("", "reproduction-summary"): (
        r"<!-- reproduction-summary -->",
        "<!-- reproduction-summary -->",
    ),
    ("/", "reproduction-summary"): (
        r"<!-- /reproduction-summary -->",
        "<!-- /reproduction-summary -->",
    ),
}


def check_markers(text: str, readme: Path) -> None:
    """Raises ValueError naming the README and the line of a marker that would leave a block
    unwritten, half written or swallowing the prose after it: a marker not written exactly as
    ``<!-- claims: NAME -->``, ``<!-- /claims -->``, ``<!-- reproduction-summary -->`` or
    ``<!-- /reproduction-summary -->`` on a line of its own (other spacing, a trailing space, a
    carriage return of CRLF line ends), an opening marker never closed or opened again before
    it is closed, a closing marker with no block open; and a README with no block at all. Such
    a README was left as it was, half replaced or cut, the command exiting 0."""
    opened: tuple[int, str, str] | None = None  # line, kind, marker
    blocks = 0
    for number, line in enumerate(text.split("\n"), start=1):
        m = _MARKER_LINE.fullmatch(line.strip())
        if m is None:
            continue
        key, kind = (m.group(1), m.group(2)), m.group(2)
        where, marker = f"{readme}:{number}", line.strip()
        pattern, written_as = _EXACT[key]
        if not re.fullmatch(pattern, line):
            ending = " (its line ends with a carriage return: CRLF)" if line.endswith("\r") else ""
            raise ValueError(
                f"{where}: {marker} is not a marker as written{ending}: write "
                f"{written_as} alone on its line"
            )
        if not m.group(1):
            if opened is not None:
                raise ValueError(
                    f"{where}: {marker} opens a block inside the one opened at line {opened[0]}"
                    f" ({opened[2]}): close that one first with <!-- /{opened[1]} -->"
                )
            opened = (number, kind, marker)
            continue
        if opened is None or opened[1] != kind:
            raise ValueError(f"{where}: {marker} closes no block")
        opened, blocks = None, blocks + 1
    if opened is not None:
        raise ValueError(
            f"{readme}:{opened[0]}: {opened[2]} is never closed with <!-- /{opened[1]} -->"
        )
    if blocks == 0:
        raise ValueError(
            f"{readme}: holds no block to regenerate (<!-- claims: NAME --> ... <!-- /claims -->"
            " or <!-- reproduction-summary --> ... <!-- /reproduction-summary -->)"
        )
    found = len(_CLAIMS.findall(text)) + len(_SUMMARY.findall(text))
    if found != blocks:  # what the checks above cannot see must not pass either
        raise ValueError(f"{readme}: {blocks} blocks are marked but {found} can be read")


def update_readme(text: str, readme: Path, results_root: Path) -> tuple[str, list[str]]:
    """(``text``, the README's, with every marked block regenerated from ``results_root``; the
    names of the experiments whose blocks were written). A block naming no registered
    experiment, and markers :func:`check_markers` refuses, are a ValueError naming the README
    (and the line)."""
    check_markers(text, readme)
    known = all_experiments()
    results = gather(results_root)
    named = [m.group(2) for m in _CLAIMS.finditer(text)]
    unknown = [n for n in named if n not in known]
    if unknown:
        raise ValueError(f"{readme}: a claims block names no experiment: {unknown[0]!r}")
    text = _CLAIMS.sub(
        lambda m: m.group(1) + claims_block(results.get(m.group(2)), m.group(2)) + m.group(4),
        text,
    )
    text = _SUMMARY.sub(lambda m: m.group(1) + summary_block(results) + m.group(3), text)
    return text, named
