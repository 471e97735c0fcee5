# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The README's marked reproduction tables are regenerated from the results folder the report
reads: the numbers are those of claims.csv, the prose around them is kept byte for byte."""

from __future__ import annotations

import shutil
from pathlib import Path

import pandas as pd
import pytest

from _helpers.cli_main import kiseki
from kiseki_experiments.harness.readme_blocks import update_readme
from kiseki_experiments.harness.registry import all_experiments
from kiseki_experiments.harness.report import duration_text, write_reproduction
from kiseki_experiments.harness.runner import run_experiment

PROSE = "# A project\n\nText before, with a | pipe.\n\n"
README = (
    PROSE
    + "<!-- claims: corridor-scans -->\nstale numbers 0.5 [0.1, 0.9]\n<!-- /claims -->\n"
    + "\nText between.\n\n"
    + "<!-- claims: exp1-corridor -->\nold\n<!-- /claims -->\n"
    + "<!-- reproduction-summary -->\n<!-- /reproduction-summary -->\nText after.\n"
)


@pytest.fixture(scope="module")
def results(tmp_path_factory) -> Path:
    root = tmp_path_factory.mktemp("results")
    out = root / "corridor-scans" / "r"
    assert run_experiment("corridor-scans", runs=5, out=out, progress=False).failed == 0
    assert (root / "corridor-scans" / "latest").resolve() == out.resolve()  # the runner's link
    return root


def _outside_blocks(text: str) -> list[str]:
    keep, inside = [], False
    for line in text.splitlines():
        if line.startswith("<!-- claims:") or line == "<!-- reproduction-summary -->":
            keep.append(line)
            inside = True
        elif line in ("<!-- /claims -->", "<!-- /reproduction-summary -->"):
            keep.append(line)
            inside = False
        elif not inside:
            keep.append(line)
    return keep


def test_blocks_hold_the_claims_of_the_latest_result_and_the_prose_is_kept(results, tmp_path):
    text, named = update_readme(README, tmp_path / "README.md", results)
    assert named == ["corridor-scans", "exp1-corridor"]
    assert _outside_blocks(text) == _outside_blocks(README)
    assert "stale numbers" not in text
    claims = pd.read_csv(results / "corridor-scans" / "latest" / "claims.csv")
    row = claims.iloc[0]
    shown = f"{row.measured_value} [{row.ci_low:.3g}, {row.ci_high:.3g}]"
    block = text.split("<!-- claims: corridor-scans -->\n")[1].split("<!-- /claims -->")[0]
    cells = [row.claim, row.paper_value, shown, row.unit, row.verdict, 5]
    assert "| " + " | ".join(map(str, cells)) + " |" in block
    assert block.startswith("`kiseki experiment run corridor-scans`: 5 trials, 0 failed")
    # an experiment without a result says so, and how to make one
    assert "No result yet: `kiseki experiment run exp1-corridor`." in text
    summary = text.split("<!-- reproduction-summary -->\n")[1].split("<!-- /reproduction-")[0]
    rows = [line for line in summary.splitlines() if line.startswith("| ")][1:]
    assert len(rows) == len(all_experiments())  # every registered experiment, a row each
    mine = next(r for r in rows if r.startswith("| corridor-scans |"))
    # claims, hold, fail, inconclusive, decided
    assert mine.split(" | ")[1:6] == ["1", "1", "0", "0", "100 %"]
    # the trials' time: their seconds in timings.parquet summed, and halved for 2 cores
    spent = pd.read_parquet(results / "corridor-scans" / "latest" / "timings.parquet")
    seconds = float(spent["trial_seconds"].sum())
    assert len(spent) == 5 and seconds > 0
    assert mine.split(" | ")[7] == duration_text(seconds)
    assert (
        f"the trials of this run took {duration_text(seconds)} on one core, "
        f"{duration_text(seconds / 2)} on 2 cores if spread evenly." in summary
    )
    # regenerating what was regenerated changes nothing
    assert update_readme(text, tmp_path / "README.md", results)[0] == text


def test_a_block_naming_no_experiment_is_refused_with_the_file(results, tmp_path):
    text = PROSE + "<!-- claims: no-such-experiment -->\n<!-- /claims -->\n"
    with pytest.raises(ValueError, match=r"README\.md: a claims block names no experiment"):
        update_readme(text, tmp_path / "README.md", results)


def test_report_command_rewrites_the_readme_in_place(results, tmp_path, monkeypatch, capsys):
    readme = tmp_path / "README.md"
    readme.write_text(README, encoding="utf-8")
    status, out, err = kiseki(
        monkeypatch, capsys, "experiment", "report", "--results", results,
        "-o", tmp_path / "R.md", "--readme", readme, "--json",
    )  # fmt: skip
    assert status == 0, err
    assert '"readme_blocks": 2' in out
    assert readme.read_text(encoding="utf-8") == update_readme(README, readme, results)[0]
    # a README that is not there: one line naming it, nothing written
    gone = tmp_path / "gone.md"
    status, out, err = kiseki(
        monkeypatch, capsys, "experiment", "report", "--results", results,
        "-o", tmp_path / "R2.md", "--readme", gone,
    )  # fmt: skip
    assert status != 0 and str(gone) in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "R2.md").exists()
    # a picture given as the README: one line naming it, nothing written
    picture = tmp_path / "x.md"
    picture.write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(range(256)))
    status, out, err = kiseki(
        monkeypatch, capsys, "experiment", "report", "--results", results,
        "-o", tmp_path / "R3.md", "--readme", picture,
    )  # fmt: skip
    assert status != 0 and len(err.strip().splitlines()) == 1
    assert f"{picture}: not UTF-8 text" in err and not (tmp_path / "R3.md").exists()


def test_the_readme_tables_are_the_committed_results():
    """The README's reproduction tables are what `kiseki experiment report --readme` makes of
    the results committed in docs/reproduction: edited by hand, or left behind by a new run,
    they fail here."""
    root = Path(__file__).resolve().parents[3]
    readme = root / "README.md"
    text = readme.read_text(encoding="utf-8")
    assert "<!-- reproduction-summary -->" in text
    regenerated, _ = update_readme(text, readme, root / "docs" / "reproduction" / "results")
    assert regenerated == text


def test_a_latest_link_leading_outside_the_results_is_refused_by_report_and_readme(
    results, tmp_path
):
    """The report and the README tables read a run through one function: a ``latest`` link
    moved or made by hand to lead outside --results is refused by both, naming the link."""
    root = tmp_path / "results"
    (root / "corridor-scans").mkdir(parents=True)
    elsewhere = (results / "corridor-scans" / "latest").resolve()
    (root / "corridor-scans" / "latest").symlink_to(elsewhere, target_is_directory=True)
    link = str(root / "corridor-scans" / "latest")
    with pytest.raises(ValueError, match="the link points outside --results") as err:
        update_readme(README, tmp_path / "README.md", root)
    assert link in str(err.value)
    with pytest.raises(ValueError, match="the link points outside --results") as err:
        write_reproduction(root, tmp_path / "R.md")
    assert link in str(err.value) and not (tmp_path / "R.md").exists()


def test_durations_read_as_people_read_them():
    assert [duration_text(s) for s in (7200.0, 5400.0, 90.0, 59.4, 0.0)] == [
        "2.00 h", "1.50 h", "2 min", "59 s", "0 s",
    ]  # fmt: skip
    assert duration_text(float("nan")) == ""


def test_a_damaged_timings_file_is_refused_by_report_and_readme_naming_it(results, tmp_path):
    """The trials' time comes from each run's timings.parquet: one that is not a table stops
    the README's tables and the report in one line naming the file, and writes nothing."""
    root = tmp_path / "results"
    shutil.copytree(results / "corridor-scans" / "latest", root / "corridor-scans")
    bad = root / "corridor-scans" / "timings.parquet"
    bad.write_bytes(b"not parquet")
    with pytest.raises(ValueError, match="not a timings table") as err:
        update_readme(README, tmp_path / "README.md", root)
    assert str(bad) in str(err.value) and "\n" not in str(err.value)
    with pytest.raises(ValueError, match="not a timings table") as err:
        write_reproduction(root, tmp_path / "R.md")
    assert str(bad) in str(err.value) and not (tmp_path / "R.md").exists()


@pytest.mark.parametrize(
    ("body", "message"),
    [
        ("No markers at all.\n", "README.md: holds no block to regenerate"),
        (
            "<!-- claims: corridor-scans -->\nold\n",
            "README.md:5: <!-- claims: corridor-scans --> is never closed with <!-- /claims -->",
        ),
        (
            "<!-- claims: corridor-scans -->\n<!-- claims: exp1-corridor -->\n<!-- /claims -->\n",
            "README.md:6: <!-- claims: exp1-corridor --> opens a block inside the one opened "
            "at line 5 (<!-- claims: corridor-scans -->): close that one first",
        ),
        ("<!-- /claims -->\n", "README.md:5: <!-- /claims --> closes no block"),
        (
            "<!-- reproduction-summary -->\n<!-- /claims -->\n",
            "README.md:6: <!-- /claims --> closes no block",
        ),
        (
            "<!-- claims: Corridor Scans -->\n<!-- /claims -->\n",
            "README.md:5: <!-- claims: Corridor Scans --> is not a marker",
        ),
        (  # the block read on to the next block's end, and the prose between was lost
            "<!-- claims: corridor-scans -->\nold\n<!-- /claims  -->\nProse to keep.\n"
            "<!-- claims: exp1-corridor -->\nold\n<!-- /claims -->\n",
            "README.md:7: <!-- /claims  --> is not a marker as written: write <!-- /claims -->",
        ),
        (  # CRLF line ends: no block was read, exit 0
            "<!-- claims: corridor-scans -->\r\nold\r\n<!-- /claims -->\r\n",
            "README.md:5: <!-- claims: corridor-scans --> is not a marker as written (its line "
            "ends with a carriage return: CRLF)",
        ),
        (
            "<!-- claims: corridor-scans --> \n<!-- /claims -->\n",
            "README.md:5: <!-- claims: corridor-scans --> is not a marker as written",
        ),
        (
            "<!--reproduction-summary-->\n<!--/reproduction-summary-->\n",
            "README.md:5: <!--reproduction-summary--> is not a marker as written: write "
            "<!-- reproduction-summary --> alone on its line",
        ),
    ],
    ids=[
        "none",
        "unclosed",
        "nested",
        "stray-close",
        "mismatched",
        "malformed",
        "spaced-close",
        "crlf",
        "trailing-space",
        "unspaced-summary",
    ],
)
def test_markers_that_would_leave_a_block_unwritten_are_refused_with_the_line(
    results, tmp_path, body, message
):
    """These READMEs were left as they were (or, nested, half replaced) and the command exited
    0 with 'readme_blocks 0'. A marker quoted inside a line of prose stays prose (the README's
    own description of the markers)."""
    with pytest.raises(ValueError) as err:
        update_readme(PROSE + body, tmp_path / "README.md", results)
    assert str(err.value).startswith(f"{tmp_path / 'README.md'}")
    assert message.split("README.md", 1)[1] in str(err.value)
    quoted = PROSE + "The `<!-- claims: NAME -->` markers.\n" + README[len(PROSE) :]
    assert update_readme(quoted, tmp_path / "README.md", results)[1] == [
        "corridor-scans",
        "exp1-corridor",
    ]
