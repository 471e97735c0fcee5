# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The command line run as a user runs it (kiseki.cli.main), in the test's own process: no
Python start per case."""

from __future__ import annotations

import signal
import sys
import warnings

import pytest

from kiseki.cli import main


def kiseki(monkeypatch, capsys, *args) -> tuple[int, str, str]:
    """``kiseki ARGS`` as the entry point runs it, in this process: (status, stdout, stderr)."""
    monkeypatch.setattr(signal, "signal", lambda *a: None)  # main's SIGTERM handler
    monkeypatch.setattr(warnings, "showwarning", warnings.showwarning)  # restored after
    monkeypatch.setattr(sys, "argv", ["kiseki", *map(str, args)])
    with pytest.raises(SystemExit) as stop:
        main()
    done = capsys.readouterr()
    return stop.value.code or 0, done.out, done.err
