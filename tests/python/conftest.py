# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Fixtures: the project's own data/ and the recorded datasets in ../shared/data.

Tests that need ../shared/data skip with a message when it is absent, except under CI
(CI=true), where its absence is an error.
"""

from __future__ import annotations

import os
import signal
from pathlib import Path

import pytest

PROJECT_ROOT = Path(__file__).resolve().parents[2]
SHARED_DATA = PROJECT_ROOT.parent / "shared" / "data"

# A test run started with SIGINT ignored (a background job of a shell without job control)
# would hand that to every command it starts, and the tests that interrupt a command with
# SIGINT, as Ctrl-C in a terminal does, would see it ignored: kiseki rightly keeps a SIGINT
# its parent ignores. The run takes SIGINT back as a terminal has it, so its children do too.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)


@pytest.fixture(scope="session")
def project_root() -> Path:
    return PROJECT_ROOT


@pytest.fixture(scope="session")
def project_data() -> Path:
    return PROJECT_ROOT / "data"


@pytest.fixture(scope="session")
def shared_data() -> Path:
    if not SHARED_DATA.is_dir():
        message = f"recorded datasets not found at {SHARED_DATA} (../shared/data)"
        if os.environ.get("CI", "").lower() == "true":
            pytest.fail(f"{message}: CI must provide them", pytrace=False)
        pytest.skip(message)
    return SHARED_DATA
