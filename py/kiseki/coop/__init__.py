# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Cooperative positioning of a robot group (Hirose, Nagata and Kurazume): standing robots
measure the bearings of a moving one and triangulate it."""

from __future__ import annotations

from kiseki.coop.triangulation import (
    MIN_INTERSECTION_ANGLE,
    paper_error,
    paper_position,
    triangulate,
)

__all__ = ["MIN_INTERSECTION_ANGLE", "paper_error", "paper_position", "triangulate"]
