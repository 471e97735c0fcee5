# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Simulation: worlds, robots with realistic odometry, the papers' sensors, runs logged to MCAP."""
