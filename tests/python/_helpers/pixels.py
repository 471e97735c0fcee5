# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Reading pictures back in tests: pixels as RGB, and patches of one colour with their centres
and sizes (for checking what a PNG shows, not only that it was written)."""

from __future__ import annotations

import numpy as np
from PIL import Image
from scipy import ndimage


def rgb(path) -> np.ndarray:
    with Image.open(path) as image:
        return np.asarray(image.convert("RGB")).astype(int)


def blobs(image: np.ndarray, colour, tol: int = 12) -> list[tuple[np.ndarray, np.ndarray]]:
    """The 4-connected patches of pixels within `tol` of `colour`, largest first: each one's
    centre (column, row) and size (columns, rows) in pixels."""
    mask = (np.abs(image - np.asarray(colour)) <= tol).all(axis=2)
    labels, n = ndimage.label(mask)
    assert n > 0, f"no pixel of colour {colour}"
    out = []
    for k in np.argsort(-ndimage.sum(mask, labels, range(1, n + 1))):
        rows, cols = np.nonzero(labels == k + 1)
        centre = np.array([(cols.min() + cols.max() + 1) / 2, (rows.min() + rows.max() + 1) / 2])
        out.append((centre, np.array([cols.max() - cols.min() + 1, rows.max() - rows.min() + 1])))
    return out


def largest_blob(image: np.ndarray, colour, tol: int = 12) -> tuple[np.ndarray, np.ndarray]:
    return blobs(image, colour, tol)[0]
