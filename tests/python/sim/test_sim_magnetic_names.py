# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""kiseki.sim.magnetic gathers the simulated field's names from the modules that hold them
(the world's field, the magnetometer, the dipoles): each name of its __all__ is the object of
its home module, and the two halves import each other in one direction only."""

from __future__ import annotations

import importlib

import kiseki.sim.magnetic as magnetic

HOMES = ("kiseki.sim.magnetic_world", "kiseki.sim.magnetometer", "kiseki.sim.dipoles")


def test_every_gathered_name_is_its_home_modules_object():
    homes = [importlib.import_module(h) for h in HOMES]
    for name in magnetic.__all__:
        held = [h for h in homes if name in getattr(h, "__all__", ())]
        assert len(held) == 1, (name, [h.__name__ for h in held])
        assert getattr(magnetic, name) is getattr(held[0], name), name
    # and nothing of the homes' __all__ is left out
    assert {n for h in homes for n in h.__all__} <= set(magnetic.__all__)
