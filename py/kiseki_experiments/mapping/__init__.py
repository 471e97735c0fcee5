# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The map builder's self-checks (no paper): maps of the CARMEN logs and of simulated corridor
scans."""
