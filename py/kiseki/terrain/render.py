# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Pictures of a terrain run: the global map's occupied voxels seen from above (coloured by
height) with the true and estimated sensor paths."""

from __future__ import annotations

import os

import numpy as np

from kiseki._support.atomic import atomic_write

__all__ = ["render_run"]


def render_run(table: np.ndarray, global_map, path: str | os.PathLike, title: str = "") -> None:
    """table: rows (move, x_true, y_true, z_true, x_est, y_est, z_est)."""
    # here, not at the top: matplotlib takes a second to load, and only drawing needs it
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # after the backend is chosen, as above

    centres = global_map.occupied_centres()
    fig, ax = plt.subplots(figsize=(7, 6), dpi=120)
    if len(centres):
        order = np.argsort(centres[:, 2])
        sc = ax.scatter(
            centres[order, 0], centres[order, 1], c=centres[order, 2], s=2, cmap="viridis",
            marker="s", linewidths=0,
        )  # fmt: skip
        fig.colorbar(sc, ax=ax, label="voxel height (m)")
    ax.plot(table[:, 1], table[:, 2], "k.-", label="true")
    ax.plot(table[:, 4], table[:, 5], "r.--", label="estimated (S-DEM search)")
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(title)
    ax.legend(loc="best")
    fig.tight_layout()
    atomic_write(path, lambda tmp: fig.savefig(tmp, format="png"))
    plt.close(fig)
