# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The append-only trial log of a run (trials.jsonl): one JSON line per finished trial,
flushed and synced as soon as the trial ends, so a killed run loses no finished trial."""

from __future__ import annotations

import contextlib
import json
import os
from pathlib import Path
from typing import Any

import pandas as pd

from kiseki._support.atomic import reworded

__all__ = ["TrialLog"]


class TrialLog:
    def __init__(self, path: Path) -> None:
        self.path = path

    def read(self) -> dict[int, dict[str, Any]]:
        """Finished trials by index. A torn last line (the process died while writing it) is
        dropped and cut off the file, so that appending resumes on a clean line."""
        if not self.path.exists():
            return {}
        done: dict[int, dict[str, Any]] = {}
        good_bytes = 0
        with self.path.open("rb") as f:
            for raw in f:
                try:
                    entry = json.loads(raw)
                except json.JSONDecodeError:
                    break
                if not raw.endswith(b"\n"):
                    break
                done[int(entry["trial"])] = entry
                good_bytes += len(raw)
        if good_bytes != self.path.stat().st_size:
            with self.path.open("r+b") as f:
                f.truncate(good_bytes)
        return done

    def append(self, entry: dict[str, Any]) -> None:
        """Appends one trial; on a failure (a full disk) the log is cut back to its finished
        trials and the error names it."""
        line = json.dumps(entry, allow_nan=True) + "\n"  # keeps the record's key order
        size = self.path.stat().st_size if self.path.exists() else 0
        try:
            with self.path.open("a", encoding="utf-8") as f:
                f.write(line)
                f.flush()
                os.fsync(f.fileno())
        except OSError as err:
            with contextlib.suppress(OSError):
                os.truncate(self.path, size)
            message = (
                f"{self.path}: {err.strerror or err}; the trials finished before are kept "
                "(--resume runs the others)"
            )
            raise reworded(err, message) from err

    @staticmethod
    def frames(entries: dict[int, dict[str, Any]]) -> tuple[pd.DataFrame, pd.DataFrame]:
        """(trials, timings) data frames, one row per trial in index order."""
        rows, timing_rows = [], []
        for index in sorted(entries):
            e = entries[index]
            rows.append({"trial": index, "seed": e["seed"], "error": e["error"], **e["record"]})
            timing_rows.append({"trial": index, "worker": e["worker"], **e["timings"]})
        trials = pd.DataFrame(rows)
        trials["seed"] = trials["seed"].astype("uint64")
        trials["error"] = trials["error"].astype("string")
        return trials, pd.DataFrame(timing_rows)
