# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The OpenBLAS kernels kiseki's core runs on, named from the processor's instruction sets.

An OpenBLAS built for many processors (``DYNAMIC_ARCH``, as Debian's) picks its kernels when it
is loaded, from the processor's model number. A processor newer than the library falls back to
its SSE3 kernels ("Prescott"): Debian 12's OpenBLAS 0.3.21 does so on a 5th-generation Xeon
(family 6, model 207), where the Gaussian processes then ran 1.5x (a hyperparameter fit on 870
points) to 4x (a factorisation of 5,000) slower.
``OPENBLAS_CORETYPE`` names the kernels instead. kiseki sets it from the instruction sets that
Linux reports in ``/proc/cpuinfo``, only when the user has not set it, and only while its core
is loaded (`kernels_while_loading`), so that numpy's own OpenBLAS and child processes choose
for themselves. ``kiseki.library_versions()["openblas"]`` names the kernels in use. On AMD's
processors the AVX2 family is OpenBLAS' "Zen" (Haswell's kernels with AMD's cache sizes), which
OpenBLAS picks there itself: on an EPYC of family 25 the two took the same time within the
runs' spread (an exact GP on 5,000 points 2.3 s against 2.4-2.8 s; the Aalto hyperparameter
fit 0.63-0.77 s against 0.57-0.81 s; two to four runs each).
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator
from pathlib import Path

VARIABLE = "OPENBLAS_CORETYPE"
# The instruction sets each kernel family needs (OpenBLAS' SkylakeX and Haswell double-precision
# kernels; later families, e.g. Cooperlake, add only reduced-precision kernels).
_KERNELS = (
    ("SkylakeX", frozenset({"avx512f", "avx512cd", "avx512bw", "avx512dq", "avx512vl"})),
    ("Haswell", frozenset({"avx2", "fma"})),
)
_AMD = frozenset({"AuthenticAMD", "HygonGenuine"})  # vendor_id of AMD's and Hygon's Zen cores
_CPUINFO_LIMIT = 1 << 20  # bytes: one processor's block is a few kB, 256 of them fit


def kernels_for(flags: set[str] | frozenset[str], vendor: str = "") -> str | None:
    """The widest kernel family whose instruction sets are all in ``flags`` (its AMD name for
    an AMD ``vendor``); None for none."""
    for name, needed in _KERNELS:
        if needed <= flags:
            return "Zen" if name == "Haswell" and vendor in _AMD else name
    return None


def processor_fields(cpuinfo: Path = Path("/proc/cpuinfo")) -> dict[str, str]:
    """The first processor's block of ``cpuinfo`` as key: value ("model name", "cpu family",
    "flags", ...); empty without the file."""
    try:
        with cpuinfo.open(encoding="ascii", errors="replace") as f:
            text = f.read(_CPUINFO_LIMIT)
    except OSError:
        return {}
    fields: dict[str, str] = {}
    for line in text.splitlines():
        if not line.strip():
            if fields:
                break  # the first processor's block ends here
            continue
        key, _, value = line.partition(":")
        fields.setdefault(key.strip(), value.strip())
    return fields


def cpu_flags(cpuinfo: Path = Path("/proc/cpuinfo")) -> frozenset[str]:
    """The first processor's ``flags`` in ``cpuinfo``; empty if the file is absent or has none."""
    return _flags(processor_fields(cpuinfo))


def cpu_vendor(cpuinfo: Path = Path("/proc/cpuinfo")) -> str:
    """The first processor's ``vendor_id`` ("GenuineIntel", "AuthenticAMD"); "" without it."""
    return processor_fields(cpuinfo).get("vendor_id", "")


def _flags(fields: dict[str, str]) -> frozenset[str]:
    return frozenset(fields.get("flags", "").split())


@contextlib.contextmanager
def kernels_while_loading(cpuinfo: Path = Path("/proc/cpuinfo")) -> Iterator[str | None]:
    """Within the block, ``OPENBLAS_CORETYPE`` names the kernels for this processor unless the
    user set it (then it is left alone and None is yielded); afterwards it is unset again."""
    if VARIABLE in os.environ:
        yield None
        return
    fields = processor_fields(cpuinfo)  # read once
    name = kernels_for(_flags(fields), fields.get("vendor_id", ""))
    if name is None:
        yield None
        return
    os.environ[VARIABLE] = name
    try:
        yield name
    finally:
        os.environ.pop(VARIABLE, None)
