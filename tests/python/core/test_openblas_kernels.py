# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The OpenBLAS kernels the core runs on: named from the processor's instruction sets unless
the user named them, and reported by library_versions."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from kiseki._support.openblas_kernels import (
    VARIABLE,
    cpu_flags,
    cpu_vendor,
    kernels_for,
    kernels_while_loading,
)

AVX512 = {"avx512f", "avx512cd", "avx512bw", "avx512dq", "avx512vl"}


def test_the_widest_family_whose_instruction_sets_are_all_there():
    assert kernels_for(AVX512 | {"avx2", "fma", "avx512_bf16"}) == "SkylakeX"
    assert kernels_for((AVX512 - {"avx512vl"}) | {"avx2", "fma"}) == "Haswell"
    assert kernels_for({"avx", "avx2", "fma", "sse4_2"}) == "Haswell"
    assert kernels_for({"avx", "avx2", "sse4_2"}) is None  # no FMA: OpenBLAS' own choice
    assert kernels_for(set()) is None
    # AMD's name for the AVX2 family, which OpenBLAS picks on AMD's processors itself
    assert kernels_for({"avx2", "fma"}, "AuthenticAMD") == "Zen"
    assert kernels_for({"avx2", "fma"}, "GenuineIntel") == "Haswell"
    assert kernels_for(AVX512 | {"avx2", "fma"}, "AuthenticAMD") == "SkylakeX"


def test_flags_are_read_from_the_first_processor(tmp_path):
    info = tmp_path / "cpuinfo"
    info.write_text(
        "processor\t: 0\nvendor_id\t: GenuineIntel\nflags\t\t: fpu sse2 avx2 fma\n\n"
        "processor\t: 1\nflags\t\t: fpu avx512f\n"
    )
    assert cpu_flags(info) == {"fpu", "sse2", "avx2", "fma"}
    assert cpu_vendor(info) == "GenuineIntel"
    assert cpu_flags(tmp_path / "absent") == frozenset()
    assert cpu_vendor(tmp_path / "absent") == ""
    (tmp_path / "none").write_text("processor\t: 0\n")
    assert cpu_flags(tmp_path / "none") == frozenset()


def test_the_variable_is_set_only_while_loading_and_a_users_value_is_kept(tmp_path, monkeypatch):
    info = tmp_path / "cpuinfo"
    info.write_text("flags\t: avx2 fma\n")
    monkeypatch.delenv(VARIABLE, raising=False)
    with kernels_while_loading(info) as name:
        assert name == "Haswell" and os.environ[VARIABLE] == "Haswell"
    assert VARIABLE not in os.environ
    info.write_text("vendor_id\t: AuthenticAMD\nflags\t: avx2 fma\n")
    with kernels_while_loading(info) as name:
        assert name == "Zen" and os.environ[VARIABLE] == "Zen"
    assert VARIABLE not in os.environ
    info.write_text("flags\t: avx2 fma\n")
    info.write_text("flags\t: sse2\n")
    with kernels_while_loading(info) as name:
        assert name is None and VARIABLE not in os.environ
    monkeypatch.setenv(VARIABLE, "Prescott")
    info.write_text("flags\t: avx2 fma\n")
    with kernels_while_loading(info) as name:
        assert name is None and os.environ[VARIABLE] == "Prescott"
    assert os.environ[VARIABLE] == "Prescott"


def loaded_kernels(env: dict[str, str]) -> list[str]:
    code = (
        "import os, kiseki; print(kiseki.library_versions()['openblas']); "
        f"print(os.environ.get('{VARIABLE}'))"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
    )
    return done.stdout.splitlines()


def test_the_core_runs_on_the_kernels_named_for_this_processor():
    expected = kernels_for(cpu_flags(), cpu_vendor())
    if expected is None:
        pytest.skip("no /proc/cpuinfo, or a processor without AVX2 and FMA")
    env = {k: v for k, v in os.environ.items() if k != VARIABLE}
    version, after = loaded_kernels(env)
    assert version.endswith(f", {expected} kernels"), version
    assert after == "None"  # unset again once the core is loaded
    version, after = loaded_kernels({**env, VARIABLE: "Prescott"})
    assert version.endswith(", Prescott kernels") and after == "Prescott"
