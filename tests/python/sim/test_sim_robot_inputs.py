# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The simulated robots' module after its split: commands that are no number, and the names it
held before, answered for one release with a warning."""

from __future__ import annotations

import importlib
from decimal import Decimal

import pytest

import kiseki.sim.robot as robot_module
from kiseki.sim.robot import DiffDriveRobot


@pytest.mark.parametrize("bad", [True, "0.5", "1_0", Decimal("0.5")])
def test_a_command_that_is_no_number_is_refused(bad):
    """True drove at 1 m/s and the text "1_0" at 10 m/s (float() of anything not a number); a
    Decimal is no real number to numbers.Real (nor to the library's one check of a number)."""
    with pytest.raises(ValueError, match="v_cmd must be a finite number"):
        DiffDriveRobot().step(bad, 0.0, 0.1)


@pytest.mark.parametrize(
    ("name", "module"),
    [("WheelOdometry", "odometry"), ("OmniOdometry", "odometry"),
     ("OdometryErrorParams", "robot_params"), ("OmniOdometryErrorParams", "robot_params")],
)  # fmt: skip
def test_names_moved_out_of_the_robot_module_import_with_a_warning(name, module):
    with pytest.warns(DeprecationWarning, match=f"moved to kiseki.sim.{module}.{name}"):
        moved = getattr(robot_module, name)
    assert moved is getattr(importlib.import_module(f"kiseki.sim.{module}"), name)
    with pytest.raises(AttributeError):
        robot_module.NoSuchName  # noqa: B018
