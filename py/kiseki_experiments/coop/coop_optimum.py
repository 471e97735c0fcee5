# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Where the paper's own algebra puts the smallest along-track error (sec. 3.1, from eq. 4): a
table row of coop-forms beside the simulation's optimum, which its claims test."""

from __future__ import annotations

import math

from kiseki.coop import paper_error

__all__ = ["analytic_optimum"]


def analytic_optimum(distance: float = 10.0, d: float = 1.0, dtheta: float = 1e-3):
    """The paper's sec. 3.1, from its eq. 4 (kiseki.coop.paper_error): each of n measurements
    places the moving robot on the centre line, d tan(theta) ahead of a baseline of half-width
    d, with theta1 = theta2 = theta and equal errors dtheta1 = dtheta2 (the along-track worst
    case); the along-track errors add up over the n steps, and n d tan(theta) = distance.
    Returns (n, theta in deg, the error) minimising that error over n = 1..200."""
    best = None
    for n in range(1, 201):
        theta = math.atan(distance / (n * d))
        error = n * abs(paper_error(d, theta, theta, dtheta, dtheta)[1])
        if best is None or error < best[2]:
            best = (n, math.degrees(theta), error)
    return best
