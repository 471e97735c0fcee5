# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""PD steering: its gains, its rate limit, its error and its time step are finite numbers in
their ranges, named in one line (True was an error of 1 rad, the text "0.5" one of 0.5 rad)."""

from __future__ import annotations

import pytest

from kiseki.control import PdSteering


def test_the_rate_is_the_clipped_pd_of_the_error():
    pd = PdSteering(kp=2.0, kd=0.5, max_rate=1.0)
    assert pd.update(0.25, 0.1) == 0.5  # no derivative on the first call
    assert pd.update(0.3, 0.1) == pytest.approx(0.85)
    assert pd.update(1.0, 0.1) == 1.0  # clipped


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda: PdSteering(kp=0.0), "PdSteering: kp must be a finite number > 0, got 0.0"),
        (lambda: PdSteering(1.0, kd=-0.1), "PdSteering: kd must be a finite number >= 0, got -0.1"),
        (
            lambda: PdSteering(1.0, max_rate=float("inf")),
            "PdSteering: max_rate must be a finite number > 0 rad/s, got inf",
        ),
        (
            lambda: PdSteering(1.0).update(0.1, 0.0),
            "PdSteering: dt must be a finite number > 0 s, got 0.0",
        ),
        (
            lambda: PdSteering(1.0).update(float("nan"), 0.1),
            "PdSteering.update: the error must be a finite number, got nan",
        ),
        (
            lambda: PdSteering(1.0).update(True, 0.1),
            "PdSteering.update: the error must be a finite number, got True",
        ),
        (
            lambda: PdSteering(1.0).update("0.5", 0.1),
            "PdSteering.update: the error must be a finite number, got '0.5'",
        ),
    ],
)
def test_a_bad_number_is_refused_in_one_line(make, message):
    with pytest.raises(ValueError) as e:
        make()
    assert str(e.value) == message
