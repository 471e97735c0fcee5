# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The rubble paper's experiments (003_fd335d240f62896b.txt): one move in environments A and B,
the corridor case, and the global map over a sequence of moves."""
