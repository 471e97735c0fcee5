# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The benchmarks' clock: the best of several runs of a call (other work on the machine only
ever slows a run down, so the fastest is the closest to the call's own cost); and the line every
benchmark prints first, naming the machine its figures come from."""

from __future__ import annotations

import os
import platform
import time
from pathlib import Path

import kiseki
from kiseki._support.openblas_kernels import processor_fields


def best_of(fn, repeats: int = 3) -> tuple[float, object]:
    """(the fastest of ``repeats`` runs of ``fn()`` in seconds, the last run's result)."""
    best, result = float("inf"), None
    for _ in range(repeats):
        start = time.perf_counter()
        result = fn()
        best = min(best, time.perf_counter() - start)
    return best, result


def processor(cpuinfo: Path = Path("/proc/cpuinfo")) -> str:
    """The first processor's model name with its family and model numbers ("AMD EPYC (family
    25, model 1)"), which tell processors of one name apart; the machine type without the file."""
    fields = processor_fields(cpuinfo)
    name = fields.get("model name", platform.machine())
    if "cpu family" in fields and "model" in fields:
        return f"{name} (family {fields['cpu family']}, model {fields['model']})"
    return name


def machine_line(cpuinfo: Path = Path("/proc/cpuinfo")) -> str:
    """Processor, cores, load, and the BLAS kernels kiseki's core runs on: what a benchmark's
    figures depend on besides the code."""
    blas = kiseki.library_versions().get("openblas", "unknown")
    return (
        f"machine: {processor(cpuinfo)}, {os.cpu_count()} cores, load average "
        f"{os.getloadavg()[0]:.1f}; kiseki's OpenBLAS {blas}; Python {platform.python_version()}"
    )
