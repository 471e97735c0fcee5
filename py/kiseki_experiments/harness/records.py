# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What trial records carry beside plain numbers: arrays packed as text (a record is one JSON
line of trials.jsonl and a row of trials.parquet), and the machine's load beside a wall time."""

from __future__ import annotations

import base64
import io
import os

import numpy as np

__all__ = ["load_average", "pack", "unpack"]


def pack(array: np.ndarray) -> str:
    """An array as text for a trial record (float32 .npy, base64)."""
    buffer = io.BytesIO()
    np.save(buffer, np.asarray(array, dtype=np.float32), allow_pickle=False)
    return base64.b64encode(buffer.getvalue()).decode("ascii")


def unpack(text: str) -> np.ndarray:
    return np.load(io.BytesIO(base64.b64decode(text)), allow_pickle=False).astype(np.float64)


def load_average() -> float:
    """The machine's 1-minute load average (wall times are slower on a busy machine)."""
    return float(os.getloadavg()[0]) if hasattr(os, "getloadavg") else float("nan")
