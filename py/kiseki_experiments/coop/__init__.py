# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Cooperative positioning (Hirose, Nagata, Kurazume): the two movement forms' error at the
goal."""
