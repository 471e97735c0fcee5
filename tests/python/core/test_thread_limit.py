# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The most threads a call may ask for is one number, the C++ core's kMaxThreads: the Python
configs and options take it from the core, so a count the core would refuse never passes a
config, and one the configs accept never fails in the core."""

from __future__ import annotations

import numpy as np
import pytest

from kiseki import _core
from kiseki._support.options import THREAD_LIMIT
from kiseki.filters import MclConfig, RelocalizeConfig
from kiseki.terrain import correlation_search, sdem_from_points


@pytest.mark.parametrize("config", [MclConfig, RelocalizeConfig])
def test_configs_take_the_limit_and_refuse_one_more(config):
    assert config(threads=THREAD_LIMIT).threads == THREAD_LIMIT
    with pytest.raises(ValueError, match=f"0..{THREAD_LIMIT:,}"):
        config(threads=THREAD_LIMIT + 1)


def test_the_core_refuses_one_more_naming_the_same_limit():
    floor = np.random.default_rng(0).uniform([-3, -3, -0.6], [3, 3, -0.4], size=(500, 3))
    m = sdem_from_points(floor)
    with pytest.raises(ValueError, match=f"threads must be an integer in 0..{THREAD_LIMIT:,}"):
        correlation_search(m, m, threads=THREAD_LIMIT + 1)
    in_core = f"correlation search: threads must be in 0..{THREAD_LIMIT}"
    with pytest.raises(ValueError, match=in_core):
        _core.CorrelationSearch(m.to_points()[0], m, None, "sum", 50, THREAD_LIMIT + 1)
