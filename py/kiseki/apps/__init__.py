# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The app tier's simulated runs: the programs that drive the simulator with the library's
methods (teaching a route in a scene, by script or keyboard, and playing it back in
`kiseki.apps.teach`; teaching and following a magnetic path in `kiseki.apps.magnetic`).

The command line, ``kiseki serve``, the demo and the experiments use them; nothing in the
library imports them, and they are the only kiseki modules besides those apps that may import
both the simulator and the methods (the layout test checks it). This ``__init__`` imports
nothing."""
