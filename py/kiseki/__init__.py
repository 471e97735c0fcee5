# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""kiseki: mobile-robot localization and navigation toolkit (C++17 core, Python front).

The public API lives in the areas (``kiseki.core``, ``kiseki.grid``, ``kiseki.mapping``,
``kiseki.io``, ``kiseki.filters``, ``kiseki.datasets``, ...; docs/DESIGN.md maps them); the
most used names are re-exported here. The modules that moved in the house layout
(``kiseki.localization``, ``kiseki.global_localization``, ``kiseki.map_io``,
``kiseki.map_schema``, ``kiseki.trajectory_csv``, ``kiseki.sim.mcap_log``) still import, with a
DeprecationWarning naming their new home, for one release (``kiseki._support.moved``).
"""

from __future__ import annotations

import os

# libgomp (the C++ core's OpenMP) reads OMP_WAIT_POLICY once, when the core is loaded, below.
# Its default lets idle workers spin between parallel regions; on a robot whose cores other
# processes keep busy, the spinning takes the time slices the work needs, and two threads ran
# slower than one (benchmarks/bench_threads_under_load.py). Passive workers sleep instead. A
# policy the user set is kept (libgomp refuses an empty one); a GOMP_SPINCOUNT the user sets
# applies under any policy (libgomp's env.c).
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

# numpy first: its own OpenBLAS picks its kernels itself, before the variable below is set.
import numpy  # noqa: E402, F401

from kiseki._support.openblas_kernels import kernels_while_loading  # noqa: E402

with kernels_while_loading():  # the core's OpenBLAS kernels named from the processor
    from kiseki import _core  # noqa: E402, F401  (loads the core, its OpenMP and its OpenBLAS)

from kiseki._support import moved  # noqa: E402
from kiseki.core import Pose2, Pose3, Random, derive_seed, library_versions, normalize_angle
from kiseki.errors import KisekiError, LogFormatError, MapFormatError
from kiseki.grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid
from kiseki.io.ros_map import load_map, save_map

moved.install()

__version__ = library_versions()["kiseki"]

__all__ = [
    "FREE",
    "OCCUPIED",
    "UNKNOWN",
    "KisekiError",
    "LogFormatError",
    "MapFormatError",
    "OccupancyGrid",
    "Pose2",
    "Pose3",
    "Random",
    "__version__",
    "derive_seed",
    "library_versions",
    "load_map",
    "normalize_angle",
    "save_map",
]
