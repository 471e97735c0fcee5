# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Magnetic navigation in a simulated scene: teaching the linear magnetic maps of a path
(`navigate_run.teach`), following it with the magnetic navigators (`navigate_run.navigate`)
and the folders of both (`navigate_outputs`). The methods are in `kiseki.magnetic`."""
