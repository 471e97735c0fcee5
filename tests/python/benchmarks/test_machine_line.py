# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The line every benchmark prints first: the processor as /proc/cpuinfo names it, with the
family and model numbers that tell one name's generations apart, and kiseki's BLAS kernels."""

from __future__ import annotations

import platform
import sys
from pathlib import Path

BENCHMARKS = Path(__file__).resolve().parents[3] / "benchmarks"
sys.path.insert(0, str(BENCHMARKS))

from timing import machine_line, processor  # noqa: E402

TWO_PROCESSORS = """processor\t: 0
vendor_id\t: GenuineIntel
cpu family\t: 6
model\t\t: 207
model name\t: Intel(R) Xeon(R) Processor
flags\t\t: fpu avx2

processor\t: 1
cpu family\t: 25
model\t\t: 1
model name\t: AMD EPYC
"""


def test_the_first_processors_name_family_and_model(tmp_path):
    cpuinfo = tmp_path / "cpuinfo"
    cpuinfo.write_text(TWO_PROCESSORS)
    assert processor(cpuinfo) == "Intel(R) Xeon(R) Processor (family 6, model 207)"
    cpuinfo.write_text("processor\t: 0\nmodel name\t: Some ARM core\n")
    assert processor(cpuinfo) == "Some ARM core"
    assert processor(tmp_path / "absent") == platform.machine()


def test_the_line_names_kiseki_s_blas_kernels(tmp_path):
    cpuinfo = tmp_path / "cpuinfo"
    cpuinfo.write_text(TWO_PROCESSORS)
    line = machine_line(cpuinfo)
    assert line.startswith("machine: Intel(R) Xeon(R) Processor (family 6, model 207), ")
    assert "kiseki's OpenBLAS 0." in line and "kernels" in line
