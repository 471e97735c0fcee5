# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The C++ harnesses of bench_anchors.py (benchmarks/anchors/): their build, the input file they
read and the estimates and times they write. Imported from beside this file.

The anchors (nav2_amcl, beluga and Sophus, unmodified snapshots) are found in the sibling folder
``../shared/anchors`` of the repository root or in the folder given; kiseki never links, imports
or copies them. The harnesses are built in build/anchors with CMake (Release: -O3 -DNDEBUG,
kiseki's flags) and the build is reused by later runs. The input layout is written out in
benchmarks/anchors/harness_io.hpp; write_input and read_input here hold the same one.
"""

from __future__ import annotations

import dataclasses
import os
import shutil
import struct
import subprocess
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
ANCHORS = ROOT.parent / "shared" / "anchors"
SOURCES = ROOT / "benchmarks" / "anchors"
BUILD = ROOT / "build" / "anchors"
HARNESSES = ("nav2_harness", "beluga_harness", "kiseki_harness")

MAGIC = b"KANCHOR1"
# the order of harness::Parameter in harness_io.hpp
PARAMETERS = (
    "z_hit",
    "z_rand",
    "sigma_hit",
    "likelihood_max_dist",
    "z_short",
    "z_max",
    "lambda_short",
    "alpha1",
    "alpha2",
    "alpha3",
    "alpha4",
    "initial_x",
    "initial_y",
    "initial_theta",
    "initial_sd_x",
    "initial_sd_y",
    "initial_sd_theta",
)


class HarnessError(RuntimeError):
    """A harness could not be built or run (the message says which and why)."""


def anchors_present(anchors: Path) -> bool:
    return all(
        (anchors / part).exists()
        for part in ("nav2_amcl/src/pf/pf.c", "beluga/beluga/include/beluga", "sophus/sophus")
    )


def build(anchors: Path, build_dir: Path = BUILD, jobs: int = 2) -> dict[str, Path]:
    """Configures (once per anchors folder) and builds the three harnesses; returns their
    paths. A second call rebuilds only what changed (nothing, normally)."""
    cmake = shutil.which("cmake")
    if cmake is None:
        raise HarnessError("cmake not found: it builds the anchors' harnesses")
    build_dir.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ)
    if shutil.which("ccache"):  # the compiler cache kiseki's builds use (scripts/setup.sh)
        env.setdefault("CMAKE_CXX_COMPILER_LAUNCHER", "ccache")
        env.setdefault("CMAKE_C_COMPILER_LAUNCHER", "ccache")
    cache = build_dir / "CMakeCache.txt"
    configured = cache.exists() and f"ANCHORS_DIR:PATH={anchors.resolve()}\n" in cache.read_text()
    # Ninja, as the editable install builds: kiseki_core's compile commands are then the same
    # and the compiler cache serves them (with Makefiles 66 of 73 compiles missed)
    generator = ["-G", "Ninja"] if shutil.which("ninja") else []
    steps = [] if configured else [
        [cmake, "-S", str(SOURCES), "-B", str(build_dir), *generator, "-DCMAKE_BUILD_TYPE=Release",
         f"-DANCHORS_DIR={anchors.resolve()}", f"-DKISEKI_ROOT={ROOT}"]
    ]  # fmt: skip
    steps.append([cmake, "--build", str(build_dir), "-j", str(jobs), "--target", *HARNESSES])
    for command in steps:
        done = subprocess.run(command, env=env, capture_output=True, text=True)
        if done.returncode != 0:
            tail = "\n".join((done.stdout + done.stderr).strip().splitlines()[-15:])
            raise HarnessError(f"building the anchors' harnesses failed:\n{tail}")
    return {name: build_dir / name for name in HARNESSES}


@dataclasses.dataclass(frozen=True)
class HarnessInput:
    """What every harness reads: the map (kiseki's cell values, corner origin), the scans'
    beams, the odometry and the shared parameters (PARAMETERS)."""

    cells: np.ndarray  # (height, width) int8: 0 free, 100 occupied, -1 unknown
    resolution: float
    origin: tuple[float, float]
    max_range: float
    angles: np.ndarray  # (beams,) float64
    ranges: np.ndarray  # (scans, beams) float32, NaN where no valid reading
    odometry: np.ndarray  # (scans, 3) float64
    parameters: dict[str, float]


def write_input(path: Path, data: HarnessInput) -> None:
    cells = np.ascontiguousarray(data.cells, dtype=np.int8)
    ranges = np.ascontiguousarray(data.ranges, dtype="<f4")
    scans, beams = ranges.shape
    if cells.ndim != 2 or data.angles.shape != (beams,) or data.odometry.shape != (scans, 3):
        raise ValueError("harness input: cells, angles, ranges and odometry do not agree")
    missing = set(PARAMETERS) - set(data.parameters)
    if missing:
        raise ValueError(f"harness input: no value for {', '.join(sorted(missing))}")
    height, width = cells.shape
    with open(path, "wb") as f:
        f.write(MAGIC)
        f.write(struct.pack("<4i", width, height, scans, beams))
        f.write(struct.pack("<4d", data.resolution, *data.origin, data.max_range))
        f.write(struct.pack(f"<{len(PARAMETERS)}d", *(data.parameters[p] for p in PARAMETERS)))
        f.write(cells.tobytes())
        f.write(np.ascontiguousarray(data.angles, dtype="<f8").tobytes())
        f.write(ranges.tobytes())
        f.write(np.ascontiguousarray(data.odometry, dtype="<f8").tobytes())


def read_input(path: Path) -> HarnessInput:
    raw = Path(path).read_bytes()
    if raw[:8] != MAGIC:
        raise ValueError(f"{path} is not a harness input")
    width, height, scans, beams = struct.unpack_from("<4i", raw, 8)
    resolution, ox, oy, max_range = struct.unpack_from("<4d", raw, 24)
    offset = 56
    values = struct.unpack_from(f"<{len(PARAMETERS)}d", raw, offset)
    offset += 8 * len(PARAMETERS)

    def take(dtype: str, count: int) -> np.ndarray:
        nonlocal offset
        out = np.frombuffer(raw, dtype=dtype, count=count, offset=offset)
        offset += out.nbytes
        return out

    cells = take("i1", width * height).reshape(height, width)
    angles = take("<f8", beams)
    ranges = take("<f4", scans * beams).reshape(scans, beams)
    odometry = take("<f8", scans * 3).reshape(scans, 3)
    if offset != len(raw):
        raise ValueError(f"{path} is longer than its header says")
    return HarnessInput(
        cells, resolution, (ox, oy), max_range, angles, ranges, odometry,
        dict(zip(PARAMETERS, values, strict=True)),
    )  # fmt: skip


def run_harness(
    harness: Path,
    input_path: Path,
    output_path: Path,
    particles: int,
    seed: int,
    threads: int = 1,
    model: str = "likelihood-field",
    combination: str = "nav2",
) -> tuple[np.ndarray, np.ndarray]:
    """Runs one harness over an input: the estimate after each scan (scans, 3) and the seconds
    its update calls took at each scan."""
    command = [
        str(harness), str(input_path), str(output_path), "--particles", str(particles),
        "--seed", str(seed), "--threads", str(threads), "--model", model,
        "--combination", combination,
    ]  # fmt: skip
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        raise HarnessError(f"{harness.name}: {done.stderr.strip() or done.returncode}")
    steps = np.fromfile(output_path, dtype="<f8").reshape(-1, 4)
    return steps[:, :3], steps[:, 3]


def echo_input(harness: Path, input_path: Path, copy_path: Path) -> None:
    """Has a harness read an input and write it back (the round trip of the tests)."""
    done = subprocess.run(
        [str(harness), str(input_path), "--echo", str(copy_path)], capture_output=True, text=True
    )
    if done.returncode != 0:
        raise HarnessError(f"{harness.name}: {done.stderr.strip()}")
