# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Issue 27's bounded numbers for ``magnetic fit --kernel``: every number of the independent
and the curl-free kernels has limits, refused in one line naming it with nothing written, and
the limits themselves fit or say why in one line (moved from test_option_bounds.py)."""

from __future__ import annotations

from pathlib import Path

import pytest

from _helpers.cli_main import kiseki

MAGNETIC_POINTS = "x,y,mx,my,mz\n0,0,1,2,3\n1,0,1.5,2,3\n0,1,1,2.5,3\n1,1,1,2,3.5\n0.5,0.5,1,2,3\n"


@pytest.mark.parametrize(
    ("kernel", "line"),
    [
        # was an OverflowError traceback, exit 3 (sigma_f squared is inf)
        ("1e200,1,0.5", "--kernel: sigma_f must be a number in [1e-6, 1e6] (the data's units), "
         "got 1e200"),
        # were taken: a map from a length scale of 1e308 m and a noise SD of 1e-200
        ("10,1e308,0.5", "--kernel: l must be a number in [1e-6, 1e6] (m), got 1e308"),
        ("1,1,1e-200", "--kernel: sigma_n must be a number in [1e-6, 1e6] (the data's units), "
         "got 1e-200"),
        ("1,-0,0.5", "--kernel: l must be a number in [1e-6, 1e6] (m), got -0"),
        ("1,1,nan", "--kernel: sigma_n must be a number in [1e-6, 1e6] (the data's units), "
         "got nan"),
        ("1,1", "--kernel must be 3 numbers sigma_f,l,sigma_n (--model independent), got 1,1"),
        ("1,x,1", "--kernel must be 3 numbers sigma_f,l,sigma_n (--model independent), got "
         "1,x,1"),
    ],
)  # fmt: skip
def test_the_kernels_numbers_have_limits(tmp_path, monkeypatch, capsys, kernel, line):
    monkeypatch.chdir(tmp_path)
    Path("pts.csv").write_text(MAGNETIC_POINTS)
    code, _, err = kiseki(monkeypatch, capsys, "magnetic", "fit", "pts.csv", "-o", "m",
                          "--model", "independent", "--kernel", kernel)  # fmt: skip
    assert (code, err.splitlines()) == (1, [f"kiseki: error: {line}"]), err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pts.csv"]  # nothing written


@pytest.mark.parametrize(
    "kernel", ["1e-6,1e-6,1e-6", "1e6,1e6,1e6", "1e6,1e6,1e-6", "1e-6,1e6,1e6"]
)
@pytest.mark.parametrize("method", ["exact", "hilbert"])
def test_the_kernels_limits_fit_or_say_why_in_one_line(tmp_path, monkeypatch, capsys, kernel,
                                                        method):  # fmt: skip
    """The controls: the limits themselves are taken, and the GP fits or refuses in one line."""
    monkeypatch.chdir(tmp_path)
    Path("pts.csv").write_text(MAGNETIC_POINTS)
    code, _, err = kiseki(monkeypatch, capsys, "magnetic", "fit", "pts.csv", "-o", "m", "--model",
                          "independent", "--kernel", kernel, "--method", method)  # fmt: skip
    assert code in (0, 1) and len(err.splitlines()) == code, err


@pytest.mark.parametrize(
    ("kernel", "line"),
    [
        ("1,1,0.1", "--kernel must be 4 numbers sigma_f,l,sigma_lin,sigma_n (--model curl-free), "
         "got 1,1,0.1"),
        ("1,1,1e7,0.1", "--kernel: sigma_lin must be a number in [1e-6, 1e6] (the data's units), "
         "got 1e7"),
        ("0,1,1,0.1", "--kernel: sigma_f must be a number in [1e-6, 1e6] (units x m), got 0"),
    ],
)  # fmt: skip
def test_the_curl_free_kernels_numbers_have_limits(tmp_path, monkeypatch, capsys, kernel, line):
    monkeypatch.chdir(tmp_path)
    Path("pts.csv").write_text(MAGNETIC_POINTS)
    code, _, err = kiseki(monkeypatch, capsys, "magnetic", "fit", "pts.csv", "-o", "m",
                          "--kernel", kernel)  # fmt: skip
    assert (code, err.splitlines()) == (1, [f"kiseki: error: {line}"]), err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pts.csv"]  # nothing written


@pytest.mark.parametrize("kernel", ["1e-6,1e-6,1e-6,1e-6", "1e6,1e6,1e6,1e6", "1e6,1e-6,1e6,1e-6"])
@pytest.mark.parametrize("method", ["exact", "hilbert"])
def test_the_curl_free_kernels_limits_fit_or_say_why_in_one_line(
    tmp_path, monkeypatch, capsys, kernel, method
):
    monkeypatch.chdir(tmp_path)
    Path("pts.csv").write_text(MAGNETIC_POINTS)
    code, _, err = kiseki(monkeypatch, capsys, "magnetic", "fit", "pts.csv", "-o", "m",
                          "--kernel", kernel, "--method", method)  # fmt: skip
    assert code in (0, 1) and len(err.splitlines()) == code, err
