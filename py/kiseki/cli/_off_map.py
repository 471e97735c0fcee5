# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The check that a map is the log's (``kiseki localize``, ``relocalize``, ``speed limits``): a
warning when most scan endpoints, at the estimated or the log's reference poses, miss the map's
walls; and whether a log has an endpoint at all (``kiseki map from-log``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import typer

from kiseki.mapping import endpoint_agreement

OFF_MAP_SHARE = 0.5  # below this share of endpoints near a wall the map is not the log's


def has_endpoints(poses: np.ndarray, ranges, max_range: float) -> bool:
    """Whether any scan at a finite pose has an endpoint as endpoint_agreement and the mappers
    count them: a finite reading in (0, max_range), float32 as the core reads it, compared in
    double as the core compares it."""
    finite = np.isfinite(poses).all(axis=1)
    kept = np.asarray(ranges, dtype=np.float32)[finite].astype(np.float64)
    return bool((np.isfinite(kept) & (kept > 0.0) & (kept < max_range)).any())


def warn_if_off_the_map(
    grid,
    trajectory: np.ndarray,
    scans,
    map_file: Path,
    share: float | None = None,
    poses: str = "estimated",
) -> None:
    """One warning line when most scan endpoints, at the ``poses`` ("estimated" by a filter, or
    the log's "reference" poses), miss the map's walls (a map of another building, a 1x1 map):
    the poses alone look fine in such a case. ``share``: the share already measured (global
    localization's, from convergence on)."""
    if poses not in ("estimated", "reference"):
        raise ValueError(f"poses must be 'estimated' or 'reference', got {poses!r}")
    if share is None:
        finite = np.isfinite(trajectory).all(axis=1)
        # with no endpoint (no estimate, or every reading at max_range) the share is undefined
        # and there is nothing to warn about
        if not has_endpoints(trajectory, scans.ranges, scans.max_range):
            return
        share = endpoint_agreement(
            grid, trajectory[finite], scans.ranges[finite], scans.angles, scans.max_range
        )
    if share < OFF_MAP_SHARE:
        lost = ", or the localization is lost" if poses == "estimated" else ""
        typer.echo(
            f"kiseki: warning: only {100 * share:.1f} % of the scan endpoints fall on or next to "
            f"an occupied cell of {map_file} at the {poses} poses: the map is probably not "
            f"the log's building{lost}",
            err=True,
        )
